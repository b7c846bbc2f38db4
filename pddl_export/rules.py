"""Symbolic rules: their data types (Rule, RuleSet) and their meaning (apply_rules).

A rule reads: under `action`, an object whose code is `code_from` takes `code_to` when the
OTHER objects' codes satisfy a context of count conditions: "some other object has code X"
(requires), "no other object has code X" (forbids), "at least n others have X" (at_least)
and "fewer than n others have X" (fewer_than). All objects are updated simultaneously from
the pre-state; an object no rule matches keeps its code. The rules of one (action, own code)
must be mutually exclusive (RuleSet checks it), so one step is a function of the pre-state.

Rules are made by pddl_export.distil.distil_rules, stored by pddl_export.rules_io and
checked against the network by pddl_export.fidelity.

    >>> import numpy as np
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=3, n_rules_before_generalization=6,
    ...              rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)),))
    >>> apply_rules(rs, np.array([1, 1, 2]), 5).tolist(), apply_rules(rs, np.array([1, 3]), 5).tolist()
    ([2, 2, 2], [1, 3])
"""
from __future__ import annotations

import contextlib
import functools
from collections import Counter
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
from threadpoolctl import threadpool_limits

from pddl_export.symbolic import N_ACTIONS

INF = 1 << 62  # open upper end of a count interval
Bounds = dict[int, tuple[int, int]]  # code -> [lo, hi) on the number of OTHER objects with it
COUNT_CAP = (1 << 15) - 2  # apply_rules_batch compares counts as int16 up to this



class AmbiguousRulesError(ValueError):
    """Rules with different outcomes matched the same object."""


def _sorted_pairs(pairs: Sequence[tuple[int, int]]) -> tuple[tuple[int, int], ...]:
    return tuple(sorted((int(x), int(n)) for x, n in pairs))


@dataclass(frozen=True)
class Rule:
    """Under `action`, an object with `code_from` becomes `code_to` if the others match."""

    action: int
    code_from: int
    code_to: int
    requires: tuple[int, ...] = ()  # some other object has each of these codes
    forbids: tuple[int, ...] = ()  # no other object has any of these codes
    at_least: tuple[tuple[int, int], ...] = ()  # (code, n >= 2): at least n others have it
    fewer_than: tuple[tuple[int, int], ...] = ()  # (code, n >= 2): fewer than n others have it

    def __post_init__(self) -> None:
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        requires, forbids = tuple(sorted(map(int, self.requires))), tuple(sorted(map(int, self.forbids)))
        at_least, fewer_than = _sorted_pairs(self.at_least), _sorted_pairs(self.fewer_than)
        set_("requires", requires)
        set_("forbids", forbids)
        set_("at_least", at_least)
        set_("fewer_than", fewer_than)
        if not 0 <= self.action < N_ACTIONS:
            raise ValueError(f"action must lie in 0..{N_ACTIONS - 1}, got {self.action}")
        lower = requires + tuple(x for x, _ in at_least)
        upper = forbids + tuple(x for x, _ in fewer_than)
        if min((self.code_from, self.code_to) + lower + upper) < 0:
            raise ValueError("codes must be non-negative")
        if self.code_from == self.code_to:
            raise ValueError("a rule must change the code (code_from == code_to)")
        if any(n < 2 for _, n in at_least + fewer_than):
            raise ValueError("at_least / fewer_than counts must be >= 2 (use requires / forbids for 1)")
        if len(set(lower)) != len(lower) or len(set(upper)) != len(upper):
            raise ValueError("each code may carry at most one lower and one upper bound")
        bounds = dict.fromkeys(forbids, (0, 1))  # most conditions forbid a code: filled without a Python loop
        bounds.update((x, (0, n)) for x, n in fewer_than)
        for x, lo in [(x, 1) for x in requires] + list(at_least):
            hi = bounds.get(x, (0, INF))[1]
            if lo >= hi:
                raise ValueError(f"contradictory conditions on code {x}: need {lo} <= count < {hi}")
            bounds[x] = (lo, hi)
        bounds = dict(sorted(bounds.items()))
        set_("_bounds", bounds)  # computed once: rules of 1-5-object scenes name about 20 context codes each

    def bounds(self) -> Bounds:
        """code -> [lo, hi) on how many OTHER objects carry it (hi = INF when open), sorted by code."""
        return dict(self._bounds)

    @classmethod
    def from_bounds(cls, action: int, code_from: int, code_to: int, bounds: Mapping[int, tuple[int, int]]) -> Rule:
        """Inverse of bounds(); trivial intervals [0, INF) are dropped."""
        req, forb, least, fewer = [], [], [], []
        for x, (lo, hi) in bounds.items():
            if lo == 1:
                req.append(x)
            elif lo > 1:
                least.append((x, lo))
            if hi == 1:
                forb.append(x)
            elif hi < INF:
                fewer.append((x, hi))
        return cls(int(action), int(code_from), int(code_to), tuple(req), tuple(forb), tuple(least), tuple(fewer))

    def matches(self, other_counts: Mapping[int, int]) -> bool:
        """Whether the context holds, given code -> number of OTHER objects with that code."""
        return all(lo <= other_counts.get(x, 0) < hi for x, (lo, hi) in self._bounds.items())

    @property
    def n_conditions(self) -> int:
        """Number of count conditions on the other objects (0: the rule always fires on code_from)."""
        return len(self.requires) + len(self.forbids) + len(self.at_least) + len(self.fewer_than)


