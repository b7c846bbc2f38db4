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
riders): `distil_lifted` grows a decision tree per structure, splitting on the refinement that explains the most
further moves. Rules under a split on the release location that share an outcome are one rule naming all their
locations. The leaves partition the moves: wherever a rule matches, no other does.

The class of a move is "cube" for a cube (lifted over both locations), "near" for a stick moved within the near
row (nothing covers a neighbour there), and the concrete (p, r) pair otherwise: a far-row stick's ends cover its
row neighbours, and which ones overlap before and after depends on the pair.

`LiftedRules.step_pieces` and `step_codes` apply them to a state (the Python form of the PDDL that
`lifted_writer` writes): a move no rule covers leaves the state as it is, as the PDDL offers no action for it.

A structure seen fewer than min_count times has no rule of its own. Those of a cube or a near-row stick
(`POOLED_CLASSES`: lifted over both locations) are pooled (`pool_key`: the class, o's place, what it lands on);
where the pooled moves mostly agree on what o does relative to the top it lands on (`relative_change`: a cube
ends two levels above it), every structure of the pool seen at least `pool_structure_min` times gets that
outcome, as a rule marked with the pool's number (`Rule.pool`). The writer states a pool as one schema lifted
over the levels, with a static relation listing its structures.

Picks at a far-row stick's end are no move of `participants`; their rules (`pddl_export.end_moves`) are kept
beside the others (`LiftedRules.end_rules`), and `step_pieces` applies them too.

A rule also keeps how often its outcome was m(z)'s answer among the moves of its descriptions (`share`) and the
other writable outcomes seen at least ALTERNATIVE_MIN_SHARE of the time (`alternatives`): the all-outcomes
determinisation that the cost form of the domain writes, one action per outcome costing by its -log share.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from functools import cached_property
from typing import Iterable, Sequence

import numpy as np

from pddl_export.bounded_json import AnyJson, Bool, Const, Int, JsonFileError, List, Map, Num, Obj, OneOf, Opt, \
    Schema, Str, Tuple, check, read_json_file
from pddl_export.end_moves import EndRule, end_change, end_participants, end_rule_json, end_rule_of_json
from pddl_export.lifted_scene import FAR_ROW, N_LOCATIONS, NEAR_ROW, CodeLayout, Piece, SceneGraph, neighbours, read_scene, \
    top_of

LIFTED_KIND = "symlearn-lifted-rules"
LIFTED_VERSION = 1
MAX_LIFTED_BYTES = 64 << 20  # a lifted rules file is kilobytes; refuse anything near this
STRUCTURE = ("cls", "o.stick", "o.place", "o.level", "u.level", "v.level", "riders.sides", "riders.place",
             "riders.level", "beneath", "landing", "u.at", "v.at")
REFINEMENTS = (("to",), ("o.kind",), ("v.kind",), ("u.kind",), ("riders.kind",))
MIN_GAIN = 0.05  # a split must explain this share of its node's moves more (distil_lifted, LiftedConfig)
ALTERNATIVE_MIN_SHARE = 0.1  # an outcome this often m(z)'s answer among a rule's moves becomes an alternative
MAX_ALTERNATIVES = 2  # per rule, the most frequent ones (the cost form writes 1 + this many actions per rule)
POOLED_CLASSES = ("cube", "near")  # the lifted move classes whose rarer structures can be pooled (distil_lifted)
POOL_MIN_COUNT = 20  # moves a pool needs before its majority outcome is given to its structures
POOL_STRUCTURE_MIN = 5  # moves a structure needs to join its pool (each one is a static fact of every problem)
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
    alternatives: tuple = ()  # ((outcome, share), ...): other writable answers, at least ALTERNATIVE_MIN_SHARE each
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
        learned, level = self.layout.learned(code), int(code) & 7
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
        return (int(learned) << 9) | (piece.loc << 6) | (piece.place << 3) | piece.level

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
                           "outcome": _outcome_json(r.outcome), "support": r.support, "share": r.share,
                           "alternatives": [[_outcome_json(o), p] for o, p in r.alternatives],
                           **({} if r.pool is None else {"pool": r.pool})} for r in self.rules],
                "codebook": [[bool(k[0]), *map(int, k[1:]), int(v)] for k, v in sorted(self.codebook.items())],
                "end_rules": [end_rule_json(r) for r in self.end_rules], "stats": self.stats}


