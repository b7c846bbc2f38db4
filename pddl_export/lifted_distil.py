"""Distilling lifted rules from observed moves: a decision tree per move structure, pools of rarer structures, and
each rule's share of m(z)'s answers with its alternatives (pddl_export.lifted_rules says what a rule is).

`distil_lifted` grows a tree per STRUCTURE key, splitting on the refinement (REFINEMENTS) that explains the most
further moves (at least MIN_GAIN of them); rules under a split on the release location that share an outcome are
one rule naming all their locations. Structures seen fewer than min_count times are pooled (pool_key) where the
pool's moves mostly agree on what o does relative to the top it lands on (relative_change). `with_network_answers`
recounts each rule's share and alternatives (outcomes at least ALTERNATIVE_MIN_SHARE of the time) over m(z)'s
answers.
"""
from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from typing import Sequence

from pddl_export.lifted_rules import MAX_ALTERNATIVES, POOLED_CLASSES, REFINEMENTS, STRUCTURE, LiftedRules, Outcome, \
    Rule, key_of, pool_key, pool_statement, relative_change, release_locations, writable
from pddl_export.lifted_scene import CodeLayout

MIN_GAIN = 0.05  # a split must explain this share of its node's moves more (distil_lifted, LiftedConfig)
ALTERNATIVE_MIN_SHARE = 0.1  # an outcome this often m(z)'s answer among a rule's moves becomes an alternative
POOL_MIN_COUNT = 20  # moves a pool needs before its majority outcome is given to its structures
POOL_STRUCTURE_MIN = 5  # moves a structure needs to join its pool (each one is a static fact of every problem)


def _pooled(sig: dict, change: tuple) -> Outcome | None:
    """The outcome of a pool's relative change in a structure: o lands change[2] levels above the top it lands on,
    nothing else changes (None where that level is off the scale)."""
    where, place, up, kind = change
    level = sig["v.level"] + up
    return ((where, place, level, kind), None, None) if where == "to" and 0 <= level < 8 else None


def _pool_rules(moves: Sequence[tuple[dict, Outcome]], handled: set, pool_min_count: int,
                pool_structure_min: int, classes: Sequence[str] = POOLED_CLASSES) -> list[Rule]:
    """Rules of the pooled structures: every structure of a lifted class with no rule of its own (`handled`: those
    distil_lifted grew a tree for), seen at least pool_structure_min times, takes its pool's majority relative
    change where the pool has pool_min_count moves."""
    pools: dict = defaultdict(Counter)
    seen: dict = defaultdict(list)
    for sig, out in moves:
        key = key_of(sig, 0)
        if sig["cls"] in classes and not sig["riders.sides"] and key not in handled:
            pools[pool_key(sig)][relative_change(sig, out)] += 1
            seen[key].append(sig)
    # pools whose structures all take the same change in the same way (class, o's place) are one schema: the
    # structures its static facts list say which pool key each came from
    written = {k: pool_statement(k, c.most_common(1)[0][0]) for k, c in pools.items()}
    numbers = {w: i for i, w in enumerate(sorted(set(written.values()), key=repr))}
    out: list[Rule] = []
    for key, sigs in seen.items():
        tally = pools[pool_key(sigs[0])]
        total = sum(tally.values())
        if len(sigs) < pool_structure_min or total < pool_min_count:
            continue
        change, n = tally.most_common(1)[0]
        outcome = _pooled(sigs[0], change)
        if outcome is not None:
            out.append(Rule(0, key, outcome, len(sigs), round(n / total, 4), (), numbers[written[pool_key(sigs[0])]]))
    return out


def _best_split(node: list, used: tuple[str, ...], least: int, best: Outcome, n_best: int) -> tuple[str | None, int]:
    """The refinement field (REFINEMENTS, none of used) whose values' own majorities explain the most moves of node
    beyond its majority outcome best (n_best moves), and how many more; (None, 0) where none explains more."""
    split, gain = None, 0
    for (name,) in REFINEMENTS:
        if name in used:
            continue
        parts: dict = defaultdict(Counter)
        for sig, out in node:
            parts[sig[name]][out] += 1
        # a value with too few moves keeps the node's answer (distil_lifted), so it explains no more than that
        g = sum(c.most_common(1)[0][1] if sum(c.values()) >= least else c[best] for c in parts.values()) - n_best
        if g > gain:
            split, gain = name, g
    return split, gain


