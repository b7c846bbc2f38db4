"""Query a transition function on every scene of up to `max_objects` objects over a vocabulary.

The transition function is permutation-equivariant (pddl_export.symbolic), so a scene is a
MULTISET of codes: one sorted ordering per multiset is enough, C(V + k - 1, k) scenes of k
objects over a vocabulary of V codes, each paired with all 36 actions. Scenes are built with
numpy (no per-scene Python loop) and sent to the transition function in large batches: one
call per scene size and chunk of `batch_size` rows.

    >>> import numpy as np
    >>> class Swap:                       # action 0 turns code 1 into 2, nothing else changes
    ...     bits = 2
    ...     def __call__(self, codes, actions):
    ...         out = codes.copy()
    ...         out[(actions[:, None] == 0) & (codes == 1)] = 2
    ...         return out
    >>> e = enumerate_transitions(Swap(), [1, 2], max_objects=2)
    >>> [b.scenes.shape for b in e.blocks], e.n_queries
    ([(2, 1), (3, 2)], 180)
    >>> vocabulary_closure(Swap(), [1], max_objects=2).vocabulary
    (1, 2)
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from math import comb
from typing import Sequence

import numpy as np

from pddl_export.symbolic import N_ACTIONS, TransitionFn


def multiset_indices(n_symbols: int, k: int) -> np.ndarray:
    """All multisets of size k over range(n_symbols) as sorted rows, in lexicographic order.

    Same rows and order as itertools.combinations_with_replacement, built column by column:
    each row with last element l is repeated n_symbols - l times and extended by l, l+1, ...
    """
    if n_symbols < 1 or k < 1:
        raise ValueError(f"need n_symbols >= 1 and k >= 1, got {n_symbols}, {k}")
    rows = np.arange(n_symbols, dtype=np.int64)[:, None]  # (V, 1)
    for _ in range(k - 1):
        last = rows[:, -1]
        reps = n_symbols - last  # children per row
        starts = np.cumsum(reps) - reps
        offsets = np.arange(int(reps.sum()), dtype=np.int64) - np.repeat(starts, reps)
        new_col = np.repeat(last, reps) + offsets
        rows = np.concatenate([np.repeat(rows, reps, axis=0), new_col[:, None]], axis=1)
    return rows


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class SceneBlock:
    """Every scene of one size k and the network's answer to each of the 36 actions.

    Row r of `actions` / `next_codes` is scene r // 36 under action r % 36.
    """

    n_objects: int
    scenes: np.ndarray  # (S, k) int64 codes, each row sorted by vocabulary order
    actions: np.ndarray  # (S * 36,) int64 action ids
    next_codes: np.ndarray  # (S * 36, k) int64 next codes

    def __post_init__(self) -> None:
        k, s = self.n_objects, len(self.scenes)
        if self.scenes.ndim != 2 or self.scenes.shape[1] != k:
            raise ValueError(f"scenes must be (S, {k}), got {self.scenes.shape}")
        if self.actions.shape != (s * N_ACTIONS,):
            raise ValueError(f"actions must be ({s * N_ACTIONS},), got {self.actions.shape}")
        if self.next_codes.shape != (s * N_ACTIONS, k):
            raise ValueError(f"next_codes must be ({s * N_ACTIONS}, {k}), got {self.next_codes.shape}")
        for name in ("scenes", "actions", "next_codes"):
            object.__setattr__(self, name, _readonly(np.asarray(getattr(self, name), np.int64)))

    @property
    def states(self) -> np.ndarray:
        """(S * 36, k) pre-state codes aligned with `actions` and `next_codes`."""
        return np.repeat(self.scenes, N_ACTIONS, axis=0)


@dataclass(frozen=True, eq=False)
class Enumeration:
    """The transition function's answers on every multiset scene of 1..max_objects objects."""

    bits: int
    vocabulary: tuple[int, ...]  # sorted, distinct codes
    max_objects: int
    blocks: tuple[SceneBlock, ...]  # one per scene size 1..max_objects
    n_calls: int  # calls made to the transition function
    seconds: float  # wall clock spent inside those calls
    complete: bool = True  # every multiset of each size; False: a chosen set of scenes (e.g. observed ones)

    def __post_init__(self) -> None:
        vocab = tuple(int(c) for c in self.vocabulary)
        if not vocab or list(vocab) != sorted(set(vocab)):
            raise ValueError("vocabulary must be non-empty, sorted and distinct")
        if any(not 0 <= c < (1 << self.bits) for c in vocab):
            raise ValueError(f"vocabulary codes must fit in {self.bits} bits")
        object.__setattr__(self, "vocabulary", vocab)
        if [b.n_objects for b in self.blocks] != list(range(1, self.max_objects + 1)):
            raise ValueError("need exactly one block per scene size 1..max_objects")
        for b in self.blocks:
            if not self.complete:
                if len(b.scenes) and not np.isin(b.scenes, vocab).all():
                    raise ValueError(f"{b.n_objects}-object block has codes outside the vocabulary")
                continue
            want = comb(len(vocab) + b.n_objects - 1, b.n_objects)
            if len(b.scenes) != want:
                raise ValueError(f"{b.n_objects}-object block has {len(b.scenes)} scenes, want {want}")
        if self.n_calls < 0 or self.seconds < 0:
            raise ValueError("n_calls and seconds must be >= 0")

    @property
    def n_scenes(self) -> int:
        return sum(len(b.scenes) for b in self.blocks)

    @property
    def n_queries(self) -> int:
        """(scene, action) pairs sent to the transition function."""
        return self.n_scenes * N_ACTIONS

    @property
    def queries_per_s(self) -> float:
        return self.n_queries / self.seconds if self.seconds > 0 else float("inf")

    def produced_codes(self) -> tuple[int, ...]:
        """Every code the transition function returned, sorted."""
        return tuple(int(c) for c in np.unique(np.concatenate([b.next_codes.ravel() for b in self.blocks])))


