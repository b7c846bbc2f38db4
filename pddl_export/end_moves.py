"""Picks at a far-row stick's end: the gripper closes on the end of a stick lying over the pick location from a
neighbour, and the stick is dragged along towards the release location.

Such a step is no move of `lifted_rules.participants` (the picked piece does not stand at the pick location), and
without these rules the domain has no action for it: 4-5% of the steps of the data sets' held-out splits, on which
m(z) is right about half the time. Where the stick ends depends on the geometry of the three locations (it keeps
its offset from the gripper, and is pushed off its spot where that would leave the table), so a rule names them:
the stick's location `s`, the pick and the release (`EndRule.cls`), and says where the stick ends (`destination`),
off or on its spot (`place`), with which kept bits (`kind`): lying on the top it finds there, one layer above it
(SIZE_LAYERS). Each class with `min_count` moves becomes a rule, its most frequent outcome, where the PDDL can state
it: not for a stick that ends on its spot in the far row (its ends would cover the destination's neighbours, at
heights the rule does not read), nor for one that ends higher than one layer above what it lands on. Other
objects keep their place: a stick with anything standing on it is not described here.

A rule applies to the cases (`EndCase`: the stick's level and the tops it leaves and finds) its class showed at
least `case_min` times. Lifted over every level, each schema would ground to thousands of actions per stick
(Fast Downward's translator took 14 s on a 5-object task); listed, it grounds to one per case and stick.
"""
from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass
from typing import Sequence

from pddl_export.lifted_scene import FAR_ROW, N_LOCATIONS, SIZE_LAYERS, Piece, SceneGraph, neighbours, top_of

END_CLASS = "end"
LEVELS = 8  # a level above the scale (a located code's 3 bits) is no outcome a rule gives


@dataclass(frozen=True)
class EndMove:
    """A pick at the end of stick `o` lying at `at` (a far-row location), released at `release`."""

    pick: int
    release: int
    o: int
    at: int

    @property
    def cls(self) -> tuple[int, int, int]:
        return (self.at, self.pick, self.release)


def end_participants(graph: SceneGraph, pick: int, release: int) -> EndMove | None:
    """The end move an action makes in a scene, or None: the top at the pick location must be the end of an on-spot
    far-row stick which tops its own location and both of its ends, with nothing standing on it."""
    if pick == release:
        return None
    o = graph.tops[pick]
    if o is None:
        return None
    p = graph.pieces[o]
    if not (p.stick and p.on_location and p.loc in FAR_ROW and pick in neighbours(p.loc)):
        return None
    if any(graph.tops[q] != o for q in (p.loc, *neighbours(p.loc))) or o in graph.support:
        return None
    return EndMove(pick, release, o, p.loc)


def lifted_level(graph: SceneGraph, m: EndMove, loc: int) -> int:
    """The level of the top at loc once the stick is lifted (0: the table)."""
    t = top_of(graph.pieces, loc, frozenset((m.o,)))
    return 0 if t is None else graph.pieces[t].level


def end_change(graph: SceneGraph, after: Sequence[Piece], m: EndMove) -> tuple[int, int, int, int]:
    """Where the stick ended: (location, place, layers above the top it found there, kind)."""
    p = after[m.o]
    up = p.level - lifted_level(graph, m, p.loc) if p.loc < N_LOCATIONS else p.level
    return (int(p.loc), int(p.place), int(up), int(p.kind))


EndCase = tuple  # (stick level, (level, stands) left at s, beneath levels of its ends, (level, stands) at the
# destination or None where the destination is s or an end)


def end_case(graph: SceneGraph, m: EndMove, destination: int) -> EndCase:
    """What an end rule reads of a scene: the stick's level and the tops it leaves and lands on once lifted."""
    def top(loc: int) -> tuple[int, bool]:
        t = top_of(graph.pieces, loc, frozenset((m.o,)))
        return (0, False) if t is None else (graph.pieces[t].level, graph.pieces[t].loc == loc)
    ends = neighbours(m.at)
    return (graph.pieces[m.o].level, top(m.at), tuple(top(q)[0] for q in ends),
            None if destination == m.at or destination in ends else top(destination))


