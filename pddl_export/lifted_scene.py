"""Located codes read as a scene of pieces: which object stands where, on what, and what is on top of each location.

A located code (9 location bits: `symlearn train-transition --preset recommended`, the default) is the effect
model's learned bits followed by three fields read from geometry: the nearest table location (3 bits; 7 when
nothing of the object is visible), its place (3 bits; 0 when it stands on the location, else which way and how far
off), and the height of its top above the table in 5 cm layers (3 bits). Of the learned bits, some track where the
crop lies in the image (the encoder sees each pixel's image x and y) and so repeat the location; the others say
what the object is and how it stands. A `CodeLayout` names the learned bits a lifted domain keeps (`kept`: those
that do not track the location, chosen from data by `position_bits`).

`read_scene` turns one state's codes into `Piece`s and the relations a lifted domain plans with: the top of
every location (a far-row stick's ends cover its row neighbours) and what each on-location piece stands on.
Everything here is plain data and numpy: no torch, no pybullet.

    >>> layout = CodeLayout(code_bits=8, kept=(0, 6))
    >>> p = layout.piece(0b10000010_000_000_010, stick=False)   # bits 0 and 6 set, location 0, on it, level 2
    >>> (p.kind, p.loc, p.place, p.level)
    (3, 0, 0, 2)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from pddl_export.location_codec import FIELD_BITS, decode_location

N_LOCATIONS = 6
FAR_ROW = (0, 1, 2)
NEAR_ROW = (3, 4, 5)
SIZE_LAYERS = {False: 2, True: 1}  # a cube is two 5 cm layers tall, a stick lying flat one


def neighbours(loc: int) -> tuple[int, ...]:
    """The far-row locations a stick lying at loc has an end over (0.18 m apart); none in the near row."""
    if loc not in FAR_ROW:
        return ()
    return tuple(n for n in FAR_ROW if abs(n - loc) == 1)


@dataclass(frozen=True)
class CodeLayout:
    """How a located code splits: `code_bits` learned bits (MSB first), of which `kept` are kept, then 9 field bits."""

    code_bits: int = 8
    kept: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not 1 <= self.code_bits <= 16:
            raise ValueError(f"code_bits={self.code_bits} must lie in 1..16")
        if list(self.kept) != sorted(set(self.kept)) or any(not 0 <= b < self.code_bits for b in self.kept):
            raise ValueError(f"kept bits {self.kept} must be distinct, increasing indices below {self.code_bits}")

    @property
    def bits(self) -> int:
        """The width of a located code."""
        return self.code_bits + FIELD_BITS

    def learned(self, code: int) -> int:
        """The learned part of a located code."""
        return decode_location(int(code))[0]

    def kind(self, code: int) -> int:
        """The kept learned bits of a code, packed in `kept` order (the first kept bit most significant)."""
        learned = self.learned(code)
        out = 0
        for b in self.kept:
            out = (out << 1) | ((learned >> (self.code_bits - 1 - b)) & 1)
        return out

    def kind_bits(self, kind: int) -> tuple[tuple[int, int], ...]:
        """((kept bit, its value 0 or 1), ...) of a packed kind, in `kept` order (as `kind` packs them)."""
        return tuple((bit, (kind >> (len(self.kept) - 1 - pos)) & 1) for pos, bit in enumerate(self.kept))

    def with_kind(self, learned: int, kind: int) -> int:
        """A learned code with its kept bits set to `kind` (as `kind` packs them), the other bits as they were."""
        for bit, value in self.kind_bits(kind):
            mask = 1 << (self.code_bits - 1 - bit)
            learned = (learned | mask) if value else (learned & ~mask)
        return learned

    def piece(self, code: int, stick: bool) -> "Piece":
        """One object's piece, read from its located code."""
        code = int(code)
        if not 0 <= code < (1 << self.bits):
            raise ValueError(f"code {code} does not fit in {self.bits} bits")
        _, (loc, place, level) = decode_location(code)
        return Piece(kind=self.kind(code), stick=bool(stick), loc=loc, place=place, level=level)


