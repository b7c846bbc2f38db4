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

from search.result import PlanResult, PlanStatus

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
    batch: int = 1,
    successors_many: Callable[[list[S]], list[Iterable[tuple[A, S, float]]]] | None = None,
) -> SearchOutcome[S, A]:
    """Best-first search on f = g + h; uniform_cost=True uses h = 0 (optimal cost, Dijkstra).

    Duplicates are detected by the best g seen per state: a pushed entry whose g is no longer
    the best is skipped when popped, and a state is re-opened if a cheaper path to it appears
    (this only happens with an inconsistent heuristic). Ties on f go to the lower h, then to
    the earlier push. A successor with h = inf is a dead end and is never pushed (UNSOLVABLE
    then means: no goal outside the states the heuristic calls dead ends).

    With batch > 1 and successors_many (states -> their successor lists, one vectorized call),
    up to `batch` best open states are popped and expanded together: each popped state is
    goal-tested first, so a goal is still returned as soon as it is popped, but states of
    slightly higher f may be expanded before a cheaper path found in the same batch is.
    """
    if max_expansions < 0:
        raise ValueError(f"max_expansions must be >= 0, got {max_expansions}")
    if batch < 1 or (batch > 1 and successors_many is None):
        raise ValueError(f"batch must be >= 1, and batch > 1 needs successors_many (got batch={batch})")
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

    expand_many = successors_many or (lambda states: [successors(x) for x in states])
    while open_:
        popped: list[tuple[float, S]] = []
        while open_ and len(popped) < batch:
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
            popped.append((g, state))
        for (g, state), succ in zip(popped, expand_many([x for _, x in popped])):
            for action, nxt, cost in succ:
                if cost < 0:
                    raise ValueError(f"A* needs non-negative costs, got {cost} for action {action!r}")
                g_next = g + cost
                if g_next < best_g.get(nxt, math.inf):
                    h = h_of(nxt)
                    if h == math.inf:
                        continue  # a dead end: the heuristic proves no goal is reachable from it
                    best_g[nxt] = g_next
                    parent[nxt] = (state, action)
                    heapq.heappush(open_, (g_next + h, h, next(tie), g_next, nxt))
                    generated += 1
    return outcome(PlanStatus.UNSOLVABLE)


def outcome_result(out: SearchOutcome, planner: str, t0: float, timeout_s: float, limit: str, reached: str,
                   extra: dict) -> PlanResult:
    """A search's outcome as the one PlanResult: `limit` names the bound a NODE_LIMIT hit, `reached` what was exhausted."""
    messages = {
        PlanStatus.SOLVED: "",
        PlanStatus.UNSOLVABLE: f"no goal state among {reached}",
        PlanStatus.NODE_LIMIT: f"stopped at {limit}",
        PlanStatus.TIMEOUT: f"stopped at timeout_s={timeout_s} after {out.expansions} expansions",
    }
    return PlanResult(planner=planner, status=out.status, plan=out.actions, predicted_states=out.states,
                      expansions=out.expansions, planning_time_s=time.perf_counter() - t0,
                      message=messages[out.status], extra={"generated": out.generated, **extra})
