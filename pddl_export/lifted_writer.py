"""The lifted PDDL domain of distilled rules, its problems, and plans read back as robot actions.

One domain for any number of objects: typed blocks (`cube`, `stick`), the six table locations, eight levels and the
places as constants, and relations read from the location bits: `(at ?b ?l)` (nearest location), `(level ?b ?h)`
(its top, in 5 cm layers), `(place ?b ?p)` (on its location, or which way and how far off), `(height ?l ?t)`
(the top at a location: where a released object lands) and `(rests ?b ?t)` (what is left at its location when it
is lifted), where the top `?t` is a layer (`h0`: the table; `h3`: a block standing there, its top at level 3) or
the end of a far-row stick lying over the location from a neighbour (`h1-end`); `(beneath ?l ?h)` (what is
left under a stick's end); `(stands ?b ?l ?h)`, `at` and `level` together, which lets Fast Downward's relaxed
exploration refuse a goal no move builds in one place (_stands_effects); and `(vacant ?l ?h)`, no block standing
at ?l with its top at ?h, kept by every move, which lets its invariant synthesis find one block per location and
level and refuse a goal that puts two there (_occupancy). A goal also says what each block on its spot rests on
(_rests_fact), so that the relaxed check sees the tops a block can be put on. The ends keep a move onto a stick's end
and one onto a tower of the same height apart (the rules' `v.at`, `u.at`: without them both actions would apply to
either). The learned bits are unary
predicates, `(bit-I ?b)` true where bit I is 1 (docs/DOMAIN.md says what they mean in a real run), with a negative
form `no-bit-I` only for a bit some rule tests as 0 (negated_bits), so that no precondition is negative; and
`(differ ?a ?b)`, `(is ?a ?b)` (the same location), `(near ?l)` and `(same-level ?t ?h)` are static facts of every
problem. Each rule of `pddl_export.lifted_rules` is one robot action in plain STRIPS with typing: no negative
preconditions, no equality, no conditional effects, no quantifiers, no axioms, so that Fast Downward (LM-cut
included), pyperplan and pyval take it. `at` (or `holding`), `level`, `rests` and `height` hold one value per block
or location, which Fast Downward's translator finds.

A cube's move is stated in two halves, as a person would write it: `pick-cube ?o ?from ?h ?t` lifts the cube off
the top of its location (which drops to what it rested on; `(liftable ?h ?t)` lists the pairs some rule puts
down) and one `release-cube-N ?o ?to` per rule puts it down at the release location. Whole, each rule would ground
once per cube and pair of locations, and the translator's time follows its operators (schemas explains).
`(hand-empty)` holds between robot actions; every other move (a stick's) is one action that needs it.
plan_decoder reads a plan back as robot actions.

The `accurate` export adds schemas lifted over the levels too (pool_schema: a pool of rarer structures; end_schema:
a pick at a far-row stick's end), each with a static relation whose facts list the cases it applies to
(Schema.statics; every problem states them, static_facts), so that every robot action still has at most one
ground action.

The cost form (`costs=True`: domain_pddl, problem_pddl) is the all-outcomes determinisation of the rules: one
action per outcome of a rule (its own and its alternatives, `-altJ`), each costing OUTCOME_COST_UNIT * (1 - ln
share) rounded (`:action-costs`, `(:metric minimize (total-cost))`; pick-cube costs nothing, the release carries
its rule's cost), so that a cost-aware search (A* with LM-cut) takes the plan whose steps m(z) answered most often,
as `rules-outcomes` does on the rules over whole codes.

A cube's move is lifted over both locations (pick-cube's `?from`, the release's `?to`), and so is a stick's moved
within the near row (`?from`, `?to`); a stick
moved in or out of the far row covers its row neighbours with its ends, and which of those overlap depends on
the pair, so its rules name the two locations (`pick-release-stick-l1-l2-...`); rules that say the same at other
pairs are written as one schema lifted over the locations, with a static relation listing them (merged_pairs).

    >>> text = domain_pddl(rules)                                        # doctest: +SKIP
    >>> problem_pddl(rules, start_codes, goal, "p01")                    # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Iterable, Sequence

from pddl_export.end_moves import EndRule
from pddl_export.lifted_rules import LiftedRules, Rule, relative_change, release_locations
from pddl_export.lifted_scene import FAR_ROW, NEAR_ROW, N_LOCATIONS, neighbours, read_scene, top_of
from pddl_export.pddl_writer import checked_name
from pddl_export.symbolic import SymbolicGoal

LEVELS = 8
OUTCOME_COST_UNIT = 10  # the cost of a step m(z) always answered so; -ln share adds in the same unit
SURFACES = ("table", "block-top", "stick-end")  # what the top at a location is, and what a block rests on


def surface(level: int, stands: bool) -> str:
    """The surface at a level: the table (level 0), a block standing at the location, or a far-row stick's end."""
    return SURFACES[0] if level == 0 else SURFACES[1] if stands else SURFACES[2]