@dataclass(frozen=True)
class Piece:
    """What a lifted domain knows of one object: its kept learned bits, its type, location, place and level."""

    kind: int
    stick: bool
    loc: int  # 0-5, or location_codec.UNSEEN
    place: int  # 0: on the location; else off it
    level: int  # top above the table, 5 cm layers

    @property
    def on_location(self) -> bool:
        return self.place == 0 and self.loc < N_LOCATIONS

    def covers(self) -> tuple[int, ...]:
        """The locations whose top this piece can be: its nearest one (on it or off it), and the row neighbours of
        a far-row stick lying on its location (its ends)."""
        if self.loc >= N_LOCATIONS:
            return ()
        if self.stick and self.place == 0:
            return tuple(sorted((self.loc, *neighbours(self.loc))))
        return (self.loc,)


@dataclass(frozen=True)
class SceneGraph:
    """Relations read from pieces: each location's top piece and each piece's support (None: the table)."""

    pieces: tuple[Piece, ...]
    tops: tuple[int | None, ...]  # per location 0-5
    support: tuple[int | None, ...]  # per piece; None for the table or an unseen piece


def top_of(pieces: Sequence[Piece], loc: int, skip: frozenset = frozenset()) -> int | None:
    """The highest piece covering loc (ties: one standing at loc, then the lower index), or None for the table."""
    best, key = None, None
    for i, p in enumerate(pieces):
        if i in skip or loc not in p.covers():
            continue
        k = (p.level, p.loc == loc, -i)
        if key is None or k > key:
            best, key = i, k
    return best


def support_of(pieces: Sequence[Piece], i: int) -> int | None:
    """What piece i stands on: the highest lower piece covering one of its locations; None for the table."""
    me = pieces[i]
    foot = set(me.covers())
    best, key = None, None
    for j, p in enumerate(pieces):
        if j == i or p.level >= me.level or not foot & set(p.covers()):
            continue
        k = (p.level, p.loc == me.loc, -j)
        if key is None or k > key:
            best, key = j, k
    return best


def read_scene(pieces: Sequence[Piece]) -> SceneGraph:
    """The scene graph of one state's pieces."""
    pieces = tuple(pieces)
    tops = tuple(top_of(pieces, loc) for loc in range(N_LOCATIONS))
    support = tuple(support_of(pieces, i) if p.loc < N_LOCATIONS else None for i, p in enumerate(pieces))
    return SceneGraph(pieces, tops, support)


def position_bits(learned: np.ndarray, locations: np.ndarray, min_info: float = 0.25) -> tuple[int, ...]:
    """The learned bits that track the location: mutual information with it of at least min_info bits.

    learned: (N, code_bits) 0/1 per observed object; locations: (N,) its nearest location. A bit that never
    changes carries nothing either way and is reported as tracking nothing (it is dropped by `kept_bits`).
    """
    learned = np.asarray(learned).astype(np.int64)
    locations = np.asarray(locations).astype(np.int64)
    if learned.ndim != 2 or learned.shape[0] != locations.shape[0]:
        raise ValueError(f"learned bits {learned.shape} and locations {locations.shape} do not match")
    return tuple(b for b in range(learned.shape[1]) if _mutual_information(learned[:, b], locations) >= min_info)


def kept_bits(learned: np.ndarray, locations: np.ndarray, min_info: float = 0.25) -> tuple[int, ...]:
    """The learned bits a lifted domain keeps: those that vary and do not track the location."""
    learned = np.asarray(learned).astype(np.int64)
    tracking = set(position_bits(learned, locations, min_info))
    varying = {b for b in range(learned.shape[1]) if 0 < learned[:, b].mean() < 1}
    return tuple(sorted(varying - tracking))


def _entropy(*columns: np.ndarray) -> float:
    _, counts = np.unique(np.column_stack(columns), axis=0, return_counts=True)
    p = counts / counts.sum()
    return float(-(p * np.log2(p)).sum())


def _mutual_information(x: np.ndarray, y: np.ndarray) -> float:
    return _entropy(x) + _entropy(y) - _entropy(x, y)