def _checked_vocabulary(vocabulary: Sequence[int], bits: int) -> tuple[int, ...]:
    vocab = tuple(sorted({int(c) for c in vocabulary}))
    if not vocab:
        raise ValueError("vocabulary must hold at least one code")
    if vocab[0] < 0 or vocab[-1] >= (1 << bits):
        raise ValueError(f"vocabulary codes must lie in 0..{(1 << bits) - 1}")
    return vocab


def enumerate_transitions(
    transition: TransitionFn,
    vocabulary: Sequence[int],
    max_objects: int = 3,
    batch_size: int = 65536,
) -> Enumeration:
    """Ask `transition` for every multiset scene of 1..max_objects codes times all 36 actions."""
    bits = int(transition.bits)
    vocab = _checked_vocabulary(vocabulary, bits)
    if max_objects < 1:
        raise ValueError(f"max_objects must be >= 1, got {max_objects}")
    if batch_size < 1:
        raise ValueError(f"batch_size must be >= 1, got {batch_size}")
    vocab_arr = np.array(vocab, np.int64)
    scenes = [vocab_arr[multiset_indices(len(vocab), k)] for k in range(1, max_objects + 1)]
    return _query(transition, bits, vocab, scenes, batch_size, complete=True)


def enumerate_scenes(transition: TransitionFn, vocabulary: Sequence[int], scenes: Sequence[Sequence[int]],
                     max_objects: int = 3, batch_size: int = 65536) -> Enumeration:
    """Ask `transition` for the given scenes only (as sorted multisets, duplicates dropped) times all 36 actions.

    For scenes that can occur (for instance those observed in the training data) rather than every
    multiset of codes: the network's answers on impossible scenes then constrain nothing.
    """
    bits = int(transition.bits)
    vocab = _checked_vocabulary(vocabulary, bits)
    by_size: list[set] = [set() for _ in range(max_objects)]
    for sc in scenes:
        sc = tuple(sorted(int(c) for c in sc))
        if not 1 <= len(sc) <= max_objects:
            raise ValueError(f"scene {sc} has {len(sc)} objects, expected 1..{max_objects}")
        by_size[len(sc) - 1].add(sc)
    arrays = [np.array(sorted(s), np.int64).reshape(-1, k) for k, s in enumerate(by_size, 1)]
    return _query(transition, bits, vocab, arrays, batch_size, complete=False)