DenseGroup = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # (C,) codes, (R, C) lo, (R, C) hi, (R,) code_to


def _dense_group(group: Sequence[Rule]) -> DenseGroup:
    """The rules of one (action, own code) as arrays: context codes, int16 bounds lo <= count < hi, outcomes.

    INF is stored as COUNT_CAP + 1 and counts are compared clipped to COUNT_CAP, which is exact because
    finite bounds above COUNT_CAP are refused (a bound counts objects of one scene).
    """
    rows, codes, los, his = [], [], [], []
    for i, r in enumerate(group):
        if r._bounds:
            rows += [i] * len(r._bounds)
            codes += r._bounds.keys()
            lo_i, hi_i = zip(*r._bounds.values())
            los += lo_i
            his += hi_i
    los_a, his_a = np.array(los, np.int64), np.array(his, np.int64)
    bad = (los_a > COUNT_CAP) | ((his_a > COUNT_CAP) & (his_a < INF))
    if bad.any():
        raise ValueError(f"{group[rows[int(np.argmax(bad))]]}: a count bound above {COUNT_CAP} objects")
    cols, where = np.unique(np.array(codes, np.int64), return_inverse=True)
    lo = np.zeros((len(group), len(cols)), np.int16)
    hi = np.full((len(group), len(cols)), COUNT_CAP + 1, np.int16)
    lo[rows, where] = los_a
    hi[rows, where] = np.minimum(his_a, COUNT_CAP + 1)
    return cols, lo, hi, np.array([r.code_to for r in group], np.int64)


