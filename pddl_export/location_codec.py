"""The location-bit format: how a located code packs the effect model's learned code with the fields geometry gives
(the nearest table location, where the object stands off it, the height of its top), and how it is read back.

A located code is the learned code followed by `n_bits` location bits: its fields, packed most significant first
in the widths FIELD_WIDTHS gives for each format size (symlearn.symbolic.locations works out the fields' values from
the camera). The lifted domain reads the format of FIELD_BITS = 9: location (3 bits), place (3), level (3). This
module is the one place that shifts and masks them: encode_location packs, decode_location unpacks, on Python ints
and numpy integer arrays alike.

    >>> encode_location(5, (2, 0, 3))          # learned code 5; location 2, on it, its top at level 3
    2691
    >>> decode_location(2691)
    (5, (2, 0, 3))
"""
from __future__ import annotations

from typing import Sequence, TypeVar

import numpy as np

FIELD_WIDTHS: dict[int, tuple[int, ...]] = {  # format size -> its fields' widths, most significant first
    4: (3, 1),  # nearest location, off flag
    5: (3, 2),  # nearest location, which way off (locations.OFF_DIRECTIONS)
    6: (3, 3),  # nearest location, place: which way and how far off (locations.OFF_PLACES)
    7: (3, 1, 3),  # nearest location, off flag, height of the top in 5 cm layers
    9: (3, 3, 3),  # nearest location, place, height: the lifted domain's format
}
LOCATION_BITS = tuple(FIELD_WIDTHS)  # the format sizes m(z) accepts
FIELD_BITS = 9  # the location bits a lifted domain reads: location (3), place (3), level (3)
UNSEEN = 7  # the location field of an object with no visible pixel (its other fields are all ones too)

Code = TypeVar("Code", int, np.ndarray)


def field_widths(n_bits: int) -> tuple[int, ...]:
    """The widths of a format's fields, most significant first; ValueError for a size with no format."""
    try:
        widths = FIELD_WIDTHS.get(n_bits)
    except TypeError:  # unhashable: no format
        widths = None
    if widths is None:
        raise ValueError(f"location bits must be one of {LOCATION_BITS}, got {n_bits!r}")
    return widths


def _check_fits(value, width: int | None, what: str) -> None:
    """ValueError unless value (an int or an integer array) lies in 0..2**width - 1 (width None: any value >= 0)."""
    if type(value) is int and value >= 0 and (width is None or value < 1 << width):
        return  # the common case (one piece's field), without numpy's overhead
    v = np.asarray(value)
    if v.dtype.kind not in "iub":
        raise ValueError(f"the {what} must be integers, not {v.dtype}")
    if v.size and (v.min() < 0 or (width is not None and v.max() >= 1 << width)):
        bad = v.min() if v.min() < 0 else v.max()
        limit = "0 or more" if width is None else f"in 0..{(1 << width) - 1} ({width} bits)"
        raise ValueError(f"the {what} {int(bad)} does not lie {limit}")


def encode_location(learned: Code, fields: Sequence[Code], n_bits: int = FIELD_BITS) -> Code:
    """A located code: the learned code followed by the fields of the n_bits format (FIELD_WIDTHS), each field
    checked to fit its width, so that no field spills into its neighbour. Ints give an int; arrays an array."""
    widths = field_widths(n_bits)
    if len(fields) != len(widths):
        raise ValueError(f"the {n_bits}-bit location format has {len(widths)} fields, got {len(fields)}")
    _check_fits(learned, None, "learned code")
    code = learned
    for i, (value, width) in enumerate(zip(fields, widths)):
        _check_fits(value, width, f"location field {i}")
        code = (code << width) | value
    return code


def decode_location(code: Code, n_bits: int = FIELD_BITS) -> tuple[Code, tuple[Code, ...]]:
    """A located code read back: (its learned code, its fields in the n_bits format, most significant first), as
    encode_location packed them. Ints give ints; arrays arrays of the same shape."""
    fields = []
    for width in reversed(field_widths(n_bits)):
        fields.append(code & ((1 << width) - 1))
        code = code >> width
    return code, tuple(reversed(fields))