def _distil_stats(lookup: LiftedRules, moves: Sequence[tuple[dict, Outcome]], n_structures: int, n_own: int,
                  unwritable: int) -> dict:
    """What distil_lifted reports: counts of its rules (the first n_own its own, the rest pooled), and how many of
    the moves a rule of lookup covers and how often its outcome is theirs."""
    rules = lookup.rules
    hits = [lookup.rule_for(sig) for sig, _ in moves]
    agree = sum(h is not None and h.outcome == out for h, (_, out) in zip(hits, moves))
    n_covered = sum(h is not None for h in hits)
    return {"moves": len(moves), "structures": n_structures, "rules": len(rules), "pooled_rules": len(rules) - n_own,
            "pools": len({r.pool for r in rules if r.pool is not None}),
            "structures_without_move": unwritable, "covered_moves": n_covered,
            "agreement": round(agree / n_covered, 4) if n_covered else 0.0}


def distil_lifted(layout: CodeLayout, stick_of: dict, moves: Sequence[tuple[dict, Outcome]], min_count: int = 3,
                  model_hash: str = "", rider_min_count: int | None = None,
                  pair_min_count: int | None = None, min_gain: float = MIN_GAIN,
                  pool_min_count: int | None = None, pool_structure_min: int = POOL_STRUCTURE_MIN,
                  pool_classes: Sequence[str] = POOLED_CLASSES) -> LiftedRules:
    """Rules from (signature, outcome) moves, as a decision tree per move structure.

    The moves of one STRUCTURE key are a node. A node becomes a rule (its majority outcome) unless some refinement
    field (REFINEMENTS) tells its outcomes apart: splitting on the field whose values' own majorities explain the
    most further moves, when that gain is at least `min_gain` of the node's moves (and at least 2 moves), makes one
    node per value, refined in turn. A condition stays only where the outcome depends on it.

    A node needs `min_count` moves to become a rule (rider_min_count where its outcome moves riders, which are rare
    in any data; pair_min_count where the move's class names its two locations, a far-row stick's, whose schema
    grounds to a handful of actions however many objects a task has). A value with fewer moves under a split node
    takes the node's majority: too few to tell it apart.

    With pool_min_count, the rarer structures of pool_classes (some of POOLED_CLASSES) are pooled (_pool_rules; the
    module docstring).
    """
    rider_min = min_count if rider_min_count is None else rider_min_count
    pair_min = min_count if pair_min_count is None else pair_min_count
    groups: dict = defaultdict(list)
    for sig, out in moves:
        groups[key_of(sig, 0)].append((sig, out))
    rules: list[Rule] = []
    tallies: dict = {}  # a rule's key -> the outcomes of its moves (a merged rule's are its leaves' together)
    unwritable = 0

    def needed(key: tuple, out: Outcome) -> int:
        base = pair_min if isinstance(dict(key)["cls"], tuple) else min_count
        return min(base, rider_min) if len(out) > 3 else base

    def leaf(key: tuple, tally: Counter, outcome: Outcome) -> None:
        nonlocal unwritable
        if not writable(outcome):
            unwritable += 1
            return
        tallies[key] = tally
        rules.append(_with_alternatives(Rule(len(key) - len(STRUCTURE), key, outcome, sum(tally.values())), tally))

    def grow(key: tuple, node: list, used: tuple[str, ...]) -> None:
        tally = Counter(out for _, out in node)
        best, n_best = tally.most_common(1)[0]
        least = needed(key, best)
        split, gain = _best_split(node, used, least, best, n_best)
        if split is None or gain < max(2, min_gain * len(node)):
            leaf(key, tally, best)
            return
        parts: dict = defaultdict(list)
        for sig, out in node:
            parts[sig[split]].append((sig, out))
        first = len(rules)
        for value, part in sorted(parts.items(), key=lambda kv: repr(kv[0])):
            child = key + ((split, value),)
            if len(part) >= least:
                grow(child, part, used + (split,))
            else:
                leaf(child, Counter(out for _, out in part), best)
        if split == "to":
            rules[first:] = _merge_destinations(key, rules[first:], best, tallies)

    handled = set()
    for key, node in groups.items():
        out = Counter(o for _, o in node).most_common(1)[0][0]
        if len(node) >= needed(key, out):
            handled.add(key)
            grow(key, node, ())
    n_own = len(rules)
    if pool_min_count is not None:
        rules += _pool_rules(moves, handled, pool_min_count, pool_structure_min, pool_classes)
    stats = _distil_stats(LiftedRules(layout, stick_of, tuple(rules)), moves, len(groups), n_own, unwritable)
    return LiftedRules(layout, stick_of, tuple(sorted(rules, key=lambda r: (repr(r.key), r.depth))),
                       model_hash, stats)