def _first_overlap(lo: np.ndarray, hi: np.ndarray, max_cells: int = 1 << 22) -> tuple[int, int] | None:
    """First pair (i, j) of boxes lo <= count < hi, (R, C) each, that some multiset satisfies both of; None if
    pairwise disjoint. Rows are compared in blocks whose (block, R) table holds at most max_cells.

    Boxes a and b are disjoint where on some column lo_a >= hi_b (or lo_b >= hi_a), that is where some finite
    upper bound t of the column has lo_a >= t and hi_b <= t. With one 0/1 feature per (column, t) for each side,
    the test is a matrix product: BLAS answers a group of 1,000 rules over 350 context codes in milliseconds,
    where comparing every pair on every column took a second (docs/BENCHMARKS.md, "Loading exported rules").
    """
    n = len(lo)
    rows, cols = np.nonzero(hi <= COUNT_CAP)  # where the upper bounds are finite
    keys = np.unique(cols.astype(np.int64) * (COUNT_CAP + 2) + hi[rows, cols])  # distinct (column, t)
    col, thr = keys // (COUNT_CAP + 2), keys % (COUNT_CAP + 2)
    at_least = (lo[:, col] >= thr).astype(np.float32)  # (R, F): lo >= t
    at_most = (hi[:, col] <= thr).astype(np.float32)  # (R, F): hi <= t
    step = max(1, max_cells // max(1, n))
    for s in range(0, n, step):
        e = min(n, s + step)
        disjoint = (at_least[s:e] @ at_most.T + at_most[s:e] @ at_least.T) > 0.5
        disjoint[np.arange(e - s), np.arange(s, e)] = True
        i, k = np.nonzero(~disjoint)
        if len(i):
            return s + int(i[0]), int(k[0])
    return None


@dataclass(frozen=True, eq=False)
class RuleSet:
    """The rules distilled from one enumeration, with the counts to report."""

    bits: int
    vocabulary: tuple[int, ...]  # the enumerated codes, sorted
    max_objects: int  # largest enumerated scene: rules are exact up to it
    rules: tuple[Rule, ...]
    n_rules_before_generalization: int  # changing (action, own code, exact others) cases
    _index: dict = field(init=False, repr=False, compare=False)
    _dense: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "vocabulary", tuple(int(c) for c in self.vocabulary))
        object.__setattr__(self, "rules", tuple(self.rules))
        if self.bits < 1 or self.max_objects < 1 or self.n_rules_before_generalization < 0:
            raise ValueError("bits and max_objects must be >= 1, n_rules_before_generalization >= 0")
        if any(not 0 <= c < (1 << self.bits) for c in self.codes):
            raise ValueError(f"every code must fit in {self.bits} bits")
        index: dict[tuple[int, int], list[Rule]] = {}
        for r in self.rules:
            index.setdefault((r.action, r.code_from), []).append(r)
        dense = {}
        # one BLAS thread: a many-threaded BLAS on small products is ten times slower beside any other busy process
        with threadpool_limits(1, user_api="blas") if len(self.rules) > 1000 else contextlib.nullcontext():
            for (a, c), group in index.items():
                dense[(a, c)] = _dense_group(group)
                clash = _first_overlap(*dense[(a, c)][1:3]) if len(group) > 1 else None
                if clash is not None:
                    i, j = clash
                    raise ValueError(f"rules for action {a}, code {c} are not mutually exclusive: "
                                     f"{group[i]} and {group[j]}")
        object.__setattr__(self, "_index", {k: tuple(v) for k, v in index.items()})
        object.__setattr__(self, "_dense", dense)

    @property
    def n_rules(self) -> int:
        """Number of rules (what the report counts)."""
        return len(self.rules)

    @functools.cached_property
    def codes(self) -> tuple[int, ...]:
        """Every code the vocabulary or a rule mentions, sorted (the PDDL predicates); computed once."""
        out = set(self.vocabulary)
        for r in self.rules:
            out |= {r.code_from, r.code_to, *r._bounds}
        return tuple(sorted(out))

    @property
    def actions(self) -> tuple[int, ...]:
        """Actions that change something, sorted."""
        return tuple(sorted({r.action for r in self.rules}))

    def with_codes(self, codes) -> "RuleSet":
        """This rule set with `codes` added to its vocabulary (itself if none is new).

        A code no rule mentions is inert under the rules' semantics (an object no rule matches keeps
        its code, and contexts count only the codes they name), so a scene holding codes the
        enumeration never saw, e.g. a 5-object scene's, is still a well-defined task for the rules.
        """
        new = {int(c) for c in codes} - set(self.codes)
        if not new:
            return self
        return RuleSet(self.bits, tuple(sorted(set(self.vocabulary) | new)), self.max_objects, self.rules,
                       self.n_rules_before_generalization)

    def rules_for(self, action: int, code_from: int) -> tuple[Rule, ...]:
        """The rules of one (action, own code), mutually exclusive; () if none."""
        return self._index.get((int(action), int(code_from)), ())

    @property
    def dense_groups(self) -> dict[tuple[int, int], DenseGroup]:
        """(action, own code) -> (C,) context codes, (R, C) lo, (R, C) hi, (R,) code_to: its rules as arrays
        (int16 bounds, see _dense_group), built once for the overlap check, apply_rules_batch and RuleSuccessors."""
        return self._dense



