"""The lifted PDDL domain of distilled rules: its vocabulary, and the rules' moves as the domain states them.

One domain for any number of objects: typed blocks (`cube`, `stick`), the six table locations, eight levels and the
places as constants, and relations read from the location bits: `(at ?b ?l)` (nearest location), `(level ?b ?h)`
(its top, in 5 cm layers), `(place ?b ?p)` (on its location, or which way and how far off), `(height ?l ?t)` (the
top at a location: where a released object lands) and `(rests ?b ?t)` (what is left at its location when it is
lifted), where the top `?t` is a layer (`h0`: the table; `h3`: a block standing there, its top at level 3) or the
end of a far-row stick lying over the location from a neighbour (`h1-end`); `(beneath ?l ?h)` (what is left under a
stick's end); `(stands ?b ?l ?h)`, `at` and `level` together, which lets Fast Downward's relaxed exploration refuse
a goal no move builds in one place (lifted_moves._stands_effects); and `(vacant ?l ?h)`, no block standing at ?l
with its top at ?h, kept by every move, which lets its invariant synthesis find one block per location and level and
refuse a goal that puts two there (_occupancy). A goal also says what each block on its spot rests on
(lifted_problem._rests_fact), so that the relaxed check sees the tops a block can be put on. The ends keep a move
onto a stick's end and one onto a tower of the same height apart (the rules' `v.at`, `u.at`: without them both
actions would apply to either). The learned bits are unary predicates, `(bit-I ?b)` true where bit I is 1
(docs/DOMAIN.md says what they mean in a real run), with a negative form `no-bit-I` only for a bit some rule tests
as 0 (negated_bits), so that no precondition is negative; and `(differ ?a ?b)`, `(is ?a ?b)` (the same location),
`(near ?l)` and `(same-level ?t ?h)` are static facts of every problem. Each rule of `pddl_export.lifted_rules` is
one robot action in plain STRIPS with typing: no negative preconditions, no equality, no conditional effects, no
quantifiers, no axioms, so that Fast Downward (LM-cut included), pyperplan and pyval take it. `at` (or `holding`),
`level`, `rests` and `height` hold one value per block or location, which Fast Downward's translator finds.

A cube's move is stated in two halves, as a person would write it: `pick-cube ?o ?from ?h ?t` lifts the cube off the
top of its location (which drops to what it rested on; `(liftable ?h ?t)` lists the pairs some rule puts down) and
one `release-cube-N ?o ?to` per rule puts it down at the release location. Whole, each rule would ground once per
cube and pair of locations, and the translator's time follows its operators (schemas explains). `(hand-empty)` holds
between robot actions; every other move (a stick's) is one action that needs it. pddl_export.lifted_moves writes
each rule's schema, pddl_export.lifted_problem the problems, and pddl_export.lifted_plans.plan_decoder reads a plan
back as robot actions.

The `accurate` export adds schemas lifted over the levels too (lifted_moves.pool_schema: a pool of rarer structures;
end_schema: a pick at a far-row stick's end), each with a static relation whose facts list the cases it applies to
(Schema.statics; every problem states them, static_facts), so that every robot action still has at most one ground
action.

The cost form (`costs=True`: domain_pddl, lifted_problem.problem_pddl) is the all-outcomes determinisation of the
rules: one action per outcome of a rule (its own and its alternatives, `-altJ`), each costing
lifted_moves.OUTCOME_COST_UNIT * (1 - ln share) rounded (`:action-costs`, `(:metric minimize (total-cost))`;
pick-cube costs nothing, the release carries its rule's cost), so that a cost-aware search (A* with LM-cut) takes the plan whose steps m(z) answered most
often, as `rules-outcomes` does on the rules over whole codes.

A cube's move is lifted over both locations (pick-cube's `?from`, the release's `?to`), and so is a stick's moved
within the near row (`?from`, `?to`); a stick moved in or out of the far row covers its row neighbours with its
ends, and which of those overlap depends on the pair, so its rules name the two locations
(`pick-release-stick-l1-l2-...`); rules that say the same at other pairs are written as one schema lifted over the
locations, with a static relation listing them (merged_pairs).

    >>> text = domain_pddl(rules)                                        # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import re
from typing import Iterable, Sequence

from pddl_export.lifted_moves import moves
from pddl_export.lifted_rules import LiftedRules
from pddl_export.lifted_scene import N_LOCATIONS
from pddl_export.lifted_vocabulary import PLACES, Schema, domain_name, fluent_value, layer_names, loc_name, \
    model_hash_text, negated_bits, schema_text

_STANDS = re.compile(r"^\((not \()?stands (\S+) (\S+) ([^\s)]+)\)\)?$")


def _occupancy(s: Schema) -> Schema | None:
    """A schema with `(vacant ?l ?h)` kept: no block stands at location ?l with its top at level ?h. None where the
    move cannot state it (below).

    Each block a move lifts from a (location, level) must stand there (a precondition) and leaves it vacant; each
    block it puts at one needs it vacant and fills it. Fast Downward's invariant synthesis then finds, for every
    location and level, that at most one of `vacant` and the blocks' `stands` there holds (the scene model's own
    fact: every block covers its nearest location, on its spot or off it, so a second one lands on top of it), and
    its translator refuses at once a goal that puts two blocks at one location and level, which the height field's
    last layer (h7: a top at 35 cm or more) can state; otherwise the relaxed task reaches each of those goal facts
    and the search must exhaust every state the rules reach to prove the goal unreachable.

    None where a block lands at the level of the top it lands on (the height field's last layer on both: the
    location then holds two blocks at that level), where two blocks fill one place, or where a block may stay at its
    place (a stick dragged by its end that keeps its location, its levels before and after parameters):
    `schemas` then states no occupancy in the whole domain, so that every move applies as the rules say."""
    eff = list(s.eff[:-1] if s.cost is not None else s.eff)
    tail = list(s.eff[len(eff):])
    found = [m.groups() for m in map(_STANDS.match, eff) if m]  # (deleted, block, location, level)
    leaves = [(b, loc, h) for deleted, b, loc, h in found if deleted]
    fills = [(loc, h) for deleted, _, loc, h in found if not deleted]
    left, filled = {(loc, h) for _, loc, h in leaves}, set(fills)
    if len(filled) < len(fills) or any(f"(height {loc} {h})" in s.pre for loc, h in filled) or any(
            loc == loc2 and h != h2 and "?" in h + h2 for loc, h in filled for loc2, h2 in left):
        return None
    pre = _stands_preconditions(list(s.pre) + [f"(stands {b} {loc} {h})" for b, loc, h in leaves])
    for loc, h in sorted(filled - left):
        pre.append(f"(vacant {loc} {h})")
        eff.append(f"(not (vacant {loc} {h}))")
    eff += [f"(vacant {loc} {h})" for loc, h in sorted(left - filled)]
    pre, eff = tuple(dict.fromkeys(pre)), tuple(dict.fromkeys(eff)) + tuple(tail)
    if (pre, eff) == (s.pre, s.eff):
        return s
    head = s.text.split("\n  (:action ", 1)[0].strip() if "\n  (:action " in s.text else ""
    return dataclasses.replace(s, pre=pre, eff=eff, text=schema_text(s.name, s.params, pre, eff, head))


def _stands_preconditions(pre: list[str]) -> list[str]:
    """Preconditions with each block's `(at T L)` and `(level T H)` read as the one `(stands T L H)` they state
    together (every action keeps stands equal to at and level): the same ground actions, with one atom fewer to
    join for each block a move reads, which pays for the occupancy's (`_occupancy`) work in the translator."""
    out: list[str] = []
    for lit in pre:
        words = lit.strip("()").split()
        if words[0] in ("at", "level") and len(words) == 3 and fluent_value(pre, "at", words[1]) and \
                fluent_value(pre, "level", words[1]):
            if words[0] == "at":
                out.append(f"(stands {words[1]} {words[2]} {fluent_value(pre, 'level', words[1])})")
            continue
        out.append(lit)
    return list(dict.fromkeys(out))


