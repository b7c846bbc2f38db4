"""Rule overrides: correct a rule set by transitions observed during execution.

A rule planner that saw an action do something else than its rules say should not plan
with the disproven rule again. `override_rules(rules, observed)` returns a rule set that
gives the observed next state on every observed (state, action) and the original outcome
everywhere else, for scenes with the same number of objects as the observed states (what
a planning task has: its objects are fixed).

Rules are per (action, own code) with count bounds on the OTHER objects' codes. An observed
step (s, a, s') says, for each object i with own code c = s_i and others' multiset M, what
c becomes under a when the others are exactly M. That case is the box B(M) = {x: [n_x, n_x + 1)
for the codes x of M}, plus "no other object has x" for the codes x that other observed
multisets of the same (a, c) hold and M does not (so two override boxes never overlap, as
RuleSet requires). With |M| = K - 1 fixed, a K-object state lies in B(M) exactly when its
others are M; scenes of another size may fall in a box and then take the override too.
Every existing rule of (a, c) is replaced by its box difference with B(M) (at most two
pieces per bounded code, pairwise disjoint), and if s'_i != c the rule (a, c, s'_i, B(M)) is
added. Two objects with the same own code and others (equal codes in one state, or one state
and its permutation) that went to different codes cannot be told apart by the rules: such a
case keeps its original rules and is counted in OverrideInfo.conflicts.

    >>> from pddl_export.rules import Rule, RuleSet, apply_rules
    >>> rs = RuleSet(bits=2, vocabulary=(0, 1, 2), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=3, code_from=1, code_to=2),))
    >>> fixed = override_rules(rs, {(1, 0): {3: (1, 0)}})   # with a 0 beside it, 1 stays 1 under action 3
    >>> apply_rules(fixed, [1, 0], 3).tolist(), apply_rules(fixed, [1, 2], 3).tolist()
    ([1, 0], [2, 2])
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Mapping

from pddl_export.rules import INF, Bounds, Rule, RuleSet

Observed = Mapping[tuple[int, ...], Mapping[int, tuple[int, ...]]]  # state -> {action: next state}
CaseKey = tuple[int, int, tuple[tuple[int, int], ...]]  # (action, own code, others' multiset as (code, n))


@dataclass(frozen=True)
class OverrideInfo:
    """What an override did: cases applied, cases dropped as conflicting, rules removed and added."""

    cases: int  # distinct (action, own code, others) cases applied
    conflicts: tuple[CaseKey, ...]  # cases whose objects went to different codes: left as the rules say
    rules_removed: int  # rules of the input replaced by their box differences
    rules_added: int  # pieces of box differences plus override rules


def observed_cases(observed: Observed) -> tuple[dict[CaseKey, int], tuple[CaseKey, ...]]:
    """(case -> observed next own code, conflicting cases) of a set of observed steps."""
    seen: dict[CaseKey, set[int]] = {}
    for state, steps in observed.items():
        total = Counter(int(c) for c in state)
        for action, nxt in steps.items():
            if len(nxt) != len(state):
                raise ValueError(f"observed step {tuple(state)} --{action}--> {tuple(nxt)} changes the object count")
            for c, c_next in zip(state, nxt):
                others = total.copy()
                others[int(c)] -= 1
                key = (int(action), int(c), tuple(sorted((x, n) for x, n in others.items() if n > 0)))
                seen.setdefault(key, set()).add(int(c_next))
    cases = {k: next(iter(v)) for k, v in seen.items() if len(v) == 1}
    return cases, tuple(sorted(k for k, v in seen.items() if len(v) > 1))


def _boxes(cases: Mapping[CaseKey, int]) -> dict[CaseKey, Bounds]:
    """Each case's box: exact counts of its others' codes, zero of the codes its siblings' others hold."""
    codes_of: dict[tuple[int, int], set[int]] = {}
    for a, c, others in cases:
        codes_of.setdefault((a, c), set()).update(x for x, _ in others)
    out = {}
    for a, c, others in cases:
        box = {x: (0, 1) for x in codes_of[(a, c)]}
        box.update({x: (n, n + 1) for x, n in others})
        out[(a, c, others)] = dict(sorted(box.items()))
    return out


def _overlap(r: Bounds, b: Bounds) -> bool:
    return all(max(r.get(x, (0, INF))[0], lo) < min(r.get(x, (0, INF))[1], hi) for x, (lo, hi) in b.items())


def box_difference(r: Bounds, b: Bounds) -> list[Bounds]:
    """r minus b as pairwise disjoint boxes (at most two per code b bounds); [r] if they do not overlap."""
    if not _overlap(r, b):
        return [dict(r)]
    pieces, rest = [], dict(r)
    for x, (b_lo, b_hi) in b.items():
        lo, hi = rest.get(x, (0, INF))
        if lo < b_lo:
            pieces.append({**rest, x: (lo, b_lo)})
        if b_hi < hi:
            pieces.append({**rest, x: (b_hi, hi)})
        rest[x] = (max(lo, b_lo), min(hi, b_hi))
    return [dict(sorted(p.items())) for p in pieces]


def override_rules_info(rules: RuleSet, observed: Observed) -> tuple[RuleSet, OverrideInfo]:
    """override_rules, with what it did (conflicting cases are left as the rules say)."""
    cases, conflicts = observed_cases(observed)
    boxes = _boxes(cases)
    by_group: dict[tuple[int, int], list[CaseKey]] = {}
    for key in cases:
        by_group.setdefault(key[:2], []).append(key)
    kept, removed, added = [], 0, []
    for r in rules.rules:
        group = by_group.get((r.action, r.code_from), [])
        pieces = [r.bounds()]
        for key in group:
            pieces = [p for q in pieces for p in box_difference(q, boxes[key])]
        if pieces == [r.bounds()]:
            kept.append(r)
            continue
        removed += 1
        added += [Rule.from_bounds(r.action, r.code_from, r.code_to, p) for p in pieces]
    added += [Rule.from_bounds(a, c, nxt, boxes[(a, c, o)]) for (a, c, o), nxt in cases.items() if nxt != c]
    codes = set(rules.vocabulary) | {int(c) for s, steps in observed.items() for n in [s, *steps.values()] for c in n}
    out = RuleSet(bits=rules.bits, vocabulary=tuple(sorted(codes)), max_objects=rules.max_objects,
                  rules=tuple(kept + added), n_rules_before_generalization=rules.n_rules_before_generalization)
    return out, OverrideInfo(cases=len(cases), conflicts=conflicts, rules_removed=removed, rules_added=len(added))


def override_rules(rules: RuleSet, observed: Observed) -> RuleSet:
    """The rules corrected by observed steps (state -> {action: next state}); see the module docstring."""
    return override_rules_info(rules, observed)[0]