def _query(transition: TransitionFn, bits: int, vocab: tuple[int, ...], scene_arrays: list[np.ndarray],
           batch_size: int, complete: bool) -> Enumeration:
    """Every scene of every size times the 36 actions, in batched calls of at most batch_size rows."""
    if batch_size < 1:
        raise ValueError(f"batch_size must be >= 1, got {batch_size}")
    blocks, n_calls, seconds = [], 0, 0.0
    for k, scenes in enumerate(scene_arrays, 1):
        n_rows = len(scenes) * N_ACTIONS
        actions = np.tile(np.arange(N_ACTIONS, dtype=np.int64), len(scenes))  # (S*36,)
        next_codes = np.empty((n_rows, k), np.int64)
        for start in range(0, n_rows, batch_size):
            stop = min(start + batch_size, n_rows)
            codes = scenes[np.arange(start, stop) // N_ACTIONS]  # (n, k)
            t0 = time.perf_counter()
            out = transition(codes, actions[start:stop].copy())
            seconds += time.perf_counter() - t0
            n_calls += 1
            out = np.asarray(out)
            if out.shape != codes.shape:
                raise ValueError(f"transition returned shape {out.shape} for input {codes.shape}")
            if out.size and (out.min() < 0 or out.max() >= (1 << bits)):
                raise ValueError(f"transition returned codes outside 0..{(1 << bits) - 1}")
            next_codes[start:stop] = out
        blocks.append(SceneBlock(k, scenes, actions, next_codes))
    return Enumeration(bits, vocab, len(scene_arrays), tuple(blocks), n_calls, seconds, complete)


@dataclass(frozen=True, eq=False)
class Closure:
    """A vocabulary closed under the transition function, and the enumeration over it."""

    vocabulary: tuple[int, ...]
    added: tuple[tuple[int, ...], ...]  # codes added by each iteration
    missing: tuple[int, ...]  # produced but not enumerated: empty iff converged
    enumeration: Enumeration  # over `vocabulary`
    n_queries: int  # over all iterations
    seconds: float  # time inside the transition function, all iterations

    def __post_init__(self) -> None:
        if tuple(self.vocabulary) != self.enumeration.vocabulary:
            raise ValueError("enumeration must be over the closure's vocabulary")
        if set(self.missing) & set(self.vocabulary):
            raise ValueError("missing codes cannot be in the vocabulary")

    @property
    def converged(self) -> bool:
        """True at a fixed point: every code the network produced is in the vocabulary."""
        return not self.missing


def vocabulary_closure(
    transition: TransitionFn,
    vocabulary: Sequence[int],
    max_objects: int = 3,
    max_iterations: int = 8,
    batch_size: int = 65536,
) -> Closure:
    """Add the codes the transition function produces from enumerated scenes until none is new.

    Each iteration enumerates every scene over the current vocabulary, at most max_iterations
    times. At the fixed point the last enumeration is complete for the returned vocabulary, so
    callers need not run it again; otherwise `missing` lists the codes still left out.
    """
    if max_iterations < 1:
        raise ValueError(f"max_iterations must be >= 1, got {max_iterations}")
    vocab = _checked_vocabulary(vocabulary, int(transition.bits))
    added: list[tuple[int, ...]] = []
    n_queries, seconds = 0, 0.0
    for iteration in range(max_iterations):
        enum = enumerate_transitions(transition, vocab, max_objects, batch_size)
        n_queries += enum.n_queries
        seconds += enum.seconds
        new = tuple(sorted(set(enum.produced_codes()) - set(vocab)))
        if not new or iteration == max_iterations - 1:
            return Closure(vocab, tuple(added), new, enum, n_queries, seconds)
        added.append(new)
        vocab = tuple(sorted(set(vocab) | set(new)))
    raise AssertionError("unreachable")