def _outcome_json(outcome: Outcome) -> list:
    return [list(c) if isinstance(c, tuple) else c for c in outcome]


def _outcome_of_json(d: list) -> Outcome:
    return tuple(tuple(c) if isinstance(c, list) else c for c in d)


def stick_reader(codes: np.ndarray, mask: np.ndarray, is_stick: np.ndarray, layout: CodeLayout) -> dict:
    """(learned code, level) -> majority type over the observed objects; (learned code, -1) over all levels."""
    codes = np.asarray(codes)[np.asarray(mask, bool)]
    sticks = np.asarray(is_stick)[np.asarray(mask, bool)].astype(bool)
    votes: dict = defaultdict(Counter)
    for c, s in zip(codes.tolist(), sticks.tolist()):
        learned, level = layout.learned(c), c & 7
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
    written = {k: _written(k, c.most_common(1)[0][0]) for k, c in pools.items()}
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


def _written(key: tuple, change: tuple) -> tuple:
    """What a pool's schema states: its class, o's place and the change (pool_key's other fields are in its facts)."""
    return (key[0], key[1], change)


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


def release_locations(cls) -> tuple[int, ...]:
    """Where a move of a lifted class can release: any location for a cube, the near row for a near-row stick."""
    return tuple(range(N_LOCATIONS)) if cls == "cube" else NEAR_ROW


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


FIELD_VALUES = 8  # a location, place or level field of a located code holds 3 bits
MAX_LIFTED_ITEMS = 1 << 20  # rules, type readings, codebook entries, end rules or cases in one file
MAX_RIDERS = 2  # a far-row stick has at most two ends


@dataclass(frozen=True)
class _Key(Schema):
    """A rule's key: [field, value] pairs (STRUCTURE's fields, then refinements), each value of its field's kind."""

    values: dict = field(default_factory=dict, hash=False)  # field name -> its value's Schema

    def describe(self) -> str:
        return f"a list of {len(STRUCTURE)}..{len(STRUCTURE) + len(REFINEMENTS)} [field, value] pairs"

    def check(self, v, at, where):
        if not (isinstance(v, list) and len(STRUCTURE) <= len(v) <= len(STRUCTURE) + len(REFINEMENTS)):
            self.refuse(v, at, where)
        for i, pair in enumerate(v):
            if not (isinstance(pair, list) and len(pair) == 2 and isinstance(pair[0], str) and pair[0] in self.values):
                self.refuse(pair, f"{at}[{i}]", where, f"expected [field, value] with a field of "
                            f"{', '.join(self.values)}, got {str(pair)[:60]!r}")
            self.values[pair[0]].check(pair[1], f"{at}[{i}][1] ({pair[0]})", where)


@dataclass(frozen=True)
class _Outcome(Schema):
    """An outcome: o's change, u's and v's new kind (or null), then each rider's change."""

    o: Schema
    kind: Schema
    rider: Schema

    def describe(self) -> str:
        return "a list of o's change, two kinds (or null) and the riders' changes"

    def check(self, v, at, where):
        if not (isinstance(v, list) and 3 <= len(v) <= 3 + MAX_RIDERS):
            self.refuse(v, at, where)
        for i, x in enumerate(v):
            (self.o if i == 0 else self.kind if i < 3 else self.rider).check(x, f"{at}[{i}]", where)