def top_name(layer: str, what: str) -> str:
    """The layer constant of a top: `h3` (the table at h0, or a block standing there), `h3-end` (a stick's end);
    a parameter (`?top_l4`) stands for itself. One value per location or block, so that Fast Downward's invariant
    synthesis (one counted argument per predicate) finds `height` and `rests` as multi-valued variables."""
    if what.startswith("?"):
        return what
    return f"{layer}-end" if what == SURFACES[2] else layer


def layer_names() -> list[str]:
    """Every layer constant: the levels h0-h7 and the stick ends h1-end-h7-end."""
    return [level_name(h) for h in range(LEVELS)] + [f"{level_name(h)}-end" for h in range(1, LEVELS)]


def outcome_cost(share: float) -> int:
    """An action's cost in the cost form: OUTCOME_COST_UNIT * (1 - ln share), rounded (share in (0, 1])."""
    if not 0 < share <= 1:
        raise ValueError(f"an outcome's share {share!r} must lie in (0, 1]")
    return OUTCOME_COST_UNIT + round(-OUTCOME_COST_UNIT * math.log(share))


def loc_name(loc: int) -> str:
    return f"l{int(loc)}"


def level_name(h: int) -> str:
    return f"h{int(h)}"


def model_hash_text(rules: LiftedRules) -> str:
    """The transition model's hash as the domain states it (checked_name: a piece of a PDDL name), or 'nohash'."""
    return checked_name(rules.model_hash, "the lifted rules' model_hash", "part") if rules.model_hash else "nohash"


def domain_name(rules: LiftedRules) -> str:
    """The domain's name: carries the transition model's hash, so two runs' domains are told apart."""
    return checked_name(f"symlearn-{model_hash_text(rules)}", "domain name")


@dataclass(frozen=True)
class Schema:
    """One action schema: its name, the robot action it stands for, its parts and its PDDL text."""

    name: str
    pick: int | None  # None: lifted (?from is the first parameter after the block)
    release: int | None  # None: lifted (?to follows ?from); a lifted schema refined on where it releases fixes it
    text: str
    params: tuple = ()
    pre: tuple = ()
    eff: tuple = ()
    alternative: int = 0  # which of its rule's outcomes (0: the rule's own)
    cost: int | None = None  # the cost form's action cost (its last effect increases total-cost by it)
    step: str = "move"  # "move": one robot action; "pick" / "release": its two halves (a cube's move, split)
    statics: tuple = ()  # facts every problem states for it: a pooled schema's structures (pool_schema)
    predicate: str = ""  # the static relation a pooled schema declares, with its typed parameters