PICK_CUBE = "pick-cube"


def _pick_cube() -> Schema:
    """The pick half of every cube's plain move (schemas)."""
    params = (("?o", "cube"), ("?from", "location"), ("?h", "layer"), ("?t", "layer"))
    pre = ("(hand-empty)", "(liftable ?h ?t)", "(at ?o ?from)", "(level ?o ?h)", "(rests ?o ?t)", "(height ?from ?h)")
    eff = ("(not (hand-empty))", "(holding ?o)", "(not (at ?o ?from))", "(not (stands ?o ?from ?h))",
           "(not (height ?from ?h))", "(height ?from ?t)")
    comment = ("; a cube is lifted off the top of its location, which drops to what it rested on; its level and what\n"
               "  ; it rested on stay with it until a release-cube action puts it down (liftable: the pairs some does)")
    return Schema(PICK_CUBE, None, None, schema_text(PICK_CUBE, params, pre, eff, comment), params, pre, eff,
                  step="pick")


def _pick_side(s: Schema) -> tuple[str, str] | None:
    """A cube's move whose pick side is the plain one (a lifted `?from`, the cube the top there, nothing else
    read or changed at ?from): its (level, rests) pair; else None (the move stays one action)."""
    if s.pick is not None or dict(s.params).get("?o") != "cube" or "?from" not in dict(s.params):
        return None
    level = next((p.split()[2][:-1] for p in s.pre if p.startswith("(level ?o ")), None)
    rests = next((p.split()[2][:-1] for p in s.pre if p.startswith("(rests ?o ")), None)
    if level is None or rests is None:
        return None
    pre = {p for p in s.pre if "?from" in p}
    eff = {e for e in s.eff if "?from" in e}
    if pre != {"(at ?o ?from)", f"(height ?from {level})", "(differ ?from ?to)"} or \
            eff != {"(not (at ?o ?from))", f"(not (stands ?o ?from {level}))", f"(not (height ?from {level}))",
                    f"(height ?from {rests})"}:
        return None
    return level, rests