# ----------------------------------------------------------------------------- application


def _as_ruleset_index(rules: RuleSet | Sequence[Rule]):
    if isinstance(rules, RuleSet):
        return rules.rules_for
    index: dict[tuple[int, int], list[Rule]] = {}
    for r in rules:
        index.setdefault((r.action, r.code_from), []).append(r)
    return lambda a, c: index.get((a, c), ())


def apply_rules(rules: RuleSet | Sequence[Rule], codes: np.ndarray | Sequence[int], action: int) -> np.ndarray:
    """Reference semantics: every object's next code from the pre-state, simultaneously."""
    lookup = _as_ruleset_index(rules)
    pre = [int(c) for c in np.asarray(codes).ravel()]
    total = Counter(pre)
    out = list(pre)
    for i, c in enumerate(pre):
        others = total.copy()
        others[c] -= 1
        hits = {r.code_to for r in lookup(int(action), c) if r.matches(others)}
        if len(hits) > 1:
            raise AmbiguousRulesError(f"action {action}: object {i} with code {c} matches outcomes {sorted(hits)}")
        if hits:
            out[i] = hits.pop()
    return np.array(out, np.int64)


def apply_rules_batch(rules: RuleSet, codes: np.ndarray, actions: np.ndarray, max_cells: int = 1 << 22) -> np.ndarray:
    """Vectorized apply_rules: (B, K) codes and (B,) actions -> (B, K) next codes.

    The (row, object) pairs are grouped by (action, own code); each group's pairs are compared with all
    of that group's rules at once (RuleSet.dense_groups), in chunks of at most `max_cells` booleans.
    """
    codes = np.asarray(codes, np.int64)
    actions = np.asarray(actions, np.int64)
    if codes.ndim != 2 or actions.shape != (len(codes),):
        raise ValueError(f"need (B, K) codes and (B,) actions, got {codes.shape} and {actions.shape}")
    out = codes.copy()
    k = codes.shape[1]
    if not codes.size:
        return out
    groups = rules.dense_groups
    n_codes = 1 << rules.bits
    valid = (codes >= 0) & (codes < n_codes) & ((actions >= 0) & (actions < N_ACTIONS))[:, None]
    key = np.where(valid, actions[:, None] * n_codes + codes, -1).ravel()  # (B*K,) one key per (row, object)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    starts = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
    ends = np.r_[starts[1:], len(key)]
    for s, e in zip(starts.tolist(), ends.tolist()):
        kv = int(sorted_key[s])
        a, c = divmod(kv, n_codes)
        group = groups.get((a, c)) if kv >= 0 else None
        if group is None:
            continue
        cols, lo, hi, code_to = group
        step = max(1, max_cells // max(1, lo.size))
        for cs in range(s, e, step):
            pos = order[cs:min(e, cs + step)]
            rows, objs = pos // k, pos % k
            others = (codes[rows][:, :, None] == cols).sum(1) - (cols == c)  # (n, C) OTHER objects with each code
            others = np.minimum(others, COUNT_CAP).astype(np.int16)  # clipped: see _dense_group
            fires = np.all((others[:, None, :] >= lo) & (others[:, None, :] < hi), axis=2)  # (n, R)
            p, r = np.nonzero(fires)
            hits = np.bincount(p, minlength=len(pos))
            if len(p) and hits.max() > 1:
                raise AmbiguousRulesError(f"action {a}: rules with different outcomes match row "
                                          f"{int(rows[hits.argmax()])}")
            out[rows[p], objs[p]] = code_to[r]
    return out
