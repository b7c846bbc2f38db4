"""Lifted rules: what one pick-and-release does to the pieces it touches, distilled from transitions.

Physics here is local. An action (pick p, release r) takes the top piece at p (`o`), with whatever stands on a
far-row stick's ends (its riders), and puts it on the top at r; every other piece keeps its location and level.
So a rule need not say which codes all other objects hold (the per-action rules of `pddl_export.rules` do): it
describes the move (`participants`, `signature`) and says what the moved pieces become, and which learned bits
change on what the move leaves on top at p and on what it lands on at r.

A rule's `key` keeps the structure of the move (`STRUCTURE`: the move's class, o's type, place and level, the
levels left at p and found at r, the riders' sides, places and levels, the levels under and beside a far-row
stick's ends, whether a piece stands on top at p and at r) and only the refinements its outcome depends on
(`REFINEMENTS`: where it releases, the learned bits of o, of what it lands on, of what it leaves on top, of the
riders): `lifted_distil.distil_lifted` grows a decision tree per structure, splitting on the refinement that
explains the most further moves. Rules under a split on the release location that share an outcome are one rule
naming all their locations. The leaves partition the moves: wherever a rule matches, no other does.

The class of a move is "cube" for a cube (lifted over both locations), "near" for a stick moved within the near
row (nothing covers a neighbour there), and the concrete (p, r) pair otherwise: a far-row stick's ends cover its
row neighbours, and which ones overlap before and after depends on the pair.

`LiftedRules.step_pieces` and `step_codes` apply them to a state (the Python form of the PDDL that
`lifted_domain` writes): a move no rule covers leaves the state as it is, as the PDDL offers no action for it.

A structure seen fewer than min_count times has no rule of its own. Those of a cube or a near-row stick
(`POOLED_CLASSES`: lifted over both locations) are pooled (`pool_key`: the class, o's place, what it lands on);
where the pooled moves mostly agree on what o does relative to the top it lands on (`relative_change`: a cube
ends two levels above it), every structure of the pool seen at least `pool_structure_min` times gets that
outcome, as a rule marked with the pool's number (`Rule.pool`). The writer states a pool as one schema lifted
over the levels, with a static relation listing its structures.

Picks at a far-row stick's end are no move of `participants`; their rules (`pddl_export.end_moves`) are kept
beside the others (`LiftedRules.end_rules`), and `step_pieces` applies them too.

A rule also keeps how often its outcome was m(z)'s answer among the moves of its descriptions (`share`) and the
other writable outcomes seen at least lifted_distil.ALTERNATIVE_MIN_SHARE of the time (`alternatives`): the
all-outcomes determinisation that the cost form of the domain writes, one action per outcome costing by its -log
share. `LiftedRules.to_json` is the form of RUN/pddl/lifted.json; pddl_export.lifted_rules_io.load_lifted reads it
back.
"""
from __future__ import annotations

import dataclasses
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from functools import cached_property
from typing import Iterable, Sequence

import numpy as np

from pddl_export.end_moves import EndRule, end_change, end_participants, end_rule_json
from pddl_export.lifted_scene import N_LOCATIONS, NEAR_ROW, CodeLayout, Piece, SceneGraph, neighbours, read_scene, \
    top_of
from pddl_export.location_codec import decode_location, encode_location

LIFTED_KIND = "symlearn-lifted-rules"
LIFTED_VERSION = 1
STRUCTURE = ("cls", "o.stick", "o.place", "o.level", "u.level", "v.level", "riders.sides", "riders.place",
             "riders.level", "beneath", "landing", "u.at", "v.at")
REFINEMENTS = (("to",), ("o.kind",), ("v.kind",), ("u.kind",), ("riders.kind",))
MAX_ALTERNATIVES = 2  # per rule, the most frequent ones (the cost form writes 1 + this many actions per rule)
POOLED_CLASSES = ("cube", "near")  # the lifted move classes whose rarer structures can be pooled (distil_lifted)
WHERE = ("to", "from", "stay", "shift")  # where a piece ends, relative to the action; an int is a location