def negated_bits(rules: LiftedRules) -> frozenset[int]:
    """The kept learned bits some rule's condition reads as 0 (LiftedRules.tested_kinds): only these get a negative
    form `no-bit-I`, so that no precondition is negative; every other bit is one predicate, true where the bit is 1
    (as a person would write it), which spares the translator two atoms per changed bit of every action."""
    return frozenset(bit for kind in rules.tested_kinds for bit, value in rules.layout.kind_bits(kind) if not value)


def _bit_literals(rules: LiftedRules, term: str, kind: int) -> list[str]:
    """Literals fixing a piece's kept learned bits to `kind` (packed in layout.kept order): `bit-I` for a 1, and
    for a 0 `no-bit-I` where the domain has it (negated_bits)."""
    negated = negated_bits(rules)
    return [f"(bit-{bit} {term})" if value else f"(no-bit-{bit} {term})"
            for bit, value in rules.layout.kind_bits(kind) if value or bit in negated]


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
        pre += _bit_literals(rules, "?o", f["o.kind"])
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
            pre += _bit_literals(rules, term, f[f"{role}.kind"])
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
    text = _schema_text(name, params, pre, eff, _comment(rule, f, alternative))
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


PLACES = ("on-spot", "minus-y-near", "minus-y-mid", "minus-y-far", "plus-y-near", "plus-y-mid", "plus-y-far", "off-x")


def place_name(p: int) -> str:
    """The place field's value as a constant: on its location, or which way (y) and how far off it (5-9, 9-15,
    over 15 cm), or off mainly in x."""
    return PLACES[int(p)]


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
                pre += _bit_literals(rules, term, f["riders.kind"][i])
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


def _value(literals: Sequence[str], predicate: str, term: str) -> str | None:
    """The second argument of the first `(predicate term X)` among literals (`at`, `level`: a block's one value)."""
    head = f"({predicate} {term} "
    return next((x[len(head):-1] for x in literals if x.startswith(head)), None)


def _stands_effects(pre: Sequence[str], eff: Sequence[str]) -> list[str]:
    """The `stands` effects of a move: each block it moves from one (location, level) to another stops standing at
    the first and stands at the second. `(stands ?b ?l ?h)` repeats `at` and `level` together, so that Fast
    Downward's relaxed reachability sees which location and level a block can reach together: a goal no rule can
    build (a stick on a tower in the far row, where no rule puts one) is refused by the translator at once, where
    at and level alone are each reachable and the search would have to exhaust the task's states to prove it."""
    out: list[str] = []
    for term in dict.fromkeys(x.split()[1] for x in pre if x.startswith("(at ")):
        loc, level = _value(pre, "at", term), _value(pre, "level", term)
        new_loc, new_level = _value(eff, "at", term) or loc, _value(eff, "level", term) or level
        if level is not None and (loc, level) != (new_loc, new_level):
            out += [f"(not (stands {term} {loc} {level}))", f"(stands {term} {new_loc} {new_level})"]
    return out


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
    return dataclasses.replace(s, pre=pre, eff=eff, text=_schema_text(s.name, s.params, pre, eff, head))


def _stands_preconditions(pre: list[str]) -> list[str]:
    """Preconditions with each block's `(at T L)` and `(level T H)` read as the one `(stands T L H)` they state
    together (every action keeps stands equal to at and level): the same ground actions, with one atom fewer to
    join for each block a move reads, which pays for the occupancy's (`_occupancy`) work in the translator."""
    out: list[str] = []
    for lit in pre:
        words = lit.strip("()").split()
        if words[0] in ("at", "level") and len(words) == 3 and _value(pre, "at", words[1]) and \
                _value(pre, "level", words[1]):
            if words[0] == "at":
                out.append(f"(stands {words[1]} {words[2]} {_value(pre, 'level', words[1])})")
            continue
        out.append(lit)
    return list(dict.fromkeys(out))


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


TEXT_WIDTH = 110  # literals are packed into lines of at most this many characters


