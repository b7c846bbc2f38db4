"""A problem of the lifted domain: the start scene read from its located codes, the goal's located fields, an
empty hand, and the static facts the domain's schemas need (pddl_export.lifted_domain.static_facts).

    >>> problem_pddl(rules, start_codes, goal, "p01")                    # doctest: +SKIP
"""
from __future__ import annotations

from typing import Sequence

from pddl_export.lifted_domain import static_facts
from pddl_export.lifted_moves import moves
from pddl_export.lifted_rules import LiftedRules
from pddl_export.lifted_scene import NEAR_ROW, N_LOCATIONS, read_scene, top_of
from pddl_export.lifted_vocabulary import LEVELS, bit_literals, domain_name, layer_names, level_name, loc_name, \
    object_name, place_name, surface, top_name
from pddl_export.pddl_writer import checked_name
from pddl_export.symbolic import SymbolicGoal


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
        init += bit_literals(rules, o, p.kind)
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
