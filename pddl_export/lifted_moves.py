"""One action schema per lifted rule: what one robot move does to the objects it touches, as STRIPS literals.

rule_schema writes a rule of pddl_export.lifted_rules (of its own outcome, or of an alternative with its cost),
pool_schema a pool of rarer structures lifted over the levels, end_schema a pick at a far-row stick's end; `moves`
gathers them, one schema per distinct action. These are whole robot actions (pick and release together):
pddl_export.lifted_domain states them as the domain does (a cube's move in two halves, the occupancy, far-row moves
merged over their locations), and its module docstring describes the vocabulary.

The cost form is the all-outcomes determinisation of the rules: one action per outcome of a rule, each costing
OUTCOME_COST_UNIT * (1 - ln share) rounded (outcome_cost).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Iterable, Sequence

from pddl_export.end_moves import EndRule
from pddl_export.lifted_rules import LiftedRules, Rule, relative_change, release_locations
from pddl_export.lifted_scene import N_LOCATIONS, neighbours
from pddl_export.lifted_vocabulary import Schema, bit_literals, fluent_value, level_name, loc_name, negated_bits, \
    place_name, schema_text, surface, top_name

OUTCOME_COST_UNIT = 10  # the cost of a step m(z) always answered so; -ln share adds in the same unit


def outcome_cost(share: float) -> int:
    """An action's cost in the cost form: OUTCOME_COST_UNIT * (1 - ln share), rounded (share in (0, 1])."""
    if not 0 < share <= 1:
        raise ValueError(f"an outcome's share {share!r} must lie in (0, 1]")
    return OUTCOME_COST_UNIT + round(-OUTCOME_COST_UNIT * math.log(share))


def _bit_effects(rules: LiftedRules, term: str, new_kind: int, old_kind: int | None) -> list[str]:
    """Effects setting the kept bits to new_kind (only those that differ where the old value is known); the
    negative form follows where the domain has it (negated_bits)."""
    negated = negated_bits(rules)
    old = dict(rules.layout.kind_bits(old_kind)) if old_kind is not None else {}
    out = []
    for bit, value in rules.layout.kind_bits(new_kind):
        if old.get(bit) == value:
            continue
        on, off = f"(bit-{bit} {term})", f"(no-bit-{bit} {term})"
        if bit in negated:
            out += [on, f"(not {off})"] if value else [off, f"(not {on})"]
        else:
            out.append(on if value else f"(not {on})")
    return out


def _move_head(f: dict) -> tuple:
    """Where a rule's move picks and releases, and the schema's parameters and preconditions on o and the two
    locations: (pick, release, frm, to, params, pre), a location None and its term `?from` / `?to` where the
    schema is lifted over it. A lifted rule refined on where it releases fixes `?to` (one location) or excludes the
    locations it does not name (`(differ ?to l)`)."""
    cls = f["cls"]
    concrete = isinstance(cls, tuple)
    pick, release = cls if concrete else (None, f.get("to"))
    others: tuple = ()  # where a rule naming several release locations may not release
    if isinstance(release, tuple):
        release, others = (release[0], ()) if len(release) == 1 else \
            (None, tuple(x for x in release_locations(cls) if x not in release))
    frm = loc_name(pick) if concrete else "?from"
    # a lifted rule refined to one release location keeps ?to as a parameter, fixed by the static `(is ?to l2)`:
    # Fast Downward's invariant synthesis then sees ?from and ?to differ (it does not see a parameter differ from a
    # constant), and finds each location's height as one variable
    to = loc_name(release) if concrete else "?to"
    params: list[tuple[str, str]] = [("?o", "stick" if f["o.stick"] else "cube")]
    pre: list[str] = [f"(at ?o {frm})", f"(level ?o {level_name(f['o.level'])})",
                      f"(rests ?o {top_name(level_name(f['u.level']), surface(f['u.level'], f['u.at']))})",
                      f"(place ?o {place_name(f['o.place'])})"]
    if not concrete:
        params += [("?from", "location"), ("?to", "location")]
        pre.append(f"(differ ?from {to})")
        if release is not None:
            pre.append(f"(is ?to {loc_name(release)})")
        if cls == "near":
            pre += ["(near ?from)"] + (["(near ?to)"] if release is None else [])
        pre += [f"(differ ?to {loc_name(x)})" for x in others]
    return pick, release, frm, to, params, pre