@dataclass(frozen=True)
class Move:
    """The pieces an action touches in one state (indices into its pieces)."""

    pick: int
    release: int
    o: int
    under: int  # the level left at the pick location once o (and its riders) are lifted
    v: int | None
    riders: tuple[int, ...]  # pieces on the ends of a far-row stick o, by side
    beneath: tuple[int, ...] = ()  # a far-row stick o: the level under each of its ends (its pick's neighbours)
    landing: tuple[int, ...] = ()  # a stick released in the far row: the level at each neighbour it will cover
    below: int | None = None  # the piece left on top at the pick location, where it stands at it
    v_at: int | None = None  # v, where it stands at the release location (not a stick's end over it)


def move_class(o: Piece, pick: int, release: int):
    """'cube', 'near' (a stick within the near row) or the (pick, release) pair of any other stick move."""
    if not o.stick:
        return "cube"
    if pick in NEAR_ROW and release in NEAR_ROW:
        return "near"
    return (pick, release)


def participants(graph: SceneGraph, pick: int, release: int) -> Move | str:
    """The move an action makes in a scene, or why no lifted rule can describe it (a short reason)."""
    if pick == release:
        return "same location"
    pieces = graph.pieces
    o = graph.tops[pick]
    if o is None:
        return "nothing to pick"
    if pieces[o].loc != pick:
        return "a stick's end"
    riders = tuple(sorted((j for j, s in enumerate(graph.support) if s == o and pieces[j].loc != pick),
                          key=lambda j: pieces[j].loc))
    if any(s in riders for s in graph.support):
        return "a tower on a stick end"
    if any(graph.tops[pieces[j].loc] != j for j in riders):
        return "a rider under another piece"
    skip = frozenset((o, *riders))
    v = top_of(pieces, release, skip)

    def level_at(loc: int) -> int:
        t = top_of(pieces, loc, skip)
        return 0 if t is None else pieces[t].level
    stick = pieces[o].stick
    beneath = tuple(level_at(n) for n in neighbours(pick)) if stick and pieces[o].place == 0 else ()
    landing = tuple(level_at(n) for n in neighbours(release)) if stick else ()
    below = top_of(pieces, pick, skip)
    below = below if below is not None and pieces[below].loc == pick else None
    v_at = v if v is not None and pieces[v].loc == release else None
    return Move(pick, release, o, level_at(pick), v, riders, beneath, landing, below, v_at)


def signature(graph: SceneGraph, m: Move) -> dict:
    """Every described field of a move (STRUCTURE and REFINEMENTS name them): what a lifted action can test."""
    ps = graph.pieces
    o = ps[m.o]
    return {"cls": move_class(o, m.pick, m.release), "to": m.release, "o.stick": o.stick, "o.kind": o.kind, "o.level": o.level,
            "o.place": o.place, "riders.place": tuple(ps[j].place for j in m.riders),
            "u.level": m.under, "v.level": 0 if m.v is None else ps[m.v].level,
            "riders.sides": tuple(ps[j].loc - m.pick for j in m.riders),
            "riders.kind": tuple(ps[j].kind for j in m.riders),
            "riders.level": tuple(ps[j].level for j in m.riders), "beneath": m.beneath, "landing": m.landing,
            "u.at": m.below is not None, "v.at": m.v_at is not None,
            "u.kind": None if m.below is None else ps[m.below].kind,
            "v.kind": None if m.v_at is None else ps[m.v_at].kind}


def _scalar_keys(key: tuple) -> list[tuple]:
    """A key with a tuple of release locations ("to") as one key per location; any other key as it is."""
    for i, (name, value) in enumerate(key):
        if name == "to" and isinstance(value, tuple):
            return [key[:i] + (("to", v),) + key[i + 1:] for v in value]
    return [key]


def key_of(sig: dict, depth: int) -> tuple:
    """The key of a signature at a refinement depth: STRUCTURE, then the first `depth` REFINEMENTS."""
    names = STRUCTURE + tuple(f for group in REFINEMENTS[:depth] for f in group)
    return tuple((n, sig[n]) for n in names)


Outcome = tuple  # (o's change, u's new kind, v's new kind, each rider's change); a change: (where, place, level,
# kind); a new kind None where the piece is absent or keeps its kind


