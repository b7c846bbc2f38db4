"""A* over the exported rules' all-outcomes determinization: the likeliest step, or one object's second outcome.

Each action leads to the state the rules predict (cost 1) and, for each of up to
`max_deviations` objects that have a second outcome there (pddl_export.outcome_rules), to
that state with this one object taking its second outcome instead, at cost 1 + w * (its
extra -log P). The rules carry no probability for their likeliest outcome, so unlike the
learned-net `astar-outcomes` a plan that follows the likeliest outcomes costs its length.
Steps execution has observed (`seen`, state -> {action: next state}) have their observed
successor only. Objects that share a code may part here (one takes its second outcome), so
the symmetry proofs of search.rules_search do not hold and are not used; the dead-end test
uses code distances over both rule sets.

    >>> from pddl_export.outcome_rules import AlternativeCosts
    >>> from pddl_export.rules import Rule, RuleSet
    >>> from pddl_export.rule_successors import RuleSuccessors
    >>> main = RuleSet(2, (1, 2, 3), 2, (Rule(action=5, code_from=1, code_to=2),), 1)
    >>> alt = RuleSet(2, (1, 2, 3), 2, (Rule(action=5, code_from=1, code_to=3),), 1)
    >>> cost = AlternativeCosts.from_costs([(5, 1, 3, 1.2)], bits=2)
    >>> res = plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), cost, [1], SymbolicGoal((3,)),
    ...                           risk_weight=1.0, timeout_s=5)
    >>> res.plan, res.predicted_states, round(res.extra["cost"], 3)
    ((5,), ((1,), (3,)), 2.2)
"""
from __future__ import annotations

import math
import time
from typing import Mapping, Sequence

import numpy as np

from pddl_export.outcome_rules import AlternativeCosts
from pddl_export.rule_successors import RuleSuccessors
from pddl_export.symbolic import N_ACTIONS, SymbolicGoal, code_str
from search.astar import astar, outcome_result
from search.result import PlanResult, PlanStatus
from search.rules_search import UNREACHABLE, checked_start, code_distances

State = tuple[int, ...]
Observed = Mapping[State, Mapping[int, State]]
MAX_DEVIATIONS = 3  # per action: the likeliest step and up to 3 one-object alternatives, as astar-outcomes' 4


def _all_actions(succ: RuleSuccessors, states: np.ndarray) -> np.ndarray:
    """(B, K) states -> (B, 36, K) next states under every action (unchanged where no rule of it fires)."""
    out = np.repeat(states[:, None, :], N_ACTIONS, axis=1)
    if len(succ.actions):
        out[:, succ.actions] = succ(states)
    return out


def outcome_steps(main: RuleSuccessors, alternates: RuleSuccessors, costs: AlternativeCosts, states: np.ndarray,
                  risk_weight: float, max_deviations: int = MAX_DEVIATIONS) -> list[list[tuple[int, State, float]]]:
    """Per state of (B, K): (action, next state, cost) for the rules' step and its one-object deviations."""
    nxt = _all_actions(main, states)  # (B, 36, K)
    alt = _all_actions(alternates, states)
    own = np.broadcast_to(states[:, None, :], alt.shape)
    dev_cost = np.where(alt != nxt, costs(np.arange(N_ACTIONS)[None, :, None], own, alt), np.inf)  # (B, 36, K)
    m = min(max_deviations, states.shape[1])
    pick = np.argsort(dev_cost, axis=2, kind="stable")[..., :m]  # (B, 36, m) the cheapest deviations
    pick_cost = np.take_along_axis(dev_cost, pick, 2)
    out = []
    for b, s in enumerate(states.tolist()):
        s = tuple(s)
        steps = [(a, t, 1.0) for a, t in enumerate(map(tuple, nxt[b].tolist())) if t != s]
        for a, j in zip(*np.nonzero(np.isfinite(pick_cost[b]))):
            k = int(pick[b, a, j])
            t = list(nxt[b, a].tolist())
            t[k] = int(alt[b, a, k])
            if tuple(t) != s:
                steps.append((int(a), tuple(t), 1.0 + risk_weight * float(pick_cost[b, a, j])))
        out.append(steps)
    return out


def plan_rules_outcomes(
    main: RuleSuccessors,
    alternates: RuleSuccessors,
    costs: AlternativeCosts,
    start: Sequence[int],
    goal: SymbolicGoal,
    *,
    risk_weight: float,
    timeout_s: float,
    seen: Observed | None = None,
    max_deviations: int = MAX_DEVIATIONS,
    batch: int = 8,
    max_expansions: int = 1_000_000,
    planner_name: str = "rules-outcomes",
) -> PlanResult:
    """A* from start codes (K,) to goal over the rules' step and one-object second outcomes (module doc).

    costs: the extra -log P of each alternative (OutcomeRules.alternative_costs).
    batch: states popped per successor call, as in plan_rules' A*; with batch > 1 a costlier plan popped in
    the same batch as a cheaper one's last state may be returned (batch=1: plain A*, one state per pop).
    """
    t0 = time.perf_counter()
    if not (math.isfinite(risk_weight) and risk_weight > 0):
        raise ValueError(f"risk_weight must be a finite number > 0, got {risk_weight}")
    if max_deviations < 0:
        raise ValueError(f"max_deviations must be >= 0, got {max_deviations}")
    if not main.bits == alternates.bits == costs.bits:
        raise ValueError(f"rules of {main.bits} and {alternates.bits} bits and costs of {costs.bits}-bit codes "
                         "do not match")
    start_arr = checked_start(start, goal, main.bits)
    seen = seen or {}
    dist = code_distances(main.rules, goal, alternates.rules,
                          changes=main.code_changes | alternates.code_changes).tolist()
    fixed = [(i, c) for i, c in enumerate(goal.codes) if c is not None]
    stuck = [i for i, c in fixed if dist[i][start_arr[i]] >= UNREACHABLE]
    if stuck:  # a proof before any search: no chain of rules or second outcomes leads this object to its goal code
        i = stuck[0]
        return PlanResult(planner=planner_name, status=PlanStatus.UNSOLVABLE, plan=(), predicted_states=(),
                          expansions=0, planning_time_s=time.perf_counter() - t0,
                          message=f"object {i} cannot reach its goal code {code_str(goal.codes[i], main.bits)} from "
                                  f"{code_str(int(start_arr[i]), main.bits)} through any chain of rules or second outcomes",
                          extra={"generated": 0, "batch": batch, "proof": "code_graph"})

    def heuristic(s: State) -> float:
        h = sum(row[c] for row, c in zip(dist, s))
        return math.inf if h >= UNREACHABLE else float(h)

    def successors_many(states: list[State]) -> list[list[tuple[int, State, float]]]:
        steps = outcome_steps(main, alternates, costs, np.array(states, np.int64).reshape(len(states), -1),
                              risk_weight, max_deviations)
        for i, s in enumerate(states):
            if s in seen:  # an observed step has its observed successor only
                known = seen[s]
                steps[i] = [x for x in steps[i] if x[0] not in known]
                steps[i] += [(a, tuple(t), 1.0) for a, t in known.items() if tuple(t) != s]
        return steps

    out = astar(tuple(start_arr.tolist()), lambda s: all(s[i] == c for i, c in fixed),
                lambda s: successors_many([s])[0], heuristic, max_expansions=max_expansions,
                timeout_s=timeout_s, batch=batch, successors_many=successors_many)
    return outcome_result(out, planner_name, t0, timeout_s, f"max_expansions={max_expansions}",
                          "the states the rules and their second outcomes reach",
                          {"batch": batch, "cost": out.cost, "risk_weight": risk_weight})