def rule_schema(rules: LiftedRules, rule: Rule, index: int, alternative: int = 0, cost: int | None = None) -> Schema:
    """The action schema of one rule (see the module docstring for the vocabulary): of its own outcome, or of its
    alternative-th alternative; with a cost, the action increases total-cost by it."""
    f = rule.fields()
    concrete = isinstance(f["cls"], tuple)
    pick, release, frm, to, params, pre = _move_head(f)
    ho, hu, hv = level_name(f["o.level"]), level_name(f["u.level"]), level_name(f["v.level"])
    eff: list[str] = []
    if f.get("o.kind") is not None:
        pre += bit_literals(rules, "?o", f["o.kind"])
    outcome = rule.outcomes()[alternative][0]
    o_out, u_kind, v_kind, *r_out = outcome
    lands_on = o_out[1] == 0  # o ends on the release location (else off it: a far stick then covers no neighbour)
    new_o = level_name(o_out[2])

    # before: the heights of the locations o (or a rider) covers; `under`: what is left there once o is lifted;
    # tops / lifted: the same for what the top there is (a surface, or a parameter where the rule's key does not
    # say: a far-row stick landing over a neighbour of some height)
    before, under = {frm: ho}, {frm: hu}
    s_u = surface(f["u.level"], f["u.at"])
    tops: dict[str, str] = {frm: "block-top"}
    lifted = {frm: s_u}
    riders = _stick_ends(rules, f, pick, ho, before, under, params, pre, eff, tops, lifted) if concrete else []
    for loc, h in before.items():
        pre.append(f"(height {loc} {top_name(h, tops[loc])})")
    # what the release location and (for a far-row stick) its neighbours hold once o is lifted
    if to in before:
        if under[to] != hv:
            raise ValueError(f"rule {index}: the release location's level {hv} is not what lies under the stick")
        s_v = lifted[to]
    else:
        s_v = tops[to] = surface(f["v.level"], f["v.at"])
        pre.append(f"(height {to} {top_name(hv, s_v)})")
    landing = dict(zip((loc_name(n) for n in neighbours(release)), map(level_name, f["landing"]))) \
        if concrete and lands_on else {}
    _landing_tops(landing, before, under, tops, params, pre, index)
    after = {to: new_o}
    eff += [f"(not (at ?o {frm}))", f"(at ?o {to})"] + _replace("rests", "?o", top_name(hu, s_u), top_name(hv, s_v))
    ends = set(landing)  # the locations o's own ends will top (unless a rider ends on one)
    for loc, h in landing.items():
        after[loc] = new_o
        eff.append(f"(beneath {loc} {h})")
    eff += _replace("place", "?o", place_name(f["o.place"]), place_name(o_out[1]))
    eff += _replace("level", "?o", ho, new_o)
    eff += _bit_effects(rules, "?o", o_out[3], f.get("o.kind"))
    known = set(before) | set(landing) | {to}  # the locations whose heights the rule knows
    for i, n, term, hr in riders:
        eff += _rider_effects(rules, f, i, n, term, hr, r_out[i], (pick, release), lands_on, (ho, new_o), known,
                              after, index, ends)
    # the learned bits of what o leaves on top at its pick location, and of what it lands on
    for term, loc, level, kind, role in (("?u", frm, hu, u_kind, "u"), ("?v", to, hv, v_kind, "v")):
        if kind is None:
            continue
        params.append((term, "block"))
        pre += [f"(at {term} {loc})", f"(level {term} {level})"]
        if f.get(f"{role}.kind") is not None:
            pre += bit_literals(rules, term, f[f"{role}.kind"])
        eff += _bit_effects(rules, term, kind, f.get(f"{role}.kind"))
    eff += _height_effects(before, after, under, landing, tops, lifted, ends, (to, hv), index)
    eff += _stands_effects(pre, eff)
    # beneath facts a landing re-adds where it also lifted them cancel out; keep the effects consistent
    eff = _net_effects(eff)
    if cost is not None:
        cost = int(cost)
        eff.append(f"(increase (total-cost) {cost})")

    where = f"-{frm}-{to}" if concrete else (f"-to-{loc_name(release)}" if release is not None else "")
    name = (f"pick-release-{'stick' if f['o.stick'] else 'cube'}{where}-{index}"
            + (f"-alt{alternative}" if alternative else ""))
    text = schema_text(name, params, pre, eff, _comment(rule, f, alternative))
    return Schema(name, pick, release, text, tuple(params), tuple(dict.fromkeys(pre)), tuple(eff), alternative, cost)


