"""Search over the exported rules in process: batched A* and layered breadth-first search.

The classical planners read the rules as a PDDL task in a new process per call, and on
4-5-object scenes that start and the task's 10^4-10^5 conditional effects cost more than the
search. Here the rules are compiled once (pddl_export.rule_successors.RuleSuccessors) and
expanded in batches: "astar" is the generic A* (search.astar), popping `batch` states per
successor call, on the summed code distances (code_distances); "bfs" is search.batched_bfs,
whose plans have optimal length and which proves a goal unreachable when it exhausts the
reachable states (max_states bounds its memory: about 60 bytes per state). Both skip states
that code_distances proves dead ends and states where two objects the goal tells apart share a
code, and search one state per permutation of objects with the same goal (search.rule_symmetry).
With pair_proof, both first ask the pair projections (search.rule_abstraction) whether the goal
is out of reach: a proof in under a second where one exists, but on the 5-object depth problems
that breadth-first search could not finish it found none.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)),))
    >>> plan_rules(rs, [1, 1], SymbolicGoal((2, None)), "bfs", timeout_s=5).plan
    (5,)
    >>> plan_rules(rs, [1, 3], SymbolicGoal((2, None)), "bfs", timeout_s=5).status.value
    'unsolvable'
    >>> plan_rules(rs, [1, 3], SymbolicGoal((2, None)), "bfs", timeout_s=5, pair_proof=True).message
    'objects 0 and 1 cannot reach their goal codes together (pair projection of the rules)'
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Iterable, Sequence

import networkx as nx
import numpy as np

from pddl_export.rule_successors import RuleSuccessors
from pddl_export.rules import RuleSet
from pddl_export.symbolic import SymbolicGoal
from search.astar import astar, outcome_result
from search.batched_bfs import breadth_first
from search.result import PlanResult, PlanStatus
from search.rule_abstraction import pair_unreachable
from search.rule_symmetry import canonical, coincident, goal_classes, replay, split_pairs

METHODS = ("astar", "bfs")
State = tuple[int, ...]
UNREACHABLE = 1 << 20  # code distance of a code from which an object's goal code cannot be reached


def code_distances(rules: RuleSet, goal: SymbolicGoal, *more: RuleSet,
                   changes: Iterable[tuple[int, int]] | None = None) -> np.ndarray:
    """(K, 2**bits) table: fewest rule firings taking object i from a code to its goal code, ignoring contexts.

    Rules of `more` rule sets (of the same bits) count as edges too. `changes`: the (code_from, code_to)
    pairs of all those rules, when the caller has them already (RuleSuccessors.code_changes): reading
    them off 200k rules costs more than the rest of a short search.

    An object only changes code when a rule on its code fires, so if no chain of rules leads from
    its code to its goal code (UNREACHABLE) no plan exists from that state: a sound dead-end test.
    Summed over the objects it is the search's heuristic (not admissible: one action may change
    several objects at once).
    """
    graph = nx.DiGraph()
    if changes is None:
        changes = {(r.code_from, r.code_to) for rs in (rules, *more) for r in rs.rules}
    graph.add_edges_from((to, frm) for frm, to in changes)  # reversed: search back from the goal
    table = np.zeros((len(goal.codes), 1 << rules.bits), np.int64)
    for i, g in enumerate(goal.codes):
        if g is None:
            continue
        table[i] = UNREACHABLE
        dist = nx.single_source_shortest_path_length(graph, g) if g in graph else {g: 0}
        table[i, list(dist)] = list(dist.values())
    return table


def checked_start(start: Sequence[int], goal: SymbolicGoal, bits: int) -> np.ndarray:
    """start as an int64 array (K,); ValueError if it does not match the goal or fit in `bits` bits."""
    arr = np.asarray(start, np.int64)
    if arr.ndim != 1 or len(goal.codes) != len(arr):
        raise ValueError(f"start codes {arr.shape} and goal of {len(goal.codes)} objects do not match")
    if arr.size and (arr.min() < 0 or arr.max() >= 1 << bits):
        raise ValueError(f"start codes {arr.tolist()} do not fit in {bits} bits")
    return arr


def _start_proof(rules: RuleSet, start: np.ndarray, goal: SymbolicGoal, pairs: np.ndarray,
                 pair_proof: bool) -> tuple[str, str] | None:
    """(kind, message) of a proof, before any search, that no plan reaches the goal; None without one.

    "coincidence": two objects the goal tells apart share a start code (search.rule_symmetry);
    "pair": with pair_proof, a pair projection cannot reach the goal (search.rule_abstraction).
    """
    together = [(int(i), int(j)) for i, j in pairs if start[i] == start[j]]
    if together:
        i, j = together[0]
        return "coincidence", (f"objects {i} and {j} hold the same code, which the rules move alike, "
                               "but have different goal codes")
    pair = pair_unreachable(rules, start.tolist(), goal) if pair_proof else None
    if pair is not None:
        return "pair", (f"objects {pair[0]} and {pair[1]} cannot reach their goal codes together "
                        "(pair projection of the rules)")
    return None


def plan_rules(
    rules: RuleSet | RuleSuccessors,
    start: Sequence[int],
    goal: SymbolicGoal,
    method: str,
    *,
    timeout_s: float,
    batch: int = 8,
    weight: float = 1.0,
    max_expansions: int = 1_000_000,
    max_states: int = 30_000_000,
    planner_name: str = "",
    pair_proof: bool = False,
    symmetry: bool = True,
) -> PlanResult:
    """Plan from start codes (K,) to goal under the rules by `method` ("astar" or "bfs").

    batch: states per successor call (A*); weight > 1 scales the heuristic (weighted A*: fewer
    expansions, longer plans). Pass a RuleSuccessors to reuse one compilation across calls.
    pair_proof: first try to prove the goal out of reach on pairs of objects (up to ~1 s on 5 objects).
    symmetry: search one state per permutation of objects with the same goal (search.rule_symmetry);
    the plan's predicted states are then replayed on the real objects. Either way, objects that share
    a code while the goal asks different codes of them end the search (UNSOLVABLE) or prune the state.
    """
    t0 = time.perf_counter()
    if method not in METHODS:
        raise ValueError(f"unknown rule search {method!r}; known: {', '.join(METHODS)}")
    succ = rules if isinstance(rules, RuleSuccessors) else RuleSuccessors(rules)
    start_arr = checked_start(start, goal, succ.bits)
    name, batch_used = planner_name or f"rules-{method}", batch if method == "astar" else 0
    pairs = split_pairs(goal.codes)
    proof = _start_proof(succ.rules, start_arr, goal, pairs, pair_proof)
    if proof is not None:
        return PlanResult(planner=name, status=PlanStatus.UNSOLVABLE, plan=(), predicted_states=(), expansions=0,
                          planning_time_s=time.perf_counter() - t0, message=proof[1],
                          extra={"generated": 0, "batch": batch_used, "proof": proof[0]})
    classes = goal_classes(goal.codes) if symmetry else ()

    def step(states: np.ndarray) -> np.ndarray:
        return canonical(succ(states), classes)

    fixed = [(i, c) for i, c in enumerate(goal.codes) if c is not None]
    idx = np.array([i for i, _ in fixed], np.int64)
    val = np.array([c for _, c in fixed], np.int64)
    actions = succ.actions.tolist()
    dist = code_distances(succ.rules, goal, changes=succ.code_changes)
    objects = np.arange(len(start_arr))
    dist_rows = dist.tolist()
    pair_rows = pairs.tolist()
    root = canonical(start_arr, classes)

    def heuristic(s: State) -> float:
        h = sum(row[c] for row, c in zip(dist_rows, s))
        return math.inf if h >= UNREACHABLE or any(s[i] == s[j] for i, j in pair_rows) else weight * h

    if method == "bfs":
        out = breadth_first(root, step, succ.actions, lambda s: np.all(s[:, idx] == val, axis=1),
                            bits=succ.bits, timeout_s=timeout_s, max_states=max_states,
                            dead_end=lambda s: (dist[objects, s] >= UNREACHABLE).any(axis=1) | coincident(s, pairs))
        limit = f"max_states={max_states}"
    else:
        def successors_many(states: list[State]) -> list[list[tuple[int, State, float]]]:
            nxt = step(np.array(states, np.int64).reshape(len(states), len(start_arr)))  # (B, A, K)
            rows = nxt.tolist()
            return [[(actions[a], t, 1.0) for a, r in enumerate(per) if (t := tuple(r)) != s]
                    for s, per in zip(states, rows)]

        out = astar(tuple(root.tolist()), lambda s: all(s[i] == c for i, c in fixed),
                    lambda s: successors_many([s])[0], heuristic,
                    max_expansions=max_expansions, timeout_s=timeout_s, batch=batch,
                    successors_many=successors_many)
        limit = f"max_expansions={max_expansions}"
    if classes and out.status is PlanStatus.SOLVED:  # the search saw sorted states: the real objects' path
        out = dataclasses.replace(out, states=replay(succ, succ.actions, start_arr, out.actions))
    reached = f"the {out.generated} states the rules reach" + (" (one per orbit of objects with the same goal)"
                                                                 if classes else "")
    return outcome_result(out, name, t0, timeout_s, limit, reached, {"batch": batch_used})
