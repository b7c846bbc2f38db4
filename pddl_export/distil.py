"""Distil an enumerated transition function into exact, mutually exclusive symbolic rules.

A rule (pddl_export.rules.Rule) reads: under `action`, an object whose code is `code_from`
takes `code_to` when the OTHER objects' codes satisfy a context of count conditions:
"some other object has code X" (requires), "no other object has code X" (forbids), "at
least n others have X" (at_least) and "fewer than n others have X" (fewer_than). All
objects are updated simultaneously from the pre-state; an object no rule matches keeps its
code.

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
    >>> from pddl_export.rules import apply_rules
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

import numpy as np
from sklearn.tree import DecisionTreeClassifier

from pddl_export.enumeration import Enumeration
from pddl_export.rules import INF, Bounds, Rule, RuleSet
from pddl_export.symbolic import N_ACTIONS


class NotEquivariantError(ValueError):
    """Two objects with the same code in one scene were given different next codes."""

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



class _Contexts:
    """Sets of enumerated contexts as Python-int bitmasks, by count intervals (cached per threshold)."""

    def __init__(self, counts: np.ndarray) -> None:
        self.counts = counts
        self.max_count = int(counts.max(initial=0))
        self.full = (1 << len(counts)) - 1
        self._ge: dict[tuple[int, int], int] = {}

    def ge(self, x: int, t: int) -> int:
        """Contexts with count_x >= t."""
        if t <= 0:
            return self.full
        if t > self.max_count:
            return 0
        if (x, t) not in self._ge:
            self._ge[(x, t)] = _bitmask(self.counts[:, x] >= t)
        return self._ge[(x, t)]

    def interval(self, x: int, a: int, b: int) -> int:
        """Contexts with a <= count_x < b."""
        return self.ge(x, a) & ~self.ge(x, b)


def _widen_box(i: int, lo: np.ndarray, hi: np.ndarray, ys: np.ndarray, alive: np.ndarray, ctx: _Contexts,
               bad: dict[int, int]) -> bool:
    """One pass over box i's conditions, widening each at most once (in place); whether anything changed."""
    changed = False
    conds = [int(x) for x in np.flatnonzero((lo[i] > 0) | (hi[i] < INF))]
    masks = [ctx.interval(x, int(lo[i, x]), int(hi[i, x])) for x in conds]
    # Alive boxes are pairwise disjoint; widening code x can only create an overlap with
    # a box separated from box i by x alone.
    sep = np.maximum(lo[i], lo) >= np.minimum(hi[i], hi)  # (R, V) codes separating i from j
    n_sep = sep.sum(1)
    for k, x in enumerate(conds):
        rest = ctx.full
        for j, mk in enumerate(masks):
            if j != k:
                rest &= mk
        xlo, xhi = int(lo[i, x]), int(hi[i, x])
        only_x = alive & (n_sep == sep[:, x])
        only_x[i] = False
        for new in [(0, INF)] + ([(0, xhi), (xlo, INF)] if xlo > 0 and xhi < INF else []):
            if rest & ctx.interval(x, *new) & bad[int(ys[i])]:
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
            masks[k] = ctx.interval(x, *new)
            sep = np.maximum(lo[i], lo) >= np.minimum(hi[i], hi)
            n_sep = sep.sum(1)
            changed = True
            break
    return changed


def _generalize(lo: np.ndarray, hi: np.ndarray, ys: np.ndarray, counts: np.ndarray,
                outcomes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Greedy exact widening of disjoint boxes (step 5 of the module docstring).

    A widened box is accepted when no enumerated context inside it has another outcome
    (checked with bitmasks over the contexts) and it stays logically disjoint from every other
    box, except same-outcome boxes it contains, which are removed.
    """
    ctx = _Contexts(counts)
    bad = {int(y): _bitmask(outcomes != y) for y in np.unique(ys)}  # contexts with another outcome
    lo, hi = lo.copy(), hi.copy()
    alive = np.ones(len(ys), bool)
    changed = True
    while changed:
        changed = False
        for i in range(len(ys)):
            if alive[i] and _widen_box(i, lo, hi, ys, alive, ctx, bad):
                changed = True
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
    if not len(cases):
        raise ValueError(f"nothing to distil: no enumerated case (no scene of the {v} vocabulary codes with at most "
                         f"{enum.max_objects} objects); collect more data or lower --min-count")
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