def _wrapped(literals, indent: str) -> str:
    """Literals joined by spaces, a new line (at indent) before one that would pass TEXT_WIDTH."""
    lines, line = [], ""
    for lit in literals:
        if line and len(indent) + len(line) + 1 + len(lit) > TEXT_WIDTH - (20 if not lines else 0):
            lines.append(line)
            line = lit
        else:
            line = f"{line} {lit}" if line else lit
    return f"\n{indent}".join(lines + [line])


def _schema_text(name: str, params, pre, eff, comment: str) -> str:
    ps = " ".join(f"{p} - {t}" for p, t in params)
    pad = " " * 6
    return (f"  {comment}\n  (:action {name}\n    :parameters ({ps})\n"
            f"    :precondition (and {_wrapped(pre, pad)})\n    :effect (and {_wrapped(eff, pad)}))\n")


PICK_CUBE = "pick-cube"


def _pick_cube() -> Schema:
    """The pick half of every cube's plain move (schemas)."""
    params = (("?o", "cube"), ("?from", "location"), ("?h", "layer"), ("?t", "layer"))
    pre = ("(hand-empty)", "(liftable ?h ?t)", "(at ?o ?from)", "(level ?o ?h)", "(rests ?o ?t)", "(height ?from ?h)")
    eff = ("(not (hand-empty))", "(holding ?o)", "(not (at ?o ?from))", "(not (stands ?o ?from ?h))",
           "(not (height ?from ?h))", "(height ?from ?t)")
    comment = ("; a cube is lifted off the top of its location, which drops to what it rested on; its level and what\n"
               "  ; it rested on stay with it until a release-cube action puts it down (liftable: the pairs some does)")
    return Schema(PICK_CUBE, None, None, _schema_text(PICK_CUBE, params, pre, eff, comment), params, pre, eff,
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
        return dataclasses.replace(s, pre=pre, text=_schema_text(s.name, s.params, pre, s.eff, comment))
    params = tuple((p, t) for p, t in s.params if p != "?from")
    pre = ("(holding ?o)",) + tuple(p for p in s.pre if "?from" not in p)
    eff = ("(not (holding ?o))", "(hand-empty)") + tuple(e for e in s.eff if "?from" not in e)
    name = s.name.replace("pick-release-cube", "release-cube", 1)
    return dataclasses.replace(s, name=name, params=params, pre=pre, eff=eff, step="release",
                               text=_schema_text(name, params, pre, eff, comment))


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
    return Schema(name, pick, release, _schema_text(name, params, pre, eff, comment), params, tuple(pre), tuple(eff),
                  0, cost, statics=tuple(facts), predicate=f"({predicate} {signature})")


def pool_schema(rules: LiftedRules, number: int, members: Sequence[Rule], cost: int | None = None) -> Schema:
    """The one schema of a pool (lifted_rules._pool_rules): a cube's or near-row stick's move lifted over the
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
    return Schema(name, None, None, _schema_text(name, params, pre, eff, comment), params, tuple(pre), tuple(eff),
                  0, cost, statics=tuple(facts),
                  predicate=f"({predicate} ?h - layer ?t - layer ?top - layer ?new - layer)")


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
        out.append(Schema(name, None, None, _schema_text(name, params, head + pre, eff, comment), params,
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


def plan_decoder(rules: LiftedRules, costs: bool = False):
    """Plan steps -> one (robot action id, pick * 6 + release; the outcome of its rule the step stands for, 0 for the
    rule's own) per robot action: a whole move ('(pick-release-stick-l1-l4-30 o2)') is one, a pick-cube and the
    release-cube that puts the cube down ('(pick-cube o1 l0 h2 h0)', '(release-cube-3-alt1 o1 l4)') are one
    together. A cube put back where it was picked is no robot action (the rules say it changes nothing there) and
    is left out. Raises ValueError on a step of no action of the domain, a release of a cube not held, a move
    while a cube is held, or a plan that ends holding one."""
    by_name = {s.name: s for s in schemas(rules, costs)}

    def location(word: str) -> int:
        if len(word) != 2 or word[0] != "l" or not word[1].isdigit() or int(word[1]) >= N_LOCATIONS:
            raise ValueError(f"{word!r} is not a location")
        return int(word[1])

    def decode(steps: Sequence[str]) -> list[tuple[int, int]]:
        out: list[tuple[int, int]] = []
        held: tuple[str, int] | None = None  # the cube in the hand and where it was picked
        for step in steps:
            words = step.strip().strip("()").lower().split()
            if not words or words[0] not in by_name:
                raise ValueError(f"plan step {step!r} names no action of the lifted domain")
            s = by_name[words[0]]
            if len(words) != len(s.params) + 1:
                raise ValueError(f"plan step {step!r} gives {len(words) - 1} arguments, {s.name} takes {len(s.params)}")
            if s.step == "release" and held is None:
                raise ValueError(f"plan step {step!r} releases a cube that is not held")
            if s.step != "release" and held is not None:
                raise ValueError(f"plan step {step!r} comes while {held[0]} is held")
            if s.step == "pick":
                held = (words[1], location(words[2]))
                continue
            if s.step == "release":
                if words[1] != held[0]:
                    raise ValueError(f"plan step {step!r} releases {words[1]}, but {held[0]} is held")
                frm, to = held[1], s.release if s.release is not None else location(words[2])
                held = None
                if frm != to:
                    out.append((frm * N_LOCATIONS + to, s.alternative))
                continue
            if s.pick is not None:
                out.append((s.pick * N_LOCATIONS + s.release, s.alternative))
                continue
            frm = location(words[2])
            to = s.release if s.release is not None else location(words[3])  # a schema refined on ?to fixes it
            out.append((frm * N_LOCATIONS + to, s.alternative))
        if held is not None:
            raise ValueError(f"the plan ends with {held[0]} held")
        return out
    return decode


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


def object_name(i: int) -> str:
    return checked_name(f"o{int(i)}", "object name")


def _surface_of(pieces, t: int | None, loc: int) -> str:
    """What piece t (None: nothing) is as the top at location loc."""
    return surface(0 if t is None else pieces[t].level, t is not None and pieces[t].loc == loc)


def _rests_fact(pieces, i: int) -> str:
    """`(rests oI T)`: the top under piece i at its own location (the level, and whether a block stands there or a
    far-row stick's end lies over it), which is what lifting it leaves there.

    A goal states it too, of each block on its spot, where every object's goal is known, as a blocks-world goal
    says what each block is on: the goal's levels already fix it, and Fast Downward's relaxed exploration then also
    sees which top a block can be put on. A goal that only a move rarer than min_count builds (a fourth cube on a
    tower, whose top the height field's last layer reads as level 7, as it reads a third cube on a stick) is then
    refused by the translator, where the search would exhaust every state the rules reach. (A block off its spot
    may have come down beside the top a rule says it lands on, so what it rests on is not stated.)"""
    p = pieces[i]
    below = top_of(pieces, p.loc, frozenset(j for j, q in enumerate(pieces) if q.level >= p.level))
    return (f"(rests {object_name(i)} "
            f"{top_name(level_name(0 if below is None else pieces[below].level), _surface_of(pieces, below, p.loc))})")


def problem_pddl(rules: LiftedRules, start_codes: Sequence[int], goal: SymbolicGoal, name: str,
                 costs: bool = False, statics: Sequence[str] | None = None) -> str:
    """A problem of the lifted domain (of its cost form, with costs): the start scene read from its codes, the goal's
    located fields and an empty hand. `statics`: static_facts of the domain's schemas where the caller has them
    (else worked out from the rules)."""
    if len(goal.codes) != len(start_codes):
        raise ValueError(f"the goal has {len(goal.codes)} objects, the start {len(start_codes)}")
    pieces = rules.pieces(start_codes)
    graph = read_scene(pieces)
    objs = " ".join(f"{object_name(i)} - {'stick' if p.stick else 'cube'}" for i, p in enumerate(pieces))
    init = [f"(near {loc_name(x)})" for x in NEAR_ROW]
    init += [f"(same-level {t} {t.removesuffix('-end')})" for t in layer_names() if t != level_name(0)]
    init += [f"(differ {loc_name(a)} {loc_name(b)})" for a in range(N_LOCATIONS) for b in range(N_LOCATIONS) if a != b]
    init += [f"(is {loc_name(a)} {loc_name(a)})" for a in range(N_LOCATIONS)]
    init += ["(hand-empty)"] + list(static_facts(moves(rules, costs)) if statics is None else statics)
    for i, p in enumerate(pieces):
        o = object_name(i)
        if p.loc < N_LOCATIONS:
            init += [f"(at {o} {loc_name(p.loc)})", f"(stands {o} {loc_name(p.loc)} {level_name(p.level)})"]
        init.append(f"(level {o} {level_name(p.level)})")
        init += _bit_literals(rules, o, p.kind)
        init.append(f"(place {o} {place_name(p.place)})")
        if p.loc < N_LOCATIONS:
            init.append(_rests_fact(pieces, i))
    stood = {(p.loc, p.level) for p in pieces if p.loc < N_LOCATIONS}
    init += [f"(vacant {loc_name(loc)} {level_name(h)})" for loc in range(N_LOCATIONS) for h in range(LEVELS)
             if (loc, h) not in stood]
    for loc, t in enumerate(graph.tops):
        init.append(f"(height {loc_name(loc)} {top_name(level_name(0 if t is None else pieces[t].level), _surface_of(pieces, t, loc))})")
        for i, p in enumerate(pieces):  # a far-row stick's end over loc: the level under it
            if p.stick and p.on_location and p.loc != loc and loc in p.covers():
                below = top_of(pieces, loc, frozenset(j for j, q in enumerate(pieces) if q.level >= p.level))
                init.append(f"(beneath {loc_name(loc)} {level_name(0 if below is None else pieces[below].level)})")
    goals = ["(hand-empty)"]
    whole = None not in goal.codes  # every object's goal known: what each rests on is known too
    goal_pieces = [rules.layout.piece(code, pieces[i].stick) for i, code in enumerate(goal.codes)] if whole else []
    for i, code in enumerate(goal.codes):
        if code is None:
            continue
        g = rules.layout.piece(code, pieces[i].stick)
        o = object_name(i)
        if g.loc < N_LOCATIONS:
            goals += [f"(at {o} {loc_name(g.loc)})", f"(stands {o} {loc_name(g.loc)} {level_name(g.level)})"]
        goals.append(f"(level {o} {level_name(g.level)})")
        goals.append(f"(place {o} {place_name(g.place)})")
        if whole and g.on_location:  # one off its spot may have come down beside what a rule says it lands on
            goals.append(_rests_fact(goal_pieces, i))
    if costs:
        init.append("(= (total-cost) 0)")
    init_s = "\n    ".join(init)
    goal_s = "\n    ".join(goals)
    metric = "\n  (:metric minimize (total-cost))" if costs else ""
    return (f"(define (problem {checked_name(name, 'problem name')})\n  (:domain {domain_name(rules)})\n"
            f"  (:objects {objs})\n"
            f"  (:init\n    {init_s})\n  (:goal (and\n    {goal_s})){metric})\n")


def plan_actions(rules: LiftedRules, steps: Sequence[str]) -> list[int]:
    """Plan steps ('(pick-cube o1 l0 h2 h0)', '(release-cube-3 o1 l4)', ...) -> robot action ids (pick * 6 +
    release), as plan_decoder reads them."""
    return [a for a, _ in plan_decoder(rules)(steps)]