def _halves(s: Schema) -> Schema:
    """A move as the domain states it: a cube's plain move becomes its release half (pick-cube is its pick half),
    any other move one action that needs the hand empty."""
    comment = s.text.split("\n", 1)[0].strip()
    if _pick_side(s) is None:
        pre = ("(hand-empty)",) + s.pre
        return dataclasses.replace(s, pre=pre, text=schema_text(s.name, s.params, pre, s.eff, comment))
    params = tuple((p, t) for p, t in s.params if p != "?from")
    pre = ("(holding ?o)",) + tuple(p for p in s.pre if "?from" not in p)
    eff = ("(not (holding ?o))", "(hand-empty)") + tuple(e for e in s.eff if "?from" not in e)
    name = s.name.replace("pick-release-cube", "release-cube", 1)
    return dataclasses.replace(s, name=name, params=params, pre=pre, eff=eff, step="release",
                               text=schema_text(name, params, pre, eff, comment))


def liftable(found: Iterable[Schema]) -> list[tuple[str, str]]:
    """The (level, rests) pairs of a cube that some release-cube action puts down: pick-cube lifts only these (a
    pooled schema's are those of the structures its static facts list)."""
    pairs = set()
    for s in found:
        if (pair := _pick_side(s)) is not None:
            pairs |= {tuple(fact.strip("()").split()[1:3]) for fact in s.statics} if s.statics else {pair}
    return sorted(pairs)


def static_facts(found: Sequence[Schema]) -> list[str]:
    """The facts of the rules' static relations, which every problem states: the liftable pairs and the pooled
    schemas' structures."""
    return [f"(liftable {h} {t})" for h, t in liftable(found)] + \
        list(dict.fromkeys(x for s in merged_pairs(found) for x in s.statics))


_LOCATION = re.compile(r"\bl[0-5]\b")  # a location constant in a literal (l0 ... l5; not ?top_l2)
PAIR_MOVE = "pick-release-stick-far"  # the name of a merged far-row move (merged_pairs)


def _pair_template(s: Schema) -> tuple[tuple, tuple, tuple, tuple[str, ...]]:
    """A far-row move's literals with its locations as parameters: its pick location ?from, its release location
    ?to, the others (the neighbours its ends cover, where riders land) ?n1, ?n2, ... in the order they first
    appear; and the locations, in the order of those parameters."""
    roles = {loc_name(s.pick): "?from", loc_name(s.release): "?to"}
    for lit in s.pre + s.eff:
        for c in _LOCATION.findall(lit):
            roles.setdefault(c, f"?n{len(roles) - 1}")
    sub = lambda lit: _LOCATION.sub(lambda m: roles[m.group(0)], lit)  # noqa: E731
    return tuple(roles.values()), tuple(sub(x) for x in s.pre), tuple(sub(x) for x in s.eff), tuple(roles)