def lifted_schema(code_bits: int, n_kept: int) -> Obj:
    """What lifted.json must hold (to_json's form), every value in its range: locations 0-5 where a rule acts (7,
    unseen, where a piece may be), places and levels 0-7, kinds below 2**n_kept, learned codes below
    2**code_bits, shares in [0, 1], a model hash of hex digits."""
    loc, at, level = Int(0, N_LOCATIONS - 1), Int(0, FIELD_VALUES - 1), Int(0, FIELD_VALUES - 1)
    place, kind, learned = Int(0, FIELD_VALUES - 1), Int(0, (1 << n_kept) - 1), Int(0, (1 << code_bits) - 1)
    levels = List(level, MAX_RIDERS)
    key = _Key({"cls": OneOf((Str(choices=("cube", "near")), Tuple((loc, loc)))), "to": OneOf((loc, List(loc, 6, 1))),
                "o.stick": Bool(), "o.kind": kind, "o.place": place, "o.level": level, "u.level": level,
                "v.level": level, "riders.sides": List(OneOf((Const(-1), Const(1))), MAX_RIDERS),
                "riders.place": List(place, MAX_RIDERS), "riders.level": levels, "riders.kind": List(kind, MAX_RIDERS),
                "beneath": levels, "landing": levels, "u.at": Bool(), "v.at": Bool(), "u.kind": Opt(kind),
                "v.kind": Opt(kind)})
    outcome = _Outcome(Tuple((Const("to"), place, level, kind)), Opt(kind),
                       Tuple((OneOf((Str(choices=WHERE), at)), place, level, kind)))
    share = Num(0, 1)
    rule = Obj({"depth": Int(0, len(REFINEMENTS)), "key": key, "outcome": outcome, "support": Int(1)},
               {"share": share, "alternatives": List(Tuple((outcome, share)), MAX_ALTERNATIVES), "pool": Int(0)})
    top = Tuple((level, Bool()))
    end_rule = Obj({"class": Tuple((loc, loc, loc)), "destination": loc, "place": place, "kind": kind,
                    "support": Int(1), "share": share,
                    "cases": List(Tuple((level, top, levels, Opt(top))), MAX_LIFTED_ITEMS)})
    stick = Tuple((learned, Int(-1, FIELD_VALUES - 1), Bool()))  # (learned code, level or -1: any) -> a stick
    return Obj({"kind": Const(LIFTED_KIND), "version": Const(LIFTED_VERSION), "code_bits": Int(1, 16),
                "kept": List(Int(0, code_bits - 1), code_bits), "stick_of": List(stick, MAX_LIFTED_ITEMS),
                "rules": List(rule, MAX_LIFTED_ITEMS)},
               {"model_hash": Str(64, r"[0-9a-f]*"), "stats": Map(AnyJson(), 1000),
                "codebook": List(Tuple((Bool(), kind, at, place, level, learned)), MAX_LIFTED_ITEMS),
                "end_rules": List(end_rule, MAX_LIFTED_ITEMS)})


def _check_lifted_json(d, path: Path) -> None:
    """Refuse (one line naming the file and the field) a lifted.json that is not to_json's form with every value in
    range (lifted_schema), before any value is used."""
    version = d.get("version") if isinstance(d, dict) else None
    if not isinstance(d, dict) or d.get("kind") != LIFTED_KIND or type(version) is not int or version != LIFTED_VERSION:
        raise ValueError(f"{path} is not a lifted rules file ({LIFTED_KIND} version {LIFTED_VERSION})")
    try:
        check(d, Obj({"code_bits": Int(1, 16), "kept": List(AnyJson(), 16)}), str(path))
        check(d, lifted_schema(d["code_bits"], len(d["kept"])), str(path))
    except JsonFileError as e:
        raise JsonFileError(f"{path}: malformed lifted rules ({str(e).removeprefix(f'{path}: ')})") from None


