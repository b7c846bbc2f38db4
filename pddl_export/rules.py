"""Distil an enumerated transition function into exact, mutually exclusive symbolic rules.

A rule reads: under `action`, an object whose code is `code_from` takes `code_to` when the
OTHER objects' codes satisfy a context of count conditions: "some other object has code X"
(requires), "no other object has code X" (forbids), "at least n others have X" (at_least)
and "fewer than n others have X" (fewer_than). All objects are updated simultaneously from
the pre-state; an object no rule matches keeps its code.

Algorithm (per action a and own code c; the network is permutation-equivariant, so the
outcome is a function of the multiset M of the other objects' codes, |M| <= max_objects - 1):

1. Cases. From the enumeration, one case per distinct (a, c, M) with the network's outcome.
   Equal codes inside one scene must get equal outcomes (else the function is not
   equivariant and distil_rules raises). `n_rules_before_generalization` counts the cases
   whose outcome differs from c: a rule per exact context, no generalization.
2. Features. Presence features "count of X in M >= 1" for every vocabulary code; when the
   outcome is not a function of presence alone, thresholds ">= 2", ">= 3", ... are added
   level by level up to max_objects - 1, where the counts (hence M) are fully determined.
3. Tree. A scikit-learn decision tree (entropy, fixed random_state, grown until pure) fits
   the outcome with zero training error (checked). Its leaves partition the context space:
   each leaf is a box of count intervals lo <= count(X) < hi, and two leaves differ on some
   split, so they are logically disjoint for ANY scene size, not just enumerated ones.
4. Drop the no-change leaves (outcome c); an object that no rule matches keeps its code.
5. Generalize greedily, exactly: widen a box by dropping a condition (or one side of a
   two-sided interval) when every enumerated context in the widened box has the rule's
   outcome and the box stays logically disjoint from every other rule of (a, c), except
   same-outcome rules it contains whole, which are removed (this also merges complementary
   leaves such as "X present" / "X absent"). Passes repeat until nothing changes. Each step
   keeps the rules exact on every enumerated case and mutually exclusive. Coverage is tested
   with bitmasks over the enumerated contexts, disjointness with numpy over all boxes. The
   result is small but not guaranteed minimal (greedy, first condition first).

Beyond the enumerated scene sizes the rules are an extrapolation: exact for <= max_objects
objects, a consistent generalization above.

    >>> from pddl_export.enumeration import enumerate_transitions
    >>> import numpy as np
    >>> class Push:                 # action 5 turns 1 into 2 unless some other object is 3
    ...     bits = 2
    ...     def __call__(self, codes, actions):
    ...         blocked = (codes == 3).sum(1, keepdims=True) - (codes == 3) > 0
    ...         out = codes.copy()
    ...         out[(actions[:, None] == 5) & (codes == 1) & ~blocked] = 2
    ...         return out
    >>> rs = distil_rules(enumerate_transitions(Push(), [1, 2, 3], max_objects=3))
    >>> rs.rules
    (Rule(action=5, code_from=1, code_to=2, requires=(), forbids=(3,), at_least=(), fewer_than=()),)
    >>> rs.n_rules_before_generalization, apply_rules(rs, np.array([1, 1, 2]), 5).tolist()
    (6, [2, 2, 2])
"""
from __future__ import annotations

import functools
from collections import Counter
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
from sklearn.tree import DecisionTreeClassifier

from pddl_export.enumeration import Enumeration
from pddl_export.symbolic import N_ACTIONS

INF = 1 << 62  # open upper end of a count interval
Bounds = dict[int, tuple[int, int]]  # code -> [lo, hi) on the number of OTHER objects with it