def _landing_tops(landing: dict, before: dict, under: dict, tops: dict, params: list, pre: list, index: int) -> None:
    """Preconditions on the locations a far-row stick's ends will cover, and their tops in `tops`: what lies under
    the stick where it covered them already, else the table at h0, or a layer parameter tied to the level
    (`(same-level ?top_l4 h2)`: a block standing there or a stick's end, which the rule's key does not say)."""
    for loc, h in landing.items():
        if loc in before:
            if under[loc] != h:
                raise ValueError(f"rule {index}: a neighbour's level {h} is not what lies under the stick")
            continue
        # no hyphen in a parameter's name: pddlgym's parser splits `?t-l4 - layer` at its first one
        tops[loc] = "table" if h == level_name(0) else f"?top_{loc}"
        if tops[loc] != "table":
            params.append((tops[loc], "layer"))
            pre.append(f"(same-level {tops[loc]} {h})")
        pre.append(f"(height {loc} {top_name(h, tops[loc])})")


def _height_effects(before: dict, after: dict, under: dict, landing: dict, tops: dict, lifted: dict, ends: set,
                    release: tuple[str, str], index: int) -> list[str]:
    """The `height` effects of a move: every location it lifts from or lands on goes from its top before (level
    and what it is) to its top after: what now lands there (o, or o's own end, or a rider), else what lifting left."""
    to, hv = release
    eff: list[str] = []
    for loc in list(before) + [x for x in after if x not in before]:
        old = before.get(loc, hv if loc == to else landing.get(loc))
        new = after.get(loc, under.get(loc, old))
        if old is None or new is None:
            raise ValueError(f"rule {index}: the height at {loc} is not known before and after the move")
        old_s = tops[loc]
        new_s = ("stick-end" if loc in ends else "block-top") if loc in after else lifted.get(loc, old_s)
        eff += _replace("height", loc, top_name(old, old_s), top_name(new, new_s))
    return eff


def _stick_ends(rules: LiftedRules, f: dict, pick: int, ho: str, before: dict, under: dict, params: list, pre: list,
                eff: list, tops: dict, lifted: dict) -> list[tuple]:
    """A far-row stick's ends over its pick's neighbours: each end's rider (a parameter, with its description) or
    the stick itself on top there, and the level beneath it. Fills before/under/params/pre/eff and the tops there
    before and once the stick is lifted (what lies beneath an end is taken to be a block standing there, or the
    table); returns the riders as (index, location, term, level)."""
    riders = []
    sides = f["riders.sides"]
    for n, hb in zip(neighbours(pick), f["beneath"]):
        side = n - pick
        if side in sides:
            i = sides.index(side)
            term, hr = f"?r{i}", level_name(f["riders.level"][i])
            params.append((term, "block"))
            pre += [f"(at {term} {loc_name(n)})", f"(level {term} {hr})", f"(rests {term} {ho}-end)",
                    f"(place {term} {place_name(f['riders.place'][i])})"]
            if f.get("riders.kind") is not None:
                pre += bit_literals(rules, term, f["riders.kind"][i])
            riders.append((i, n, term, hr))
            before[loc_name(n)] = hr
            tops[loc_name(n)] = "block-top"
        else:
            before[loc_name(n)] = ho
            tops[loc_name(n)] = "stick-end"
        under[loc_name(n)] = level_name(hb)
        lifted[loc_name(n)] = surface(hb, True)
        pre.append(f"(beneath {loc_name(n)} {level_name(hb)})")
        eff.append(f"(not (beneath {loc_name(n)} {level_name(hb)}))")
    return riders


def _stands_effects(pre: Sequence[str], eff: Sequence[str]) -> list[str]:
    """The `stands` effects of a move: each block it moves from one (location, level) to another stops standing at
    the first and stands at the second. `(stands ?b ?l ?h)` repeats `at` and `level` together, so that Fast
    Downward's relaxed reachability sees which location and level a block can reach together: a goal no rule can
    build (a stick on a tower in the far row, where no rule puts one) is refused by the translator at once, where
    at and level alone are each reachable and the search would have to exhaust the task's states to prove it."""
    out: list[str] = []
    for term in dict.fromkeys(x.split()[1] for x in pre if x.startswith("(at ")):
        loc, level = fluent_value(pre, "at", term), fluent_value(pre, "level", term)
        new_loc, new_level = fluent_value(eff, "at", term) or loc, fluent_value(eff, "level", term) or level
        if level is not None and (loc, level) != (new_loc, new_level):
            out += [f"(not (stands {term} {loc} {level}))", f"(stands {term} {new_loc} {new_level})"]
    return out