def _check_rule(r: Rule, at: str) -> None:
    """Refuse (ValueError naming the rule's field `at`) a rule whose parts do not fit together: shares in (0, 1],
    STRUCTURE's fields then distinct refinements as many as its depth, as many riders in its key and outcomes as it
    has sides, a concrete class of two locations, a pooled rule of a pooled class."""
    if not all(0 < share <= 1 for _, share in r.outcomes()):
        raise ValueError(f"{at}: a rule's outcome shares {[share for _, share in r.outcomes()]} must lie in (0, 1]")
    names = tuple(k for k, _ in r.key)
    if names[:len(STRUCTURE)] != STRUCTURE:
        raise ValueError(f"{at}: a rule's key names {names[:len(STRUCTURE)]}, expected {STRUCTURE}")
    extra = names[len(STRUCTURE):]
    if len(set(extra)) != len(extra) or not set(extra) <= {n for (n,) in REFINEMENTS} or r.depth != len(extra):
        raise ValueError(f"{at}: a rule's refinements {extra} must be distinct fields of {REFINEMENTS}, "
                         f"as many as its depth {r.depth}")
    f = r.fields()
    riders = len(f["riders.sides"])
    lengths = [len(f[n]) for n in ("riders.place", "riders.level", "riders.kind") if n in f]
    lengths += [len(outcome) - 3 for outcome, _ in r.outcomes()]
    if any(n != riders for n in lengths):
        raise ValueError(f"{at}: a rule with {riders} riders states {lengths} riders in its key and outcomes")
    if isinstance(f["cls"], tuple) and f["cls"][0] == f["cls"][1]:
        raise ValueError(f"{at}: a rule's class {list(f['cls'])} picks and releases at one location")
    if r.pool is not None and (r.depth or r.alternatives or f["cls"] not in POOLED_CLASSES):
        raise ValueError(f"{at}: pooled rule of pool {r.pool} must be a {' or '.join(POOLED_CLASSES)} move's "
                         f"structure, with no refinement and no alternative")


def load_lifted(path) -> LiftedRules:
    """LiftedRules back from to_json's form (RUN/pddl/lifted.json), every field checked first (_check_lifted_json)."""
    path = Path(path)
    d = read_json_file(path, what="lifted rules file", max_bytes=MAX_LIFTED_BYTES)  # bounded; one line naming it
    _check_lifted_json(d, path)
    try:
        layout = CodeLayout(int(d["code_bits"]), tuple(int(b) for b in d["kept"]))
        stick_of = {(int(a), int(b)): bool(s) for a, b, s in d["stick_of"]}
        codebook = {(bool(e[0]), int(e[1]), int(e[2]), int(e[3]), int(e[4])): int(e[5]) for e in d.get("codebook", [])}
        rules = tuple(Rule(int(r["depth"]), tuple((k, tuple(v) if isinstance(v, list) else v) for k, v in r["key"]),
                           _outcome_of_json(r["outcome"]), int(r["support"]), float(r.get("share", 1.0)),
                           tuple((_outcome_of_json(o), float(p)) for o, p in r.get("alternatives", [])),
                           None if r.get("pool") is None else int(r["pool"]))
                      for r in d["rules"])
        for i, r in enumerate(rules):
            _check_rule(r, f"field rules[{i}]")
        pools: dict = defaultdict(set)
        for r in rules:
            if r.pool is not None:
                pools[r.pool].add(_written(pool_key(r.fields()), relative_change(r.fields(), r.outcome)))
        if any(len(v) > 1 for v in pools.values()):
            raise ValueError("the rules of one pool must share its key and relative outcome")
        ends = tuple(end_rule_of_json(e) for e in d.get("end_rules", []))
    except (KeyError, TypeError, ValueError, OverflowError, IndexError) as e:
        raise ValueError(f"{path}: malformed lifted rules ({str(e).splitlines()[0][:200]})") from None
    return LiftedRules(layout, stick_of, rules, str(d.get("model_hash", "")), dict(d.get("stats", {})), codebook, ends)


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
