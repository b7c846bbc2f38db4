"""Symbolic states and the transition-function protocol shared by search and PDDL export.

A symbolic state is one integer code per object, in object identity order: the encoder's
`bits`-bit binary vector read most significant bit first (vector element 0 is the MSB), so
code 0b00011011 with bits=8 is written "00011011". A transition function maps a batch of
states (all with the same number of objects K) and one action id per row (0..35,
pick * 6 + release) to the next states. It must be permutation-equivariant in the objects:
each object's next code depends on its own code and the multiset of the others' codes.

Nothing here imports torch or pybullet: the learned network is wrapped into this protocol by
symlearn, and hand-made functions serve in tests.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

N_LOCATIONS = 6  # table locations: far row 0-2, near row 3-5 (geometry in symlearn.world)
N_ACTIONS = N_LOCATIONS * N_LOCATIONS  # action id = pick * N_LOCATIONS + release


class TransitionFn(Protocol):
    bits: int

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """(B, K) int64 codes and (B,) int64 action ids -> (B, K) int64 next codes."""
        ...


class ScoredTransitionFn(TransitionFn, Protocol):
    """A transition function that also says how likely each of its predictions is."""

    def scored(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As __call__, plus (B,) float -log P(predicted next state) under the model (0: certain)."""
        ...


class OutcomeTransitionFn(TransitionFn, Protocol):
    """A transition function whose bits are independent given the input, with each bit's probability.

    The most likely next state thresholds them at 0.5; every other next state has a probability too,
    which the all-outcomes planner (search.learned_astar, `astar-outcomes`) reads.
    """

    def bit_probabilities(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """(B, K) int64 codes and (B,) action ids -> (B, K, bits) float P(each next bit is 1), MSB first."""
        ...


def code_str(code: int, bits: int) -> str:
    """Integer code -> its bit string, most significant bit first ('00011011')."""
    if not 0 <= int(code) < (1 << bits):
        raise ValueError(f"code {code} does not fit in {bits} bits")
    return format(int(code), f"0{bits}b")


def codes_from_bits(b: np.ndarray) -> np.ndarray:
    """(..., bits) array of 0/1 -> (...) int64 codes, element 0 the most significant bit."""
    b = np.asarray(b).astype(np.int64)
    weights = 1 << np.arange(b.shape[-1] - 1, -1, -1, dtype=np.int64)
    return (b * weights).sum(-1)


def bit_flip_costs(probs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(..., bits) P(each bit is 1) -> (the likeliest bits, the extra -log P of flipping each), both (..., bits).

    Bits are independent, so flipping bit b multiplies P by q_b / (1 - q_b), q_b the probability of the
    value it does not take in the likeliest state: the extra cost is log((1 - q_b) / q_b) >= 0 (inf if q_b = 0).
    """
    probs = np.asarray(probs, np.float64)
    top = probs >= 0.5
    q = np.where(top, 1.0 - probs, probs)
    with np.errstate(divide="ignore"):
        return top, np.log1p(-q) - np.log(q)


def bits_from_codes(codes: np.ndarray, bits: int) -> np.ndarray:
    """(...) int codes -> (..., bits) float32 0/1 vectors, element 0 the most significant bit."""
    codes = np.asarray(codes, np.int64)
    shifts = np.arange(bits - 1, -1, -1, dtype=np.int64)
    return ((codes[..., None] >> shifts) & 1).astype(np.float32)


@dataclass(frozen=True)
class SymbolicGoal:
    """Goal codes per object; None leaves an object free (partial goal)."""

    codes: tuple[int | None, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "codes", tuple(None if c is None else int(c) for c in self.codes))
        if all(c is None for c in self.codes):
            raise ValueError("a goal must fix the code of at least one object")

    def satisfied(self, states: np.ndarray) -> np.ndarray:
        """(B, K) codes -> (B,) bool."""
        states = np.atleast_2d(states)
        if states.shape[1] != len(self.codes):
            raise ValueError(f"goal has {len(self.codes)} objects, states have {states.shape[1]}")
        idx = [i for i, c in enumerate(self.codes) if c is not None]
        want = np.array([self.codes[i] for i in idx], np.int64)
        return np.all(states[:, idx] == want, axis=1)

    def mismatches(self, states: np.ndarray) -> np.ndarray:
        """(B, K) codes -> (B,) number of fixed objects whose code differs from the goal."""
        states = np.atleast_2d(states)
        idx = [i for i, c in enumerate(self.codes) if c is not None]
        want = np.array([self.codes[i] for i in idx], np.int64)
        return np.sum(states[:, idx] != want, axis=1)
