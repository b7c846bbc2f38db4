"""Every successor of a batch of joint states under the rules, for searches that expand in batches.

apply_rules_batch (pddl_export.rules) answers one (state, action) per row; a search wants every
action's successor of every frontier state, and over joint states of 4-5 objects it meets
millions of them. RuleSuccessors answers all actions at once: it groups rules by own code,
touches only the objects that hold that code, and tests all of a code's rules, whatever their
action, in one comparison (RuleSet.dense_groups stacked per own code). What an object does depends only
on its own code and how many others hold each code its rules count, so each such answer is kept: a search
meets the same few again and again, and with the rules of 1-5-object scenes (161,021 rules on 17-bit codes)
the comparison was 95% of rules-outcomes' time (docs/BENCHMARKS.md). Tests check it against
apply_rules_batch and the row-by-row apply_rules. States pack into one int64 key (pack_states)
for duplicate detection.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)),))
    >>> succ = RuleSuccessors(rs)
    >>> succ.actions.tolist(), succ(np.array([[1, 2], [3, 1]])).tolist()
    ([5], [[[2, 2]], [[3, 1]]])
"""
from __future__ import annotations

from functools import cached_property

import numpy as np

from pddl_export.rules import COUNT_CAP, RuleSet

MAX_PACKED_BITS = 62  # a packed state must fit in a non-negative int64
MEMO_SIZE = 500_000  # (own code, context counts) answers RuleSuccessors keeps; it starts afresh past this


def pack_states(states: np.ndarray, bits: int) -> np.ndarray:
    """(..., K) codes of `bits` bits each -> (...) int64 keys, object 0 in the lowest bits; refuses K * bits > 62."""
    states = np.asarray(states, np.int64)
    k = states.shape[-1]
    if k * bits > MAX_PACKED_BITS:
        raise ValueError(f"{k} objects of {bits}-bit codes do not pack into one int64 "
                         f"(at most {MAX_PACKED_BITS // bits} objects)")
    return (states << np.arange(k, dtype=np.int64) * bits).sum(axis=-1)


class RuleSuccessors:
    """states (F, K) -> next states (F, A, K) under each of the rules' A changing actions (self.actions).

    The rules are compiled per own code c: the codes any rule on c counts (its context codes) and
    each rule's [lo, hi) bounds on them as dense arrays. A batch is then evaluated per code: the
    (state, object) pairs holding c, their others' counts of c's context codes, and one
    broadcast comparison against all of c's rules at once (the rules of one action and own
    code are mutually exclusive, so at most one of them fires per pair and action).
    """

    def __init__(self, rules: RuleSet, chunk: int = 20_000) -> None:
        self.rules, self.bits, self.chunk = rules, int(rules.bits), int(chunk)
        self.actions = np.array(rules.actions, np.int64)
        column = {int(a): i for i, a in enumerate(self.actions)}
        dense = rules.dense_groups  # per (action, own code), as RuleSet built them; stacked here per own code
        self._context = np.array(sorted({int(x) for cols, *_ in dense.values() for x in cols}), np.int64)
        where = {int(x): i for i, x in enumerate(self._context)}
        by_code: dict[int, list] = {}
        for (a, c), group in dense.items():
            by_code.setdefault(c, []).append((column[a], group))
        self._groups = {}  # own code -> (context columns, (R, C) lo, (R, C) hi, (R,) action column, (R,) code_to)
        for c, parts in sorted(by_code.items()):
            cols = sorted({where[int(x)] for _, (codes, *_) in parts for x in codes})
            pos = {j: i for i, j in enumerate(cols)}
            n = sum(len(group[3]) for _, group in parts)
            lo = np.zeros((n, len(cols)), np.int16)
            hi = np.full((n, len(cols)), COUNT_CAP + 1, np.int16)
            row = 0
            for _, (codes, glo, ghi, _) in parts:
                idx = [pos[where[int(x)]] for x in codes]
                lo[row:row + len(glo), idx], hi[row:row + len(glo), idx] = glo, ghi
                row += len(glo)
            self._groups[c] = (np.array(cols, np.int64), lo, hi,
                               np.concatenate([np.full(len(g[3]), a, np.int64) for a, g in parts]),
                               np.concatenate([g[3] for _, g in parts]))
        self._memo: dict[tuple[int, bytes], tuple[np.ndarray, np.ndarray]] = {}

    @cached_property
    def code_changes(self) -> frozenset[tuple[int, int]]:
        """The (code_from, code_to) pairs of the rules: the code graph of the searches' heuristic, read once."""
        return frozenset((r.code_from, r.code_to) for r in self.rules.rules)

    def __call__(self, states: np.ndarray) -> np.ndarray:
        states = np.asarray(states, np.int64)
        if states.ndim != 2:
            raise ValueError(f"states must have shape (F, K), got {states.shape}")
        f, k = states.shape
        out = np.repeat(states[:, None, :], len(self.actions), axis=1)  # (F, A, K): unchanged unless a rule fires
        for lo_row in range(0, f, self.chunk):
            part = states[lo_row:lo_row + self.chunk]
            counts = (part[:, :, None] == self._context).sum(axis=1)  # (F', C) objects holding each context code
            for c in np.unique(part).tolist():  # only the codes present: a small batch holds few
                if c not in self._groups:
                    continue
                cols = self._groups[c][0]
                rows, pos = np.nonzero(part == c)
                others = counts[rows][:, cols] - (self._context[cols] == c)  # (n, C_c) counts among the OTHER objects
                others = np.minimum(others, COUNT_CAP).astype(np.int16)  # as the int16 bounds (rules._dense_group)
                contexts, which = np.unique(others, axis=0, return_inverse=True)
                which = which.reshape(-1)  # per (state, object) pair: its row of contexts
                acts, tos, starts, sizes = self._fired(c, contexts)
                n_fired = sizes[which]  # per pair: the rules that fire on it
                pair = np.repeat(np.arange(len(rows)), n_fired)
                entry = np.repeat(starts[which] - np.cumsum(n_fired) + n_fired, n_fired) + np.arange(len(pair))
                out[lo_row + rows[pair], acts[entry], pos[pair]] = tos[entry]
        return out

    def _fired(self, c: int, contexts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For (U, C_c) distinct context counts of own code c: the fired rules' action columns and next codes,
        concatenated, with each context's start and size in them.

        An object's next code under each action depends only on its own code and these counts, and a search
        meets the same few again and again (most actions move one or two objects), so each answer is kept:
        only contexts not seen before go through the (U', R, C_c) comparison with c's rules.
        """
        memo = self._memo
        keys = [(c, row.tobytes()) for row in contexts]
        found = [memo.get(key) for key in keys]
        new = [i for i, hit in enumerate(found) if hit is None]
        if new:
            _, lo, hi, acol, code_to = self._groups[c]
            fresh = contexts[new]
            fires = np.all((fresh[:, None, :] >= lo) & (fresh[:, None, :] < hi), axis=2)  # (U', R)
            if len(memo) + len(new) > MEMO_SIZE:
                memo.clear()
            for i, hit in zip(new, fires):
                r = np.flatnonzero(hit)
                found[i] = memo[keys[i]] = (acol[r], code_to[r])
        sizes = np.array([len(a) for a, _ in found], np.int64)
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        acts = np.concatenate([a for a, _ in found]) if found else np.zeros(0, np.int64)
        tos = np.concatenate([t for _, t in found]) if found else np.zeros(0, np.int64)
        return acts, tos, starts, sizes
