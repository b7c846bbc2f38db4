"""Shorter plans of the learned relational domain: plan neighborhood graph search over a planner's first plan.

A satisficing planner's first plan (Fast Downward's lama-first) can run several times the shortest: moves out of the
way and back, an object set down twice. Executed in a closed loop with a step budget, such a plan runs out of steps.
Plan neighborhood graph search (Nakhost and Mueller, ICAPS 2010) takes the states the plan passes through, adds every
state a breadth-first search reaches from them within `depth` steps, and finds the shortest path from the start to a
goal state inside that set (search.astar, uniform cost). Each shorter plan found becomes the new centre; the depth
grows by one once a round finds nothing shorter, until the time or the state budget runs out or the neighborhood
stops growing (then it is every state reachable, and the plan is a shortest one). The plan returned is
never longer than the one given, and every step of it is a step of the domain (its precondition holds where it is
taken), so it is a plan of the same problem.
"""
from __future__ import annotations

import itertools
import time
from typing import Callable, Iterable, Sequence

from pddl_export.learned_domain import Atom, Operator, bindings, step_successor, successor
from search.astar import astar
from search.result import PlanStatus

State = frozenset[Atom]


def applicable(ops: Sequence[Operator], state: State,
               entities: dict[str, Sequence[str]]) -> Iterable[tuple[str, State]]:
    """Every ground step "(op args...)" whose precondition holds in state, with the state it leads to. A parameter
    its precondition does not name (an ablation can drop the atoms that did) ranges over `entities` of its type
    ({"item": the problem's objects, "location": the domain's constants}), distinct from the others, as a PDDL
    planner grounds it."""
    for op in ops:
        for b in bindings(op, state, {}):
            free = [(v, t) for v, t in op.parameters if v not in b]
            for rest in itertools.product(*(entities.get(t, ()) for _, t in free)):
                if len(set(rest)) < len(rest) or set(rest) & set(b.values()):
                    continue
                args = [{**b, **dict(zip((v for v, _ in free), rest))}[v] for v, _ in op.parameters]
                after = successor(op, args, state)
                if after is not None:
                    yield f"({op.name} {' '.join(args)})", after


def plan_states(ops: dict[str, Operator], state: State, steps: Sequence[str]) -> list[State] | None:
    """The states a plan passes through, the start first; None where a step does not apply."""
    out = [state]
    for step in steps:
        if (state := step_successor(ops, step, state)) is None:
            return None
        out.append(state)
    return out


def shorten_plan(ops: Sequence[Operator], objects: Sequence[str], state: State, goal: State, steps: Sequence[str], *,
                 timeout_s: float, max_states: int = 4000, n_locations: int = 6) -> list[str]:
    """A plan for `goal` from `state` over `objects` (the problem's items; the locations are the domain's constants
    l0.. as pddl_export.learned_domain writes them) no longer than `steps` (itself a plan of it), by plan neighborhood
    graph search within timeout_s and a neighborhood of at most max_states states. `steps` comes back unchanged where
    it does not reach the goal in the domain (nothing to improve on) or nothing shorter is found."""
    t0 = time.perf_counter()
    by_name = {o.name: o for o in ops}
    best = list(steps)
    states = plan_states(by_name, state, best)
    if states is None or not goal <= states[-1] or len(best) <= 1:
        return best
    memo: dict[State, list[tuple[str, State]]] = {}
    entities = {"item": list(objects), "location": [f"l{i}" for i in range(n_locations)]}

    def moves(s: State) -> list[tuple[str, State]]:
        if s not in memo:
            memo[s] = list(applicable(ops, s, entities))
        return memo[s]

    depth, last = 1, 0
    while True:
        left = timeout_s - (time.perf_counter() - t0)
        if left <= 0:
            return best
        around = _neighborhood(moves, states, depth, max_states, t0 + left)
        if around is None:  # out of time or states before the neighborhood was whole
            return best
        out = astar(state, lambda s: goal <= s,
                    lambda s: ((step, after, 1.0) for step, after in moves(s) if after in around),
                    lambda s: 0.0, max_expansions=len(around), timeout_s=max(left, 1e-3), uniform_cost=True)
        if out.status is not PlanStatus.SOLVED:
            return best
        if len(out.actions) < len(best):
            best, states, last = list(out.actions), list(out.states), 0
        elif len(around) == last:  # the whole reachable space around the plan: nothing shorter exists
            return best
        else:
            depth, last = depth + 1, len(around)


def _neighborhood(moves: Callable[[State], list[tuple[str, State]]], centre: list[State], depth: int,
                  max_states: int, deadline: float) -> set[State] | None:
    """The states within `depth` steps of a centre state; None where that is more than max_states or the deadline
    passes first."""
    seen, frontier = set(centre), list(dict.fromkeys(centre))
    for _ in range(depth):
        nxt = []
        for s in frontier:
            if time.perf_counter() > deadline:
                return None
            for _, after in moves(s):
                if after not in seen:
                    seen.add(after)
                    nxt.append(after)
                    if len(seen) > max_states:
                        return None
        frontier = nxt
    return seen
