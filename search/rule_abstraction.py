"""Proofs that a goal is out of reach of the rules, from projections of the state onto pairs of objects.

Breadth-first search proves a goal unreachable only by exhausting every reachable state, which on
5-object scenes passes 10^7 states. A projection onto two objects i and j keeps their codes and
forgets the rest: a rule on i fires in the projection whenever some codes of the other objects
could satisfy its context, given j's code and the codes the others can ever take (the codes
reachable from theirs in the rules' code graph). Keeping a code is always allowed, and i and j
choose their next codes independently. Every concrete step is then a step of the projection (it
over-approximates), so if the projection cannot reach a pair of codes meeting both objects'
goals, no plan exists. The projection has at most |codes|^2 states: it is searched in well under
a second. The context-free code graph alone (rules_search.code_distances) misses what contexts
forbid; pairs keep the conditions between two objects.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)),))
    >>> pair_unreachable(rs, [1, 3], SymbolicGoal((2, None)))   # object 1 (code 3) always forbids the rule
    (0, 1)
    >>> pair_unreachable(rs, [1, 1], SymbolicGoal((2, None))) is None
    True
"""
from __future__ import annotations

import itertools
from collections import defaultdict, deque
from typing import Sequence

import networkx as nx

from pddl_export.rules import Rule, RuleSet
from pddl_export.symbolic import SymbolicGoal


def reachable_codes(rules: RuleSet, codes: Sequence[int]) -> list[frozenset[int]]:
    """Per start code, every code an object can take from it, following rules and ignoring their contexts."""
    graph = nx.DiGraph()
    graph.add_edges_from({(r.code_from, r.code_to) for r in rules.rules})
    return [frozenset(nx.descendants(graph, c) | {c}) if c in graph else frozenset({c}) for c in map(int, codes)]


class _Others:
    """What the objects outside a pair can contribute to a context: per code, how many may and must hold it."""

    def __init__(self, reach: Sequence[frozenset[int]]) -> None:
        self.may: dict[int, int] = defaultdict(int)
        self.must: dict[int, int] = defaultdict(int)
        for codes in reach:
            for c in codes:
                self.may[c] += 1
            if len(codes) == 1:
                self.must[next(iter(codes))] += 1


def _can_fire(rule: Rule, partner: int, others: _Others) -> bool:
    """Whether some codes of the other objects satisfy the rule's context, the pair's partner having `partner`."""
    def most(code: int) -> int:
        return (partner == code) + others.may[code]

    def least(code: int) -> int:
        return (partner == code) + others.must[code]

    return (all(most(x) >= 1 for x in rule.requires)
            and all(least(x) == 0 for x in rule.forbids)
            and all(most(x) >= n for x, n in rule.at_least)
            and all(least(x) < n for x, n in rule.fewer_than))


def _next_codes(rules: RuleSet, action: int, own: int, partner: int, others: _Others) -> set[int]:
    """Codes the object can take under `action`: its own (no rule fired) and every rule's that can fire."""
    return {own} | {r.code_to for r in rules.rules_for(action, own) if _can_fire(r, partner, others)}


def pair_reaches_goal(rules: RuleSet, start: Sequence[int], goal: SymbolicGoal, i: int, j: int,
                      reach: Sequence[frozenset[int]] | None = None) -> bool:
    """Whether the projection onto objects i and j reaches codes meeting both objects' goals."""
    if reach is None:
        reach = reachable_codes(rules, start)
    others = _Others([reach[k] for k in range(len(start)) if k not in (i, j)])  # outside the pair, for i and for j
    gi, gj = goal.codes[i], goal.codes[j]

    def done(ci: int, cj: int) -> bool:
        return (gi is None or ci == gi) and (gj is None or cj == gj)

    actions = rules.actions
    first = (int(start[i]), int(start[j]))
    seen, queue = {first}, deque([first])
    while queue:
        ci, cj = queue.popleft()
        if done(ci, cj):
            return True
        for a in actions:
            for nxt in itertools.product(_next_codes(rules, a, ci, cj, others), _next_codes(rules, a, cj, ci, others)):
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
    return False


def pair_unreachable(rules: RuleSet, start: Sequence[int], goal: SymbolicGoal) -> tuple[int, int] | None:
    """A pair of objects whose projection cannot reach the goal (a proof that no plan exists), or None."""
    if len(goal.codes) != len(start):
        raise ValueError(f"start codes of {len(start)} objects and a goal of {len(goal.codes)} do not match")
    reach = reachable_codes(rules, start)
    for i, j in itertools.combinations(range(len(start)), 2):
        if goal.codes[i] is None and goal.codes[j] is None:
            continue
        if not pair_reaches_goal(rules, start, goal, i, j, reach):
            return i, j
    return None
