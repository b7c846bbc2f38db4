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
"""
from __future__ import annotations

import time

import numpy as np

from search.astar import astar, outcome_result
from search.result import PlanResult
from pddl_export.symbolic import N_ACTIONS, SymbolicGoal, TransitionFn

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
    batch = np.repeat(np.asarray(state, np.int64)[None], N_ACTIONS, 0)  # (36, K)
    nxt = np.asarray(transition(batch, np.arange(N_ACTIONS, dtype=np.int64)))  # (36, K)
    _check_codes(nxt, (N_ACTIONS, len(state)), int(transition.bits), "transition output")
    moved = np.flatnonzero(np.any(nxt != batch, axis=1))  # self-loops dropped
    rows = nxt.tolist()
    return [(int(a), tuple(rows[a])) for a in moved]


def plan_symbolic(
    transition: TransitionFn,
    start_codes: np.ndarray,
    goal: SymbolicGoal,
    *,
    max_expansions: int = 20000,
    timeout_s: float = 30.0,
    uniform_cost: bool = False,
    planner_name: str = "astar",
) -> PlanResult:
    """Plan from start_codes (K,) to a (partial) goal; one batched transition call per expansion."""
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
    fixed = [(i, c) for i, c in enumerate(goal.codes) if c is not None]

    def is_goal(state: State) -> bool:
        return all(state[i] == c for i, c in fixed)

    def heuristic(state: State) -> float:
        return float(sum(state[i] != c for i, c in fixed))

    def successors(state: State) -> list[tuple[int, State, float]]:
        return [(a, nxt, 1.0) for a, nxt in symbolic_successors(transition, state)]

    out = astar(tuple(start_arr.tolist()), is_goal, successors, heuristic,
                max_expansions=max_expansions, timeout_s=timeout_s, uniform_cost=uniform_cost)
    return outcome_result(out, planner_name, t0, timeout_s, f"max_expansions={max_expansions}",
                          f"the {out.expansions} reachable states", {"uniform_cost": uniform_cost})