def _replace(predicate: str, term: str, old: str, new: str) -> list[str]:
    """Effects moving a one-value fluent of term from old to new (none where they are equal)."""
    return [] if old == new else [f"(not ({predicate} {term} {old}))", f"({predicate} {term} {new})"]


def _rider_effects(rules: LiftedRules, f: dict, i: int, n: int, term: str, hr: str, change, move: tuple[int, int],
                   lands_on: bool, stick_levels: tuple[str, str], known: set, after: dict, index: int,
                   ends: set) -> list[str]:
    """Effects on rider i of a far-row stick (at neighbour n, level hr): it rides along to the shifted neighbour,
    or falls (it stays at its place's location, or the one m(z) says, on the table). Sets `after`'s height where a
    rider ends at a location whose height the rule knows, and takes that location out of `ends` (the stick's end
    there is not its top)."""
    pick, release = move
    ho, new_o = stick_levels
    shifted = n + release - pick
    new_r = level_name(change[2])
    if change[0] == "shift" and lands_on and shifted in neighbours(release):  # rides along
        after[loc_name(shifted)] = new_r
        ends.discard(loc_name(shifted))
        eff = [f"(not (at {term} {loc_name(n)}))", f"(at {term} {loc_name(shifted)})"]
        eff += _replace("rests", term, f"{ho}-end", f"{new_o}-end")
    else:
        where = change[0]
        new_loc = {"stay": n, "shift": shifted}.get(where, where if isinstance(where, int) else n)
        if not 0 <= new_loc < N_LOCATIONS:
            raise ValueError(f"rule {index}: a rider ends at no location ({new_loc})")
        if loc_name(new_loc) in known:
            after[loc_name(new_loc)] = new_r  # elsewhere the rule does not know the height it lands beside
            ends.discard(loc_name(new_loc))
        eff = [f"(not (rests {term} {ho}-end))", f"(rests {term} {level_name(0)})"]
        eff += _replace("at", term, loc_name(n), loc_name(new_loc))
    eff += _replace("place", term, place_name(f["riders.place"][i]), place_name(change[1]))
    eff += _replace("level", term, hr, new_r)
    return eff + _bit_effects(rules, term, change[3], f["riders.kind"][i] if f.get("riders.kind") else None)


def _net_effects(eff: list[str]) -> list[str]:
    """Drop a delete and an add of the same atom (the atom keeps its value), keeping the first order otherwise."""
    adds = {e for e in eff if not e.startswith("(not ")}
    dels = {e[5:-1] for e in eff if e.startswith("(not ")}
    both = adds & dels
    out, seen = [], set()
    for e in eff:
        atom = e[5:-1] if e.startswith("(not ") else e
        if atom in both or e in seen:
            continue
        seen.add(e)
        out.append(e)
    return out


def _comment(rule: Rule, f: dict, alternative: int = 0) -> str:
    outcome, share = rule.outcomes()[alternative]
    o = outcome[0]
    which = f"alternative {alternative}, {share:.0%} of the moves" if alternative else f"{rule.support} moves"
    return (f"; {which}: {'a stick' if f['o.stick'] else 'a cube'} "
            f"{'lands on' if o[1] == 0 else 'ends off'} its release location at level {o[2]}")