def outcome_of(graph: SceneGraph, after: Sequence[Piece], m: Move) -> Outcome:
    """What each piece of a move became, relative to the action where it can be."""
    def rel(i: int | None):
        if i is None:
            return None
        before, now = graph.pieces[i], after[i]
        if now.loc == before.loc:
            where = "stay"
        elif now.loc == m.release:
            where = "to"
        elif now.loc == m.pick:
            where = "from"
        elif now.loc == before.loc + m.release - m.pick:
            where = "shift"
        else:
            where = int(now.loc)
        return (where, now.place, now.level, now.kind)
    def new_kind(i: int | None):
        return None if i is None or after[i].kind == graph.pieces[i].kind else after[i].kind
    return (rel(m.o), new_kind(m.below), new_kind(m.v_at), *(rel(i) for i in m.riders))


def _place(before: Piece, change, m: Move) -> Piece:
    where, place, level, kind = change
    loc = {"to": m.release, "from": m.pick, "stay": before.loc,
           "shift": before.loc + m.release - m.pick}.get(where, where)
    return Piece(kind=kind, stick=before.stick, loc=int(loc), place=place, level=level)


def writable(outcome: Outcome) -> bool:
    """Whether an outcome is a move a lifted action can state: the picked piece goes to the release location
    (on it or off it)."""
    return outcome[0][0] == "to"


@dataclass(frozen=True)
class Rule:
    """One lifted rule: its refinement depth, its key (field, value) pairs, and the outcome of its move."""

    depth: int
    key: tuple
    outcome: Outcome
    support: int  # observed moves it was distilled from (all of its key's)
    share: float = 1.0  # how often `outcome` was m(z)'s answer among those moves
    alternatives: tuple = ()  # ((outcome, share), ...): other writable answers (lifted_distil)
    pool: int | None = None  # a pooled rule: the number of its pool (its structure was rarer than min_count)

    def outcomes(self) -> tuple:
        """((outcome, share), ...): the rule's own outcome first, then its alternatives."""
        return ((self.outcome, self.share), *self.alternatives)

    def fields(self) -> dict:
        return dict(self.key)