@dataclass(frozen=True)
class EndRule:
    """One end rule: its class (s, pick, release), where the stick ends and how, its support and share."""

    cls: tuple[int, int, int]
    destination: int
    place: int
    kind: int
    support: int  # the class's observed moves
    share: float  # how often the class's moves ended so
    cases: tuple = ()  # the EndCases it applies to, sorted

    def __post_init__(self) -> None:
        s, pick, release = self.cls
        if s not in FAR_ROW or pick not in neighbours(s) or not 0 <= release < N_LOCATIONS or release == pick:
            raise ValueError(f"an end rule's class {list(self.cls)} is no pick at a far-row stick's end")
        if not 0 <= self.destination < N_LOCATIONS or (self.place == 0 and self.destination in FAR_ROW):
            raise ValueError(f"an end rule's destination l{self.destination} (place {self.place}) is not one the "
                             f"PDDL states")
        if not 0 < self.share <= 1:
            raise ValueError(f"an end rule's share {self.share!r} must lie in (0, 1]")
        n_ends = len(neighbours(s))
        for c in self.cases:
            direct = self.destination == s or self.destination in neighbours(s)
            if len(c) != 4 or len(c[2]) != n_ends or (c[3] is None) != direct or not 0 < c[0] < LEVELS:
                raise ValueError(f"an end rule's case {c} does not fit its class {list(self.cls)}")

    def after(self, graph: SceneGraph, m: EndMove) -> Piece | None:
        """The stick after the move, or None where the rule does not apply (a case it does not list)."""
        if end_case(graph, m, self.destination) not in self.cases:
            return None
        return Piece(kind=self.kind, stick=True, loc=self.destination, place=self.place, level=self.new_level(
            end_case(graph, m, self.destination)))

    def new_level(self, case: EndCase) -> int:
        """The stick's level after the move in a case: one layer above the top it finds at the destination."""
        h, (u, _), beneath, top = case
        s = self.cls[0]
        found = u if self.destination == s else beneath[neighbours(s).index(self.destination)] \
            if self.destination in neighbours(s) else top[0]
        return found + SIZE_LAYERS[True]


def distil_end_rules(moves: Sequence[tuple[SceneGraph, EndMove, tuple]], min_count: int,
                     case_min: int = 1) -> tuple[EndRule, ...]:
    """End rules from observed (scene, end move, end_change) triples: one per class seen min_count times whose most
    frequent change the PDDL can state, for the cases of the class seen case_min times (the module docstring)."""
    by_class: dict = defaultdict(list)
    for g, m, change in moves:
        by_class[m.cls].append((g, m, change))
    rules = []
    for cls, items in sorted(by_class.items()):
        tally = Counter(change for _, _, change in items)
        total = len(items)
        (loc, place, up, kind), n = tally.most_common(1)[0]
        if total < min_count or up != SIZE_LAYERS[True] or loc >= N_LOCATIONS or (place == 0 and loc in FAR_ROW):
            continue
        seen = Counter(end_case(g, m, loc) for g, m, _ in items)
        rule = EndRule(cls, loc, place, kind, total, round(n / total, 4))
        cases = tuple(sorted((c for c, k in seen.items() if k >= case_min and rule.new_level(c) < LEVELS), key=repr))
        if cases:
            rules.append(EndRule(cls, loc, place, kind, total, round(n / total, 4), cases))
    return tuple(rules)


def end_rule_json(r: EndRule) -> dict:
    return {"class": list(r.cls), "destination": r.destination, "place": r.place, "kind": r.kind,
            "support": r.support, "share": r.share,
            "cases": [[h, list(u), list(b), None if t is None else list(t)] for h, u, b, t in r.cases]}


def end_rule_of_json(d: dict) -> EndRule:
    """An EndRule back from end_rule_json's form (ValueError, KeyError or TypeError where it is not one)."""
    cls = tuple(int(x) for x in d["class"])
    if len(cls) != 3:
        raise ValueError(f"an end rule's class {d['class']} must name three locations")
    cases = tuple((int(h), (int(u[0]), bool(u[1])), tuple(int(x) for x in b), None if t is None else (int(t[0]), bool(t[1])))
                  for h, u, b, t in d["cases"])
    return EndRule(cls, int(d["destination"]), int(d["place"]), int(d["kind"]), int(d["support"]), float(d["share"]),
                   cases)