class NotEquivariantError(ValueError):
    """Two objects with the same code in one scene were given different next codes."""


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
        set_("requires", tuple(sorted(int(x) for x in self.requires)))
        set_("forbids", tuple(sorted(int(x) for x in self.forbids)))
        set_("at_least", _sorted_pairs(self.at_least))
        set_("fewer_than", _sorted_pairs(self.fewer_than))
        if not 0 <= self.action < N_ACTIONS:
            raise ValueError(f"action must lie in 0..{N_ACTIONS - 1}, got {self.action}")
        codes = [self.code_from, self.code_to, *self.requires, *self.forbids]
        codes += [x for x, _ in self.at_least + self.fewer_than]
        if any(c < 0 for c in codes):
            raise ValueError("codes must be non-negative")
        if self.code_from == self.code_to:
            raise ValueError("a rule must change the code (code_from == code_to)")
        if any(n < 2 for _, n in self.at_least + self.fewer_than):
            raise ValueError("at_least / fewer_than counts must be >= 2 (use requires / forbids for 1)")
        lower = list(self.requires) + [x for x, _ in self.at_least]
        upper = list(self.forbids) + [x for x, _ in self.fewer_than]
        if len(set(lower)) != len(lower) or len(set(upper)) != len(upper):
            raise ValueError("each code may carry at most one lower and one upper bound")
        for x, (lo, hi) in self.bounds().items():
            if lo >= hi:
                raise ValueError(f"contradictory conditions on code {x}: need {lo} <= count < {hi}")

    def bounds(self) -> Bounds:
        """code -> [lo, hi) on how many OTHER objects carry it (hi = INF when open)."""
        out: dict[int, list[int]] = {}
        for x in self.requires:
            out.setdefault(x, [0, INF])[0] = 1
        for x, n in self.at_least:
            out.setdefault(x, [0, INF])[0] = n
        for x in self.forbids:
            out.setdefault(x, [0, INF])[1] = 1
        for x, n in self.fewer_than:
            out.setdefault(x, [0, INF])[1] = n
        return {x: (lo, hi) for x, (lo, hi) in sorted(out.items())}

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
        return all(lo <= other_counts.get(x, 0) < hi for x, (lo, hi) in self.bounds().items())

    @property
    def n_conditions(self) -> int:
        return len(self.requires) + len(self.forbids) + len(self.at_least) + len(self.fewer_than)


def _first_overlap(boxes: Sequence[Mapping[int, tuple[int, int]]]) -> tuple[int, int] | None:
    """First pair (i, j) of boxes that some multiset satisfies both of, or None if pairwise disjoint."""
    if len(boxes) < 2:
        return None
    codes = sorted({x for b in boxes for x in b})
    lo = np.array([[b.get(x, (0, INF))[0] for x in codes] for b in boxes], np.int64).reshape(len(boxes), len(codes))
    hi = np.array([[b.get(x, (0, INF))[1] for x in codes] for b in boxes], np.int64).reshape(len(boxes), len(codes))
    disjoint = np.any(np.maximum(lo[:, None], lo[None]) >= np.minimum(hi[:, None], hi[None]), axis=2)  # (R, R)
    i, j = np.nonzero(~disjoint & ~np.eye(len(boxes), dtype=bool))
    return (int(i[0]), int(j[0])) if len(i) else None


@dataclass(frozen=True, eq=False)
class RuleSet:
    """The rules distilled from one enumeration, with the counts to report."""

    bits: int
    vocabulary: tuple[int, ...]  # the enumerated codes, sorted
    max_objects: int  # largest enumerated scene: rules are exact up to it
    rules: tuple[Rule, ...]
    n_rules_before_generalization: int  # changing (action, own code, exact others) cases
    _index: dict = field(init=False, repr=False, compare=False)

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
        for (a, c), group in index.items():
            clash = _first_overlap([r.bounds() for r in group])
            if clash is not None:
                i, j = clash
                raise ValueError(f"rules for action {a}, code {c} are not mutually exclusive: "
                                 f"{group[i]} and {group[j]}")
        object.__setattr__(self, "_index", {k: tuple(v) for k, v in index.items()})

    @property
    def n_rules(self) -> int:
        return len(self.rules)

    @functools.cached_property
    def codes(self) -> tuple[int, ...]:
        """Every code the vocabulary or a rule mentions, sorted (the PDDL predicates); computed once."""
        out = set(self.vocabulary)
        for r in self.rules:
            out |= {r.code_from, r.code_to, *r.bounds()}
        return tuple(sorted(out))

    @property
    def actions(self) -> tuple[int, ...]:
        """Actions that change something, sorted."""
        return tuple(sorted({r.action for r in self.rules}))

    def rules_for(self, action: int, code_from: int) -> tuple[Rule, ...]:
        return self._index.get((int(action), int(code_from)), ())


# ----------------------------------------------------------------------------- distillation