@dataclass(frozen=True)
class LiftedRules:
    """The distilled rules of a code layout, a type reader, and where they came from."""

    layout: CodeLayout
    stick_of: dict = field(hash=False)  # (learned code, level) -> is it a stick (majority in the data)
    rules: tuple[Rule, ...] = ()
    model_hash: str = ""
    stats: dict = field(default_factory=dict, hash=False)
    # (stick, kind, loc, place, level) -> the learned code observed most often with them: what a moved piece's
    # whole code is predicted to be (its position-tracking bits follow its new location)
    codebook: dict = field(default_factory=dict, hash=False)
    end_rules: tuple[EndRule, ...] = ()  # picks at a far-row stick's end (pddl_export.end_moves)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_ends", {r.cls: r for r in self.end_rules})
        index, splits = {}, {}
        for r in self.rules:
            for key in _scalar_keys(r.key):  # a rule naming several release locations answers for each
                index[key] = r
                for n in range(len(STRUCTURE), len(key)):  # every shorter key of a rule was split on its next field
                    splits[key[:n]] = key[n][0]
        object.__setattr__(self, "_index", index)
        object.__setattr__(self, "_splits", splits)

    @cached_property
    def tested_kinds(self) -> frozenset[int]:
        """Every kind (packed kept bits) some rule's condition tests: of o, of what it leaves on top or lands on, or
        of a rider (the writer states a bit's negative form only where one of these has it at 0)."""
        out = set()
        for r in self.rules:
            f = r.fields()
            out.update(k for k in (f.get("o.kind"), f.get("u.kind"), f.get("v.kind"), *(f.get("riders.kind") or ()))
                       if k is not None)
        return frozenset(out)

    def is_stick(self, code: int) -> bool:
        """The type a located code reads as: the data's majority for its learned code and level (else level 1)."""
        learned, (_, _, level) = decode_location(int(code))
        got = self.stick_of.get((learned, level))
        if got is None:
            got = self.stick_of.get((learned, -1), level % 2 == 1)
        return bool(got)

    def pieces(self, codes: Iterable[int]) -> tuple[Piece, ...]:
        return tuple(self.layout.piece(c, self.is_stick(c)) for c in codes)

    def rule_for(self, sig: dict) -> Rule | None:
        """The rule whose key the signature has (the leaf of its structure's tree), or None."""
        key = key_of(sig, 0)
        while key not in self._index:
            name = self._splits.get(key)
            if name is None:
                return None
            key = key + ((name, sig[name]),)
        return self._index[key]

    def end_rule_for(self, graph: SceneGraph, pick: int, release: int) -> EndRule | None:
        """The end rule of a pick at a far-row stick's end, or None (no such pick, or no rule for it)."""
        m = end_participants(graph, pick, release)
        rule = None if m is None else self._ends.get(m.cls)
        return rule if rule is not None and rule.after(graph, m) is not None else None

    def step_pieces(self, pieces: Sequence[Piece], action: int, alternative: int = 0
                    ) -> tuple[tuple[Piece, ...], Rule | EndRule | None]:
        """The pieces after an action (pick * 6 + release), and the rule that fired (None: nothing changes); with
        `alternative` j > 0, the rule's j-th alternative outcome instead of its own."""
        pick, release = divmod(int(action), 6)
        graph = read_scene(pieces)
        m = participants(graph, pick, release)
        if m == "a stick's end" and (end := self.end_rule_for(graph, pick, release)) is not None:
            if alternative:
                raise ValueError(f"the end rule of action {action} has no alternatives, not {alternative}")
            out = list(pieces)
            m = end_participants(graph, pick, release)
            out[m.o] = end.after(graph, m)
            return tuple(out), end
        if isinstance(m, str):
            return tuple(pieces), None
        rule = self.rule_for(signature(graph, m))
        if rule is None:
            return tuple(pieces), None
        out = list(pieces)
        outcomes = rule.outcomes()
        if not 0 <= alternative < len(outcomes):
            raise ValueError(f"the rule of action {action} has {len(outcomes) - 1} alternatives, not {alternative}")
        o_change, u_kind, v_kind, *r_changes = outcomes[alternative][0]
        for i, change in zip((m.o, *m.riders), (o_change, *r_changes)):
            out[i] = _place(pieces[i], change, m)
        for i, kind in ((m.below, u_kind), (m.v_at, v_kind)):
            if i is not None and kind is not None:
                out[i] = dataclasses.replace(out[i], kind=int(kind))
        return tuple(out), rule

    def code_of(self, piece: Piece, old_code: int) -> int:
        """A piece's whole located code: its fields, after the learned code the data shows most often with them
        (else the old learned code with the kept bits set to the piece's kind)."""
        learned = self.codebook.get((piece.stick, piece.kind, piece.loc, piece.place, piece.level))
        if learned is None:
            learned = self.layout.with_kind(self.layout.learned(old_code), piece.kind)
        return encode_location(int(learned), (piece.loc, piece.place, piece.level))

    def step_codes(self, codes: Sequence[int], action: int, alternative: int = 0
                   ) -> tuple[tuple[int, ...], Rule | None]:
        """The located codes after an action (with a rule's alternative outcome if asked): unmoved objects keep
        theirs, moved ones get code_of their pieces."""
        pieces = self.pieces(codes)
        after, rule = self.step_pieces(pieces, action, alternative)
        return tuple(int(c) if a == p else self.code_of(a, c) for c, p, a in zip(codes, pieces, after)), rule

    def to_json(self) -> dict:
        return {"kind": LIFTED_KIND, "version": LIFTED_VERSION, "model_hash": self.model_hash,
                "code_bits": self.layout.code_bits, "kept": list(self.layout.kept),
                "stick_of": [[int(a), int(b), bool(s)] for (a, b), s in sorted(self.stick_of.items())],
                "rules": [{"depth": r.depth, "key": [[k, v] for k, v in r.key],
                           "outcome": outcome_json(r.outcome), "support": r.support, "share": r.share,
                           "alternatives": [[outcome_json(o), p] for o, p in r.alternatives],
                           **({} if r.pool is None else {"pool": r.pool})} for r in self.rules],
                "codebook": [[bool(k[0]), *map(int, k[1:]), int(v)] for k, v in sorted(self.codebook.items())],
                "end_rules": [end_rule_json(r) for r in self.end_rules], "stats": self.stats}


def outcome_json(outcome: Outcome) -> list:
    return [list(c) if isinstance(c, tuple) else c for c in outcome]


def outcome_of_json(d: list) -> Outcome:
    return tuple(tuple(c) if isinstance(c, list) else c for c in d)