def _merge_destinations(key: tuple, children: list[Rule], best: Outcome, tallies: dict) -> list[Rule]:
    """The rules under a node split on where the move releases, with the leaves of one outcome merged into one rule
    whose "to" names all their locations (a schema with `?to` and `(differ ?to l)` for the others, not one per
    location), its share and alternatives those of its leaves' moves together. Locations no move released at join
    the node's own answer, as the unsplit node would have had it."""
    depth = len(key) - len(STRUCTURE) + 1
    leaves = [r for r in children if len(r.key) == len(key) + 1]
    seen = {r.key[-1][1] for r in children}
    by_outcome: dict = defaultdict(list)
    for r in leaves:
        by_outcome[r.outcome].append(r)
    unseen = tuple(d for d in release_locations(dict(key)["cls"]) if d not in seen)
    if unseen and best not in by_outcome and writable(best):
        by_outcome[best] = []
    merged = []
    for outcome, group in by_outcome.items():
        where = tuple(sorted({r.key[-1][1] for r in group} | (set(unseen) if outcome == best else set())))
        tally = sum((tallies[r.key] for r in group), Counter())
        rule = Rule(depth, key + (("to", where),), outcome, sum(tally.values()))
        tallies[rule.key] = tally
        merged.append(_with_alternatives(rule, tally))
    return merged + [r for r in children if len(r.key) > len(key) + 1]


def with_network_answers(rules: LiftedRules, answers: Sequence[tuple[dict, Outcome]]) -> LiftedRules:
    """The rules with each one's share and alternatives recounted over m(z)'s answers (signature, outcome) on the
    moves it covers: rules distilled from observed outcomes state what the world did; the cost form then weighs
    each outcome by how often m(z) gives it."""
    tallies: dict = defaultdict(Counter)
    pooled: dict = defaultdict(Counter)  # a pool's answers: m(z)'s relative changes over all its structures
    for sig, out in answers:
        r = rules.rule_for(sig)
        if r is not None and r.pool is not None:
            pooled[r.pool][relative_change(sig, out) if writable(out) else None] += 1
        elif r is not None:
            tallies[r.key][out] += 1
    redone = []
    for r in rules.rules:
        if r.pool is not None:  # one share for the pool, as its schema states one outcome for all its structures
            t = pooled.get(r.pool)
            if t:
                n = t[relative_change(r.fields(), r.outcome)]
                r = dataclasses.replace(r, share=round(n / sum(t.values()), 4) if n else
                                        round(1 / (sum(t.values()) + 1), 4))
            redone.append(r)
            continue
        t = tallies.get(r.key)
        if not t:
            redone.append(r)
            continue
        r2 = _with_alternatives(dataclasses.replace(r, share=1.0, alternatives=()), t)
        if r2.share == 0:  # m(z) never answered the rule's own outcome: it keeps share 1/(n+1) beside its answers
            r2 = dataclasses.replace(r2, share=round(1 / (sum(t.values()) + 1), 4))
        redone.append(r2)
    return dataclasses.replace(rules, rules=tuple(redone))


def _with_alternatives(rule: Rule, answers: Counter) -> Rule:
    """The rule with its outcome's share of m(z)'s answers and the other writable answers of at least
    ALTERNATIVE_MIN_SHARE (the MAX_ALTERNATIVES most frequent)."""
    total = sum(answers.values())
    if not total:
        return rule
    alts = tuple((out, round(n / total, 4)) for out, n in answers.most_common()
                 if out != rule.outcome and writable(out) and n / total >= ALTERNATIVE_MIN_SHARE)[:MAX_ALTERNATIVES]
    return dataclasses.replace(rule, share=round(answers[rule.outcome] / total, 4), alternatives=alts)