def _cases(enum: Enumeration) -> np.ndarray:
    """(N, 3 + m) rows [action, own vocab index, others' vocab indices padded with V, outcome code].

    One row per distinct (action, own code, multiset of others): scenes are sorted multisets,
    so the first position of each code in a scene stands for all its copies.
    """
    vocab = np.array(enum.vocabulary, np.int64)
    v, m = len(vocab), enum.max_objects - 1
    parts = []
    for b in enum.blocks:
        k = b.n_objects
        idx = np.repeat(np.searchsorted(vocab, b.scenes), N_ACTIONS, axis=0)  # (S*36, k)
        for j in range(k):
            if j > 0:
                same = idx[:, j] == idx[:, j - 1]
                bad = same & (b.next_codes[:, j] != b.next_codes[:, j - 1])
                if bad.any():
                    r = int(np.flatnonzero(bad)[0])
                    raise NotEquivariantError(
                        f"scene {b.scenes[r // N_ACTIONS].tolist()} action {int(b.actions[r])}: objects "
                        f"with equal codes got different next codes {b.next_codes[r].tolist()}")
                keep = ~same
            else:
                keep = np.ones(len(idx), bool)
            others = np.delete(idx[keep], j, axis=1)  # (n, k-1), sorted
            pad = np.full((len(others), m - (k - 1)), v, np.int64)
            parts.append(np.column_stack([b.actions[keep], idx[keep, j], others, pad, b.next_codes[keep, j]]))
    return np.concatenate(parts)


def _n_distinct_rows(rows: np.ndarray) -> int:
    """Number of distinct rows of a 2-D uint8/bool array (rows compared as bytes)."""
    rows = np.ascontiguousarray(rows)
    return len(np.unique(rows.view(np.dtype((np.void, rows.shape[1] * rows.itemsize))).ravel()))


def _feature_table(counts: np.ndarray, outcomes: np.ndarray, max_level: int) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Smallest threshold level whose features make the outcome a function of them.

    Returns the (n, F) bool feature matrix and its (vocab index, threshold) per column.
    """
    out_bytes = outcomes.astype(">i8").view(np.uint8).reshape(len(outcomes), 8)
    for level in range(1, max_level + 1):
        feats = [(x, t) for t in range(1, level + 1) for x in range(counts.shape[1])]
        table = np.stack([counts[:, x] >= t for x, t in feats], axis=1)  # (n, F)
        varying = table.any(0) & ~table.all(0)
        table, feats = table[:, varying], [f for f, keep in zip(feats, varying) if keep]
        packed = np.packbits(table, axis=1)  # (n, ceil(F/8))
        if _n_distinct_rows(packed) == _n_distinct_rows(np.concatenate([packed, out_bytes], axis=1)):
            return table, feats
    raise AssertionError("counts up to max_objects - 1 must determine the context")


def _tree_leaves(table: np.ndarray, feats: list[tuple[int, int]], outcomes: np.ndarray,
                 n_codes: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fit a pure decision tree; return its leaves as boxes lo <= count < hi: (L, V) lo, (L, V) hi, (L,) outcome."""
    clf = DecisionTreeClassifier(criterion="entropy", random_state=0).fit(table, outcomes)
    if not np.array_equal(clf.predict(table), outcomes):
        raise RuntimeError("decision tree did not reach zero training error")
    t = clf.tree_
    los, his, ys = [], [], []
    stack = [(0, np.zeros(n_codes, np.int64), np.full(n_codes, INF, np.int64))]
    while stack:
        node, lo, hi = stack.pop()
        left, right = t.children_left[node], t.children_right[node]
        if left == -1:
            los.append(lo)
            his.append(hi)
            ys.append(int(clf.classes_[int(np.argmax(t.value[node][0]))]))
            continue
        x, thr = feats[t.feature[node]]  # left: feature false (count < thr); right: count >= thr
        lhi, rlo = hi.copy(), lo.copy()
        lhi[x], rlo[x] = min(hi[x], thr), max(lo[x], thr)
        stack.append((left, lo, lhi))
        stack.append((right, rlo, hi))
    return np.array(los), np.array(his), np.array(ys, np.int64)


def _bitmask(column: np.ndarray) -> int:
    """Bool vector -> Python int with bit i set where column[i] (fast set algebra over contexts)."""
    return int.from_bytes(np.packbits(column, bitorder="little").tobytes(), "little")