def stick_reader(codes: np.ndarray, mask: np.ndarray, is_stick: np.ndarray, layout: CodeLayout) -> dict:
    """(learned code, level) -> majority type over the observed objects; (learned code, -1) over all levels."""
    codes = np.asarray(codes)[np.asarray(mask, bool)]
    sticks = np.asarray(is_stick)[np.asarray(mask, bool)].astype(bool)
    votes: dict = defaultdict(Counter)
    for c, s in zip(codes.tolist(), sticks.tolist()):
        learned, (_, _, level) = decode_location(c)
        votes[(learned, level)][s] += 1
        votes[(learned, -1)][s] += 1
    return {k: c.most_common(1)[0][0] for k, c in votes.items()}


def observed_moves(rules_like: LiftedRules, before: np.ndarray, after: np.ndarray, actions: np.ndarray,
                   mask: np.ndarray) -> tuple[list[tuple[dict, Outcome]], Counter]:
    """Every modelled move in (N, K) code arrays with its signature and outcome; a tally of the reasons others fail."""
    moves, why = [], Counter()
    for n in range(len(actions)):
        k = int(np.asarray(mask[n]).sum())
        pb = rules_like.pieces(before[n, :k].tolist())
        pa = rules_like.pieces(after[n, :k].tolist())
        graph = read_scene(pb)
        pick, release = divmod(int(actions[n]), 6)
        m = participants(graph, pick, release)
        if isinstance(m, str):
            why[m] += 1
            continue
        moves.append((signature(graph, m), outcome_of(graph, pa, m)))
    return moves, why


def observed_end_moves(rules_like: LiftedRules, before: np.ndarray, after: np.ndarray, actions: np.ndarray,
                       mask: np.ndarray) -> list[tuple]:
    """Every pick at a far-row stick's end in (N, K) code arrays: (scene, end move, where the stick ended)."""
    out = []
    for n in range(len(actions)):
        k = int(np.asarray(mask[n]).sum())
        graph = read_scene(rules_like.pieces(before[n, :k].tolist()))
        m = end_participants(graph, *divmod(int(actions[n]), 6))
        if m is not None:
            out.append((graph, m, end_change(graph, rules_like.pieces(after[n, :k].tolist()), m)))
    return out


def pool_key(sig: dict) -> tuple:
    """What pools a rarer structure with others: its class (POOLED_CLASSES), o's place, and what it lands on (a
    block standing at the release location or not, the table or not)."""
    return (sig["cls"], sig["o.place"], sig["v.at"], sig["v.level"] > 0)


def relative_change(sig: dict, outcome: Outcome) -> tuple:
    """What o does in a move, its new level relative to the top it lands on: (where, place, levels above, kind)."""
    where, place, level, kind = outcome[0]
    return (where, place, level - sig["v.level"] if where == "to" else level, kind)


def pool_statement(key: tuple, change: tuple) -> tuple:
    """What a pool's schema states: its class, o's place and the change (pool_key's other fields are in its facts)."""
    return (key[0], key[1], change)


def release_locations(cls) -> tuple[int, ...]:
    """Where a move of a lifted class can release: any location for a cube, the near row for a near-row stick."""
    return tuple(range(N_LOCATIONS)) if cls == "cube" else NEAR_ROW


def build_codebook(rules_like: LiftedRules, codes: np.ndarray, mask: np.ndarray) -> dict:
    """(stick, kind, loc, place, level) -> the learned code most often observed with them, over (N, K) codes."""
    votes: dict = defaultdict(Counter)
    for c in np.asarray(codes)[np.asarray(mask, bool)].tolist():
        p = rules_like.layout.piece(c, rules_like.is_stick(c))
        votes[(p.stick, p.kind, p.loc, p.place, p.level)][rules_like.layout.learned(c)] += 1
    return {k: v.most_common(1)[0][0] for k, v in votes.items()}


class LiftedTransition:
    """The lifted rules as a transition function over located codes (pddl_export.symbolic.TransitionFn)."""

    def __init__(self, rules: LiftedRules) -> None:
        self.rules, self.bits = rules, rules.layout.bits

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        codes = np.asarray(codes, np.int64)
        out = codes.copy()
        for i, (row, a) in enumerate(zip(codes.tolist(), np.asarray(actions).tolist())):
            out[i] = self.rules.step_codes(row, int(a))[0]
        return out