def moves(rules: LiftedRules, costs: bool = False) -> tuple[Schema, ...]:
    """One schema per rule, each a whole robot action (pick and release); in the cost form one per outcome of each
    rule, with its cost. `schemas` states them as the domain does.

    (A form with one schema per kind of move and a conditional effect per rule would ground to far fewer
    actions, but Fast Downward's translator then works out, for every fact one clause adds and another
    deletes, the negation of the other clauses' conditions: a 4-object task did not translate in 10 minutes.)
    """
    pools: dict[int, list[Rule]] = {}
    for r in rules.rules:
        if r.pool is not None:
            pools.setdefault(r.pool, []).append(r)
    pooled = [pool_schema(rules, number, members, outcome_cost(members[0].share) if costs else None)
              for number, members in sorted(pools.items())]
    pooled += [end_schema(rules, r, i, outcome_cost(r.share) if costs else None) for i, r in enumerate(rules.end_rules)]
    if not costs:
        return _distinct([rule_schema(rules, r, i) for i, r in enumerate(rules.rules) if r.pool is None] + pooled)
    out = []
    for i, r in enumerate(rules.rules):
        if r.pool is not None:
            continue
        for j, (_, share) in enumerate(r.outcomes()):
            try:
                out.append(rule_schema(rules, r, i, j, outcome_cost(share)))
            except ValueError:
                if j == 0:  # the rule's own outcome always writes (export_lifted checks it)
                    raise
                # an alternative whose heights cannot be stated from the rule's key: no action for it
    return _distinct(out + pooled)


def end_schema(rules: LiftedRules, rule: EndRule, index: int, cost: int | None = None) -> Schema:
    """The schema of an end rule (pddl_export.end_moves): the robot picks at `pick`, where the top is the end of a
    stick lying at `s` (its level ?h, `?e` the end's layer), and releases at `release`; the stick ends at the
    rule's destination, lying on the top it finds there (what it rested on at s, `?u`; what lay under one of its
    ends, `?b_l0`; or the top there, `?top`), one layer above it (`?new`). The static relation
    `(end-case-N ?h ?e ?u ?b_l.. [?top] ?new)` lists the rule's cases (Schema.statics): lifted over the levels
    without it, the schema grounds to thousands of actions per stick."""
    s, pick, release = rule.cls
    n, ends = rule.destination, neighbours(rule.cls[0])
    under = {q: f"?b_{loc_name(q)}" for q in ends}
    found = "?u" if n == s else under.get(n, "?top")
    params = [("?o", "stick"), ("?h", "layer"), ("?e", "layer"), ("?u", "layer")] + \
        [(t, "layer") for t in under.values()] + ([("?top", "layer")] if found == "?top" else []) + [("?new", "layer")]
    predicate = f"end-case-{index}"
    facts = []
    for h, (u, u_at), beneath, top in rule.cases:
        words = [level_name(h), f"{level_name(h)}-end", top_name(level_name(u), surface(u, u_at))]
        words += [level_name(b) for b in beneath]
        words += [top_name(level_name(top[0]), surface(*top))] if top is not None else []
        facts.append(f"({predicate} {' '.join(words)} {level_name(rule.new_level((h, (u, u_at), beneath, top)))})")
    ls, ln = loc_name(s), loc_name(n)
    pre = [f"(at ?o {ls})", "(level ?o ?h)", f"(place ?o {place_name(0)})", "(rests ?o ?u)", f"(height {ls} ?h)"]
    for q, b in under.items():
        pre += [f"(height {loc_name(q)} ?e)", f"(beneath {loc_name(q)} {b})"]
    if found == "?top":
        pre.append(f"(height {ln} ?top)")
    pre.append(f"({predicate} {' '.join(p for p, _ in params[1:])})")
    eff = [f"(not (at ?o {ls}))", f"(at ?o {ln})", "(not (rests ?o ?u))", f"(rests ?o {found})"] if n != s else []
    eff += _replace("place", "?o", place_name(0), place_name(rule.place))
    eff += ["(not (level ?o ?h))", "(level ?o ?new)"] + _bit_effects(rules, "?o", rule.kind, None)
    eff += [f"(not (beneath {loc_name(q)} {b}))" for q, b in under.items()]
    eff += [f"(not (height {ls} ?h))", f"(height {ls} {'?new' if n == s else '?u'})"]
    for q, b in under.items():
        eff += [f"(not (height {loc_name(q)} ?e))", f"(height {loc_name(q)} {'?new' if n == q else b})"]
    if found == "?top":
        eff += [f"(not (height {ln} ?top))", f"(height {ln} ?new)"]
    eff += [f"(not (stands ?o {ls} ?h))", f"(stands ?o {ln} ?new)"]
    if cost is not None:
        eff.append(f"(increase (total-cost) {int(cost)})")
    name = f"pick-release-stick-end-{loc_name(pick)}-{loc_name(release)}-{index}"
    comment = (f"; {rule.support} moves: picked at its end, a stick at {ls} ends at {ln} ({place_name(rule.place)}); "
               f"{predicate} lists its cases")
    params = tuple(params)
    signature = " ".join(f"{p} - layer" for p, _ in params[1:])
    return Schema(name, pick, release, schema_text(name, params, pre, eff, comment), params, tuple(pre), tuple(eff),
                  0, cost, statics=tuple(facts), predicate=f"({predicate} {signature})")


