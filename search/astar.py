"""One generic A* over hashable states (after predicators' run_astar).

The caller supplies the goal test, a successor function yielding (action, next_state, cost)
and a heuristic; the learned network only ever appears inside those callables.

    >>> graph = {"a": [("ab", "b", 1.0), ("ac", "c", 5.0)], "b": [("bc", "c", 1.0)], "c": []}
    >>> out = astar("a", lambda s: s == "c", lambda s: graph[s], lambda s: 0.0,
    ...             max_expansions=100, timeout_s=1.0)
    >>> out.status.value, out.actions, out.states
    ('solved', ('ab', 'bc'), ('a', 'b', 'c'))

Outcomes are kept apart because they mean different things: SOLVED (goal popped), UNSOLVABLE
(open list exhausted: no goal is reachable, given complete successors), NODE_LIMIT (stopped
after max_expansions: no proof either way) and TIMEOUT (wall clock passed timeout_s, checked
before each pop, so the overrun is at most one expansion).
"""
from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass
from typing import Callable, Generic, Hashable, Iterable, TypeVar

from search.result import PlanStatus

S = TypeVar("S", bound=Hashable)
A = TypeVar("A")


@dataclass(frozen=True)
class SearchOutcome(Generic[S, A]):
    """How one A* run ended, the path it found (start included in states) and its counts."""

    status: PlanStatus  # SOLVED, UNSOLVABLE, NODE_LIMIT or TIMEOUT
    actions: tuple[A, ...]  # empty unless SOLVED
    states: tuple[S, ...]  # start + one state per action when SOLVED, else empty
    cost: float  # path cost when SOLVED, else math.inf
    expansions: int  # states whose successors were generated
    generated: int  # states pushed onto the open list (start included), re-pushes on a better g
    time_s: float


def _path(parent: dict[S, tuple[S, A] | None], goal: S) -> tuple[tuple[A, ...], tuple[S, ...]]:
    """The actions and states from the start to goal, following parent links back from goal."""
    actions: list[A] = []
    states: list[S] = [goal]
    node = goal
    while (link := parent[node]) is not None:
        node, action = link
        actions.append(action)
        states.append(node)
    return tuple(reversed(actions)), tuple(reversed(states))


def astar(
    start: S,
    is_goal: Callable[[S], bool],
    successors: Callable[[S], Iterable[tuple[A, S, float]]],
    heuristic: Callable[[S], float],
    *,
    max_expansions: int,
    timeout_s: float,
    uniform_cost: bool = False,
) -> SearchOutcome[S, A]:
    """Best-first search on f = g + h; uniform_cost=True uses h = 0 (optimal cost, Dijkstra).

    Duplicates are detected by the best g seen per state: a pushed entry whose g is no longer
    the best is skipped when popped, and a state is re-opened if a cheaper path to it appears
    (this only happens with an inconsistent heuristic). Ties on f go to the lower h, then to
    the earlier push.
    """
    if max_expansions < 0:
        raise ValueError(f"max_expansions must be >= 0, got {max_expansions}")
    if not timeout_s > 0:
        raise ValueError(f"timeout_s must be > 0, got {timeout_s}")
    t0 = time.perf_counter()
    h_of = (lambda s: 0.0) if uniform_cost else heuristic
    tie = itertools.count()
    best_g: dict[S, float] = {start: 0.0}
    parent: dict[S, tuple[S, A] | None] = {start: None}
    h0 = h_of(start)
    open_: list[tuple[float, float, int, float, S]] = [(h0, h0, next(tie), 0.0, start)]
    expansions, generated = 0, 1

    def outcome(status: PlanStatus, goal: S | None = None) -> SearchOutcome[S, A]:
        actions, states = _path(parent, goal) if goal is not None else ((), ())
        return SearchOutcome(
            status=status, actions=actions, states=states,
            cost=best_g[goal] if goal is not None else math.inf,
            expansions=expansions, generated=generated, time_s=time.perf_counter() - t0)

    while open_:
        if time.perf_counter() - t0 > timeout_s:
            return outcome(PlanStatus.TIMEOUT)
        _, _, _, g, state = heapq.heappop(open_)
        if g > best_g[state]:
            continue  # stale entry: a cheaper path to this state was pushed after it
        if is_goal(state):
            return outcome(PlanStatus.SOLVED, state)
        if expansions >= max_expansions:
            return outcome(PlanStatus.NODE_LIMIT)
        expansions += 1
        for action, nxt, cost in successors(state):
            if cost < 0:
                raise ValueError(f"A* needs non-negative costs, got {cost} for action {action!r}")
            g_next = g + cost
            if g_next < best_g.get(nxt, math.inf):
                best_g[nxt] = g_next
                parent[nxt] = (state, action)
                h = h_of(nxt)
                heapq.heappush(open_, (g_next + h, h, next(tie), g_next, nxt))
                generated += 1
    return outcome(PlanStatus.UNSOLVABLE)