def _generalize(lo: np.ndarray, hi: np.ndarray, ys: np.ndarray, counts: np.ndarray,
                outcomes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Greedy exact widening of disjoint boxes (step 5 of the module docstring).

    A widened box is accepted when no enumerated context inside it has another outcome
    (checked with bitmasks over the contexts) and it stays logically disjoint from every other
    box, except same-outcome boxes it contains, which are removed.
    """
    n, m = len(counts), int(counts.max(initial=0))
    full = (1 << n) - 1
    ge_cache: dict[tuple[int, int], int] = {}

    def ge(x: int, t: int) -> int:  # contexts with count_x >= t
        if t <= 0:
            return full
        if t > m:
            return 0
        if (x, t) not in ge_cache:
            ge_cache[(x, t)] = _bitmask(counts[:, x] >= t)
        return ge_cache[(x, t)]

    def interval(x: int, a: int, b: int) -> int:  # contexts with a <= count_x < b
        return ge(x, a) & ~ge(x, b)

    bad = {int(y): _bitmask(outcomes != y) for y in np.unique(ys)}  # contexts with another outcome
    lo, hi = lo.copy(), hi.copy()
    alive = np.ones(len(ys), bool)
    changed = True
    while changed:
        changed = False
        for i in range(len(ys)):
            if not alive[i]:
                continue
            conds = [int(x) for x in np.flatnonzero((lo[i] > 0) | (hi[i] < INF))]
            masks = [interval(x, int(lo[i, x]), int(hi[i, x])) for x in conds]
            # Alive boxes are pairwise disjoint; widening code x can only create an overlap with
            # a box separated from box i by x alone.
            sep = np.maximum(lo[i], lo) >= np.minimum(hi[i], hi)  # (R, V) codes separating i from j
            n_sep = sep.sum(1)
            for k, x in enumerate(conds):
                rest = full
                for j, mk in enumerate(masks):
                    if j != k:
                        rest &= mk
                xlo, xhi = int(lo[i, x]), int(hi[i, x])
                only_x = alive & (n_sep == sep[:, x])
                only_x[i] = False
                for new in [(0, INF)] + ([(0, xhi), (xlo, INF)] if xlo > 0 and xhi < INF else []):
                    if rest & interval(x, *new) & bad[int(ys[i])]:
                        continue
                    overlap = np.flatnonzero(only_x & (np.maximum(new[0], lo[:, x]) < np.minimum(new[1], hi[:, x])))
                    clo, chi = lo[i].copy(), hi[i].copy()
                    clo[x], chi[x] = new
                    swallow = overlap[(ys[overlap] == ys[i]) & np.all(clo <= lo[overlap], axis=1)
                                      & np.all(chi >= hi[overlap], axis=1)]
                    if len(swallow) < len(overlap):
                        continue
                    alive[swallow] = False
                    lo[i], hi[i] = clo, chi
                    masks[k] = interval(x, *new)
                    sep = np.maximum(lo[i], lo) >= np.minimum(hi[i], hi)
                    n_sep = sep.sum(1)
                    changed = True
                    break
    return lo[alive], hi[alive], ys[alive]


MAX_WIDEN_BOXES = 40  # larger groups keep the decision tree's (exact, disjoint) leaves unwidened


def _group_rules(counts: np.ndarray, outcomes: np.ndarray, own: int, max_level: int) -> list[tuple[Bounds, int]]:
    """Exact, mutually exclusive changing rules (box over vocab indices, outcome) for one (a, c)."""
    if np.all(outcomes == own):
        return []
    if np.all(outcomes == outcomes[0]):
        return [({}, int(outcomes[0]))]
    table, feats = _feature_table(counts, outcomes, max_level)
    lo, hi, ys = _tree_leaves(table, feats, outcomes, counts.shape[1])
    change = ys != own
    if change.sum() <= MAX_WIDEN_BOXES:  # the greedy widening is quadratic in the boxes; leaves are exact too
        lo, hi, ys = _generalize(lo[change], hi[change], ys[change], counts, outcomes)
    else:
        lo, hi, ys = lo[change], hi[change], ys[change]
    rules = []
    for blo, bhi, y in zip(lo, hi, ys):
        box = {int(x): (int(blo[x]), int(bhi[x])) for x in np.flatnonzero((blo > 0) | (bhi < INF))}
        rules.append((box, int(y)))
    return rules


def distil_rules(enumeration: Enumeration) -> RuleSet:
    """Exact, generalized rules reproducing the network on every enumerated case (see module doc)."""
    enum = enumeration
    vocab = np.array(enum.vocabulary, np.int64)
    v, m = len(vocab), enum.max_objects - 1
    cases = _cases(enum)
    actions, own_idx, others, outcome = cases[:, 0], cases[:, 1], cases[:, 2:2 + m], cases[:, -1]
    n_before = int(np.sum(outcome != vocab[own_idx]))
    key = actions * v + own_idx
    order = np.argsort(key, kind="stable")
    bounds = np.flatnonzero(np.diff(key[order])) + 1
    rules: list[Rule] = []
    for rows in np.split(order, bounds):
        a, c = int(actions[rows[0]]), int(vocab[own_idx[rows[0]]])
        counts = np.zeros((len(rows), v + 1), np.int64)
        if m:
            np.add.at(counts, (np.repeat(np.arange(len(rows)), m), others[rows].ravel()), 1)
        for box, y in _group_rules(counts[:, :v], outcome[rows], c, m):
            rules.append(Rule.from_bounds(a, c, y, {int(vocab[x]): b for x, b in box.items()}))
    rules.sort(key=lambda r: (r.action, r.code_from, r.code_to, r.requires, r.forbids, r.at_least, r.fewer_than))
    return RuleSet(enum.bits, enum.vocabulary, enum.max_objects, tuple(rules), n_before)


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


def apply_rules_batch(rules: RuleSet, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
    """Vectorized apply_rules: (B, K) codes and (B,) actions -> (B, K) next codes."""
    codes = np.asarray(codes, np.int64)
    actions = np.asarray(actions, np.int64)
    if codes.ndim != 2 or actions.shape != (len(codes),):
        raise ValueError(f"need (B, K) codes and (B,) actions, got {codes.shape} and {actions.shape}")
    out, written = codes.copy(), np.zeros(codes.shape, bool)
    by_action: dict[int, list[Rule]] = {}
    for r in rules.rules:
        by_action.setdefault(r.action, []).append(r)
    for a, group in by_action.items():
        rows = np.flatnonzero(actions == a)
        if not rows.size:
            continue
        sub = codes[rows]  # (n, K)
        totals: dict[int, np.ndarray] = {}
        for r in group:
            ok = sub == r.code_from  # (n, K)
            if not ok.any():
                continue
            for x, (lo, hi) in r.bounds().items():
                if x not in totals:
                    totals[x] = (sub == x).sum(1)
                others = totals[x][:, None] - (sub == x)  # (n, K) others with code x
                ok &= (others >= lo) & (others < hi)
            rr, kk = np.nonzero(ok)
            rr = rows[rr]
            clash = written[rr, kk] & (out[rr, kk] != r.code_to)
            if clash.any():
                raise AmbiguousRulesError(f"action {a}: rules with different outcomes match row {int(rr[clash][0])}")
            out[rr, kk] = r.code_to
            written[rr, kk] = True
    return out


@dataclass(frozen=True)
class Mismatch:
    """One enumerated transition where the rules and the network disagree."""

    codes: tuple[int, ...]
    action: int
    network: tuple[int, ...]
    rules: tuple[int, ...]

    def __post_init__(self) -> None:
        if not len(self.codes) == len(self.network) == len(self.rules):
            raise ValueError("codes, network and rules must describe the same objects")


@dataclass(frozen=True)
class Fidelity:
    """Agreement of rules with the network over every enumerated (scene, action) pair."""

    n_transitions: int
    n_exact: int  # transitions where every object's next code agrees
    n_object_codes: int
    n_object_codes_exact: int
    mismatches: tuple[Mismatch, ...]  # the first few disagreements

    def __post_init__(self) -> None:
        if not (0 <= self.n_exact <= self.n_transitions and 0 <= self.n_object_codes_exact <= self.n_object_codes):
            raise ValueError("exact counts must lie between 0 and the totals")

    @property
    def fraction(self) -> float:
        return self.n_exact / self.n_transitions if self.n_transitions else 1.0


def rule_fidelity(rules: RuleSet, enumeration: Enumeration, reference: bool = False, max_mismatches: int = 10) -> Fidelity:
    """Compare the rules with the network on every enumerated case.

    reference=True applies the pure-Python apply_rules row by row (slow, for cross-checks).
    """
    n_tr = n_ex = n_obj = n_obj_ex = 0
    mismatches: list[Mismatch] = []
    for b in enumeration.blocks:
        states = b.states
        if reference:
            pred = np.stack([apply_rules(rules, s, int(a)) for s, a in zip(states, b.actions)])
        else:
            pred = apply_rules_batch(rules, states, b.actions)
        eq = pred == b.next_codes  # (S*36, k)
        n_tr += len(eq)
        n_ex += int(eq.all(1).sum())
        n_obj += eq.size
        n_obj_ex += int(eq.sum())
        for r in np.flatnonzero(~eq.all(1))[: max_mismatches - len(mismatches)]:
            mismatches.append(Mismatch(tuple(states[r].tolist()), int(b.actions[r]),
                                       tuple(b.next_codes[r].tolist()), tuple(pred[r].tolist())))
    return Fidelity(n_tr, n_ex, n_obj, n_obj_ex, tuple(mismatches))