def pool_schema(rules: LiftedRules, number: int, members: Sequence[Rule], cost: int | None = None) -> Schema:
    """The one schema of a pool (lifted_distil._pool_rules): a cube's or near-row stick's move lifted over the
    levels as well as the locations. `?h` (o's level), `?t` (what it rests on), `?top` (the top at ?to) and `?new`
    (o's level after) are parameters, tied by the static relation `(pooled-N ?h ?t ?top ?new)` whose facts (in every
    problem: Schema.statics) list the pool's structures: the rule applies to no other, and no other rule to these.
    A release onto what it rested on (?t = ?top) deletes and adds the same fact: the add stands (PDDL's semantics)."""
    f = members[0].fields()
    where, place, up, kind = relative_change(f, members[0].outcome)
    predicate = f"pooled-{number}"
    facts = sorted({f"({predicate} {level_name(r.fields()['o.level'])} "
                    f"{top_name(level_name(r.fields()['u.level']), surface(r.fields()['u.level'], r.fields()['u.at']))} "
                    f"{top_name(level_name(r.fields()['v.level']), surface(r.fields()['v.level'], r.fields()['v.at']))} "
                    f"{level_name(r.fields()['v.level'] + up)})" for r in members})
    stick = f["o.stick"]
    params = (("?o", "stick" if stick else "cube"), ("?from", "location"), ("?to", "location"),
              ("?h", "layer"), ("?t", "layer"), ("?top", "layer"), ("?new", "layer"))
    pre = ["(at ?o ?from)", "(level ?o ?h)", "(rests ?o ?t)", f"(place ?o {place_name(f['o.place'])})",
           "(differ ?from ?to)"] + (["(near ?from)", "(near ?to)"] if f["cls"] == "near" else []) + \
        ["(height ?from ?h)", "(height ?to ?top)", f"({predicate} ?h ?t ?top ?new)"]
    eff = ["(not (at ?o ?from))", "(at ?o ?to)", "(not (rests ?o ?t))", "(rests ?o ?top)"]
    eff += _replace("place", "?o", place_name(f["o.place"]), place_name(place))
    eff += ["(not (level ?o ?h))", "(level ?o ?new)"] + _bit_effects(rules, "?o", kind, None)
    eff += ["(not (height ?from ?h))", "(height ?from ?t)", "(not (height ?to ?top))", "(height ?to ?new)"]
    eff += _stands_effects(pre, eff)
    if cost is not None:
        eff.append(f"(increase (total-cost) {int(cost)})")
    what = "a stick" if stick else "a cube"
    comment = (f"; {sum(r.support for r in members)} moves of {len(members)} rarer structures ({predicate} lists "
               f"them): {what} lands {up} levels above the top at ?to")
    name = f"pick-release-{'stick' if stick else 'cube'}-pooled-{number}"
    return Schema(name, None, None, schema_text(name, params, pre, eff, comment), params, tuple(pre), tuple(eff),
                  0, cost, statics=tuple(facts),
                  predicate=f"({predicate} ?h - layer ?t - layer ?top - layer ?new - layer)")


def _distinct(found: Iterable[Schema]) -> tuple[Schema, ...]:
    """One schema per action: rules whose keys differ only in what the PDDL does not state (whether a piece
    stands on top at the pick or release location) write the same parameters, preconditions and effects; the
    copies would only multiply the translator's grounded operators. The cheapest copy stays (the first among
    equals), in the place of the first, and its comment names the rules it stands for."""
    kept: dict[tuple, list[Schema]] = {}
    for s in found:
        body = (s.params, s.pre, s.eff if s.cost is None else s.eff[:-1])
        kept.setdefault(body, []).append(s)
    out = []
    for copies in kept.values():
        best = min(copies, key=lambda c: c.cost or 0)
        if len(copies) > 1:
            others = ", ".join(c.name for c in copies if c is not best)
            head, rest = best.text.split("\n", 1)
            best = dataclasses.replace(best, text=f"{head}; it also stands for {others}\n{rest}")
        out.append(best)
    return tuple(out)
