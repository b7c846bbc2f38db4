"""A* over symbolic states, with a (learned) TransitionFn as the successor model.

    result = plan_symbolic(transition, np.array([3, 0, 12]), SymbolicGoal((3, None, 7)),
                           uniform_cost=True)
    if result.found:
        print(result.plan, result.predicted_states[-1])  # action ids, predicted final codes

States are tuples of per-object integer codes; every action costs 1, and actions that leave
the state unchanged (self-loops) are skipped.

Batching: each expansion evaluates all 36 actions in one call,
`transition(np.repeat(state[None], 36, 0), np.arange(36))`. For the learned model the forward
pass (attention over K objects) dominates the cost of an expansion, and 36 rows cost about as
much as one, so one call per expansion is ~36x cheaper than one call per action.

Heuristic: the number of goal-fixed objects whose code differs from the goal. It is NOT
admissible in general: one action can change several objects at once (pushing a stick moves
the cube riding on it), so h can exceed the remaining plan length and A* may return a longer
plan than needed. A* stays complete with it (finite state space, re-opening on cheaper paths).
Pass uniform_cost=True (h = 0, breadth-first order) for plans of optimal length.

Most likely plans: with risk_weight w > 0 an action costs 1 + w * (-log P(its predicted next
state)), read from a ScoredTransitionFn's `scored`. Among plans of similar length A* then
prefers those whose every prediction the model is sure of, the plans most likely to unfold in
the world as predicted (m(z)'s confidence is calibrated on held-out steps: docs/RESULTS.md).
The mismatch heuristic is then counted in cost units, times the median cost of the start's actions,
so that the search stays as greedy as with unit costs. The result's extra["log_p"] is the plan's
summed log-probability.
"""
from __future__ import annotations

import time

import numpy as np

from search.astar import astar, outcome_result
from search.result import PlanResult
from pddl_export.symbolic import N_ACTIONS, ScoredTransitionFn, SymbolicGoal, TransitionFn

State = tuple[int, ...]


def _check_codes(codes: np.ndarray, shape: tuple[int, ...], bits: int, what: str) -> None:
    """Refuse arrays of the wrong shape, non-integer dtype, or codes outside 0..2**bits - 1."""
    if codes.shape != shape:
        raise ValueError(f"{what} has shape {codes.shape}, expected {shape}")
    if not np.issubdtype(codes.dtype, np.integer):
        raise ValueError(f"{what} must hold integer codes, got dtype {codes.dtype}")
    if codes.size and (codes.min() < 0 or codes.max() >= 1 << bits):
        raise ValueError(f"{what} holds codes outside 0..{(1 << bits) - 1} ({bits} bits)")


def symbolic_successors(transition: TransitionFn, state: State) -> list[tuple[int, State]]:
    """(action, next_state) for each action that changes state; one batched call of 36 rows."""
    return [(a, nxt) for a, nxt, _ in scored_successors(transition, state, scored=False)]


def scored_successors(transition: TransitionFn | ScoredTransitionFn, state: State,
                      scored: bool = True) -> list[tuple[int, State, float]]:
    """(action, next_state, -log P(next_state)) for each action that changes state (0.0 when not scored)."""
    batch = np.repeat(np.asarray(state, np.int64)[None], N_ACTIONS, 0)  # (36, K)
    actions = np.arange(N_ACTIONS, dtype=np.int64)
    if scored:
        nxt, nll = transition.scored(batch, actions)
        nxt, nll = np.asarray(nxt), np.asarray(nll, np.float64)
        if nll.shape != (N_ACTIONS,) or not np.all(np.isfinite(nll)) or nll.min() < 0:
            raise ValueError(f"transition scores must be (36,) finite and >= 0, got {nll.shape}")
    else:
        nxt, nll = np.asarray(transition(batch, actions)), np.zeros(N_ACTIONS)
    _check_codes(nxt, (N_ACTIONS, len(state)), int(transition.bits), "transition output")
    moved = np.flatnonzero(np.any(nxt != batch, axis=1))  # self-loops dropped
    rows = nxt.tolist()
    return [(int(a), tuple(rows[a]), float(nll[a])) for a in moved]


def plan_symbolic(
    transition: TransitionFn,
    start_codes: np.ndarray,
    goal: SymbolicGoal,
    *,
    max_expansions: int = 20000,
    timeout_s: float = 30.0,
    uniform_cost: bool = False,
    risk_weight: float = 0.0,
    planner_name: str = "astar",
) -> PlanResult:
    """Plan from start_codes (K,) to a (partial) goal; one batched transition call per expansion.

    risk_weight > 0 charges each action w * (-log P) on top of its unit cost (module docstring).
    """
    t0 = time.perf_counter()
    bits = int(transition.bits)
    start_arr = np.asarray(start_codes)
    if start_arr.ndim != 1:
        raise ValueError(f"start_codes must have shape (K,), got {start_arr.shape}")
    k = start_arr.shape[0]
    if len(goal.codes) != k:
        raise ValueError(f"goal has {len(goal.codes)} objects, start_codes has {k}")
    _check_codes(start_arr, (k,), bits, "start_codes")
    if any(c is not None and not 0 <= c < 1 << bits for c in goal.codes):
        raise ValueError(f"goal {goal.codes} holds codes outside 0..{(1 << bits) - 1}")
    if not (np.isfinite(risk_weight) and risk_weight >= 0):
        raise ValueError(f"risk_weight must be a finite number >= 0, got {risk_weight}")
    scored = risk_weight > 0
    if scored and not callable(getattr(transition, "scored", None)):
        raise ValueError(f"risk_weight {risk_weight} needs a transition that scores its predictions "
                         f"(a `scored` method); {type(transition).__name__} has none")
    fixed = [(i, c) for i, c in enumerate(goal.codes) if c is not None]
    step_nll: dict[tuple[State, int], float] = {}

    def is_goal(state: State) -> bool:
        return all(state[i] == c for i, c in fixed)

    start = tuple(start_arr.tolist())
    first = scored_successors(transition, start) if scored and not is_goal(start) else []
    # With risk, an action costs more than 1, so h is put in cost units (the median cost of the start's
    # actions); else A* would fall back towards breadth-first order and run out of time on bigger scenes.
    scale = float(np.median([1.0 + risk_weight * nll for *_, nll in first])) if first else 1.0

    def heuristic(state: State) -> float:
        return scale * sum(state[i] != c for i, c in fixed)

    def successors(state: State) -> list[tuple[int, State, float]]:
        out = []
        for a, nxt, nll in (first if state == start and first else scored_successors(transition, state, scored)):
            if scored:  # kept for the plan's log_p; unit-cost search needs none of it
                step_nll[state, a] = nll
            out.append((a, nxt, 1.0 + risk_weight * nll))
        return out

    out = astar(start, is_goal, successors, heuristic,
                max_expansions=max_expansions, timeout_s=timeout_s, uniform_cost=uniform_cost)
    extra: dict = {"uniform_cost": uniform_cost, "risk_weight": risk_weight}
    if scored:
        extra["heuristic_scale"] = round(scale, 6)
    if scored and out.states:
        extra["log_p"] = round(-sum(step_nll[s, a] for s, a in zip(out.states, out.actions)), 6)
    return outcome_result(out, planner_name, t0, timeout_s, f"max_expansions={max_expansions}",
                          f"the {out.expansions} reachable states", extra)
