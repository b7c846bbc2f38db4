"""The lifted rules' file, RUN/pddl/lifted.json: LiftedRules.to_json's form read back with every field checked
(lifted_schema, the bounded reader) before any value is used, each refusal one line naming the file and the field.

    >>> rules = load_lifted(Path("pretrained/recommended/pddl/lifted.json"))    # doctest: +SKIP
"""
from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

from pddl_export.bounded_json import AnyJson, Bool, Const, Int, JsonFileError, List, Map, Num, Obj, OneOf, Opt, \
    Schema, Str, Tuple, check, read_json_file
from pddl_export.end_moves import end_rule_of_json
from pddl_export.lifted_rules import LIFTED_KIND, LIFTED_VERSION, MAX_ALTERNATIVES, POOLED_CLASSES, REFINEMENTS, \
    STRUCTURE, WHERE, LiftedRules, Rule, outcome_of_json, pool_key, pool_statement, relative_change
from pddl_export.lifted_scene import N_LOCATIONS, CodeLayout
from pddl_export.location_codec import FIELD_BITS, field_widths

MAX_LIFTED_BYTES = 64 << 20  # a lifted rules file is kilobytes; refuse anything near this
FIELD_VALUES = 1 << max(field_widths(FIELD_BITS))  # the values a location, place or level field holds
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
                           outcome_of_json(r["outcome"]), int(r["support"]), float(r.get("share", 1.0)),
                           tuple((outcome_of_json(o), float(p)) for o, p in r.get("alternatives", [])),
                           None if r.get("pool") is None else int(r["pool"]))
                      for r in d["rules"])
        for i, r in enumerate(rules):
            _check_rule(r, f"field rules[{i}]")
        pools: dict = defaultdict(set)
        for r in rules:
            if r.pool is not None:
                pools[r.pool].add(pool_statement(pool_key(r.fields()), relative_change(r.fields(), r.outcome)))
        if any(len(v) > 1 for v in pools.values()):
            raise ValueError("the rules of one pool must share its key and relative outcome")
        ends = tuple(end_rule_of_json(e) for e in d.get("end_rules", []))
    except (KeyError, TypeError, ValueError, OverflowError, IndexError) as e:
        raise ValueError(f"{path}: malformed lifted rules ({str(e).splitlines()[0][:200]})") from None
    return LiftedRules(layout, stick_of, rules, str(d.get("model_hash", "")), dict(d.get("stats", {})), codebook, ends)
