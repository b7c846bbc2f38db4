"""Breadth-first search that expands a whole layer of states in one batched successor call.

For unit-cost problems whose successor function is vectorized (all actions of F states at
once, e.g. pddl_export.rule_successors.RuleSuccessors), layer-by-layer search does in numpy
what a heap-based A* does one state at a time: duplicate detection is a sorted-array
membership test on packed int64 keys, and the goal test runs over the whole new layer. The
first layer holding a goal gives a plan of optimal length; an empty layer proves no goal is
reachable (UNSOLVABLE), which A* would need one heap operation per state to show.

    >>> succ = lambda s: np.stack([(s + 1) % 5, (s + 2) % 5], axis=1)   # 1 object, 2 actions
    >>> out = breadth_first(np.array([0]), succ, np.array([7, 9]), lambda s: s[:, 0] == 4,
    ...                     bits=3, timeout_s=1.0, max_states=100)
    >>> out.status.value, out.actions, out.states
    ('solved', (9, 9), ((0,), (2,), (4,)))
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np

from pddl_export.rule_successors import pack_states
from search.astar import SearchOutcome
from search.result import PlanStatus


Layer = tuple[np.ndarray, np.ndarray, np.ndarray]  # states (n, K), parent index in the previous layer, action


def _path(layers: list[Layer], goal_index: int) -> tuple[tuple[int, ...], tuple[tuple[int, ...], ...]]:
    """The actions and states from the start to state goal_index of the last layer, following parents back."""
    plan: list[int] = []
    path: list[tuple[int, ...]] = []
    i = goal_index
    for depth in range(len(layers) - 1, -1, -1):
        states, parents, acts = layers[depth]
        path.append(tuple(int(c) for c in states[i]))
        if depth:
            plan.append(int(acts[i]))
            i = int(parents[i])
    return tuple(reversed(plan)), tuple(reversed(path))


def _new_successors(part: np.ndarray, nxt: np.ndarray, actions: np.ndarray, seen: np.ndarray,
                    bits: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(keys, states, parent rows in part, actions) of the successors nxt (F, A, K) of part not in sorted `seen`.

    Self-loops are dropped, and a state reached several times keeps its first (parent, action).
    """
    keys = pack_states(nxt, bits)  # (F, A)
    fi, ai = np.nonzero(keys != pack_states(part, bits)[:, None])  # by parent, then action
    keys, first = np.unique(keys[fi, ai], return_index=True)  # first occurrence: lowest parent, then action
    pos = np.minimum(np.searchsorted(seen, keys), len(seen) - 1)  # seen is never empty
    fresh = seen[pos] != keys
    fi, ai = fi[first[fresh]], ai[first[fresh]]
    return keys[fresh], nxt[fi, ai], fi, actions[ai]


def breadth_first(
    start: np.ndarray,
    successors: Callable[[np.ndarray], np.ndarray],
    actions: np.ndarray,
    is_goal: Callable[[np.ndarray], np.ndarray],
    *,
    bits: int,
    timeout_s: float,
    max_states: int,
    dead_end: Callable[[np.ndarray], np.ndarray] | None = None,
    chunk: int = 20_000,
) -> SearchOutcome[tuple[int, ...], int]:
    """Layered BFS from start (K,): successors maps (F, K) -> (F, A, K), is_goal (F, K) -> (F,) bool.

    dead_end, (F, K) -> (F,) bool, marks states from which no goal is reachable (it must be
    sound: a relaxation's proof); they are remembered as seen but never expanded.

    Self-loops are dropped. Among the parents of a new state the first in layer order wins, and
    among its actions the first in `actions`, so the plan returned is deterministic. Ends
    SOLVED, UNSOLVABLE (every reachable state seen), NODE_LIMIT (more than max_states states)
    or TIMEOUT (checked before each chunk of successor calls).
    """
    if not timeout_s > 0:
        raise ValueError(f"timeout_s must be > 0, got {timeout_s}")
    t0 = time.perf_counter()
    start = np.asarray(start, np.int64).reshape(1, -1)
    actions = np.asarray(actions, np.int64)
    layers: list[Layer] = [(start, np.zeros(1, np.int64), np.zeros(1, np.int64))]
    seen = pack_states(start, bits)
    expansions, generated = 0, 1

    def outcome(status: PlanStatus, goal_index: int | None = None) -> SearchOutcome:
        plan, path = _path(layers, goal_index) if goal_index is not None else ((), ())
        return SearchOutcome(status=status, actions=plan, states=path,
                             cost=float(len(plan)) if goal_index is not None else float("inf"),
                             expansions=expansions, generated=generated, time_s=time.perf_counter() - t0)

    hits = np.flatnonzero(is_goal(start))
    if len(hits):
        return outcome(PlanStatus.SOLVED, int(hits[0]))
    while True:
        frontier = layers[-1][0]
        if not len(frontier):
            return outcome(PlanStatus.UNSOLVABLE)
        parts = []  # per chunk: keys, states, parents, actions of its new states
        for lo in range(0, len(frontier), chunk):
            if time.perf_counter() - t0 > timeout_s:
                return outcome(PlanStatus.TIMEOUT)
            part = frontier[lo:lo + chunk]
            keys, states, parents, acts = _new_successors(part, successors(part), actions, seen, bits)
            parts.append((keys, states, parents + lo, acts))
            expansions += len(part)
        keys, states, parents, acts = (np.concatenate(x) for x in zip(*parts))
        keys, first = np.unique(keys, return_index=True)  # a state new to two chunks: keep the earlier chunk's
        states, parents, acts = states[first], parents[first], acts[first]
        order = np.lexsort((acts, parents))  # layer order: by parent, then action
        states, parents, acts, keys = states[order], parents[order], acts[order], keys[order]
        generated += len(keys)
        if time.perf_counter() - t0 > timeout_s:
            return outcome(PlanStatus.TIMEOUT)
        seen = np.union1d(seen, keys)
        if dead_end is not None:
            alive = ~dead_end(states)
            states, parents, acts = states[alive], parents[alive], acts[alive]
        layers.append((states, parents, acts))
        hits = np.flatnonzero(is_goal(states))
        if len(hits):
            return outcome(PlanStatus.SOLVED, int(hits[0]))
        if len(seen) > max_states:
            return outcome(PlanStatus.NODE_LIMIT)