def merged_pairs(found: Sequence[Schema]) -> tuple[Schema, ...]:
    """Far-row moves that differ only in their locations as one schema: `pick-release-stick-far-N ?o ?from ?to
    ?n1 ...`, whose static relation `(pair-move-N ?from ?to ?n1 ...)`, stated in every problem, lists the locations
    of each move it stands for. The same ground actions, in fewer schemas: Fast Downward's translator pays for
    every schema it parses, normalises and synthesises invariants over, whether or not it grounds (a far-row move
    names its locations, one schema per pair and level case: 97 of the shipped domain's 120 schemas; docs/DOMAIN.md).
    Moves of one pair, and any move alone in its template, stay as they are; the first of a group gives the
    merged schema its place."""
    keys: list[tuple | None] = []  # per schema: its template, with what else must match; None: no pair move
    groups: dict[tuple, list[tuple[Schema, tuple[str, ...]]]] = {}
    for s in found:
        key = None
        if s.step == "move" and s.pick is not None:
            roles, pre, eff, where = _pair_template(s)
            key = (s.params, roles, pre, eff, s.alternative, s.cost)
            groups.setdefault(key, []).append((s, where))
        keys.append(key)
    numbers = {key: n for n, key in enumerate(k for k, v in groups.items() if len({w[:2] for _, w in v}) > 1)}
    out, done = [], set()
    for s, key in zip(found, keys):
        if key not in numbers:
            out.append(s)
            continue
        if key in done:
            continue
        done.add(key)
        _, roles, pre, eff, _, _ = key
        members = groups[key]
        n = numbers[key]
        predicate = f"pair-move-{n}"
        name = f"{PAIR_MOVE}-{n}" + (f"-alt{s.alternative}" if s.alternative else "")
        params = (s.params[0],) + tuple((r, "location") for r in roles[:2]) + s.params[1:] + \
            tuple((r, "location") for r in roles[2:])
        head = (f"({predicate} {' '.join(roles)})",)
        comment = (f"; one move at {len(members)} pairs of locations ({predicate} lists them): "
                   + "; ".join(f"{m.name}, {m.text.split(chr(10), 1)[0].strip().lstrip('; ')}" for m, _ in members))
        statics = tuple(f"({predicate} {' '.join(w)})" for _, w in members)
        out.append(Schema(name, None, None, schema_text(name, params, head + pre, eff, comment), params,
                          head + pre, eff, s.alternative, s.cost, statics=statics,
                          predicate=f"({predicate} {' '.join(f'{r} - location' for r in roles)})"))
    return tuple(out)


def schemas(rules: LiftedRules, costs: bool = False) -> tuple[Schema, ...]:
    """The domain's action schemas: pick-cube, the release half of every cube's plain move, and every other move
    whole.

    A cube's move, grounded whole, is one action per cube and pair of locations (30 pairs) for each rule: with 4
    cubes, about 1,900 operators that Fast Downward's translator instantiates before it searches. Split, the
    release half is one per cube and release location (6), and one pick-cube per cube, location and (level,
    rests) pair: a third of the operators, the same robot actions. A release at the location the cube was
    picked from puts it back on what it rested on; `plan_decoder` drops such a pair from the robot's plan.
    """
    found = merged_pairs(moves(rules, costs))
    halves = tuple(_halves(s) for s in found)
    if any(s.step == "release" for s in halves):
        halves = (_pick_cube(),) + halves
    kept = tuple(_occupancy(s) for s in halves)
    return halves if None in kept else kept


def domain_pddl(rules: LiftedRules, costs: bool = False) -> str:
    """The lifted domain's text; with costs, its all-outcomes cost form (the module docstring)."""
    negated = negated_bits(rules)
    bits = " ".join(f"(bit-{b} ?b - block)" + (f" (no-bit-{b} ?b - block)" if b in negated else "")
                    for b in rules.layout.kept)
    locs = " ".join(loc_name(i) for i in range(N_LOCATIONS))
    lvls = " ".join(layer_names())
    found = schemas(rules, costs)
    body = "".join(s.text for s in found)
    pooled = " ".join(dict.fromkeys(s.predicate for s in found if s.predicate))
    requirements = ":strips :typing :action-costs" if costs else ":strips :typing"
    functions = "  (:functions (total-cost) - number)\n" if costs else ""
    return (f"; A lifted domain distilled from the transition model {model_hash_text(rules)} by symlearn.\n"
            f"; Blocks stand at locations l0-l5 (far row l0-l2, near row l3-l5) on a support, at a level (5 cm layers).\n"
            f"(define (domain {domain_name(rules)})\n"
            f"  (:requirements {requirements})\n"
            # one line per parent type: pddlgym's parser reads a parent's name up to the end of its line
            "  (:types\n    block location layer position - object\n    cube stick - block)\n"
            f"  (:constants {locs} - location {' '.join(PLACES)} - position\n    {lvls} - layer)\n"
            "  (:predicates (at ?b - block ?l - location) (level ?b - block ?h - layer)\n"
            "               (stands ?b - block ?l - location ?h - layer) (vacant ?l - location ?h - layer)\n"
            "               (rests ?b - block ?t - layer) (height ?l - location ?t - layer) (same-level ?t - layer ?h - layer)\n"
            "               (beneath ?l - location ?h - layer) (place ?b - block ?p - position)\n"
            "               (near ?l - location) (differ ?a - location ?b - location) (is ?a - location ?b - location)\n"
            "               (hand-empty) (holding ?b - block) (liftable ?h - layer ?t - layer)"
            + (f"\n               {bits}" if bits else "") + (f"\n               {pooled}" if pooled else "") + ")\n"
            + functions + body + ")\n")
