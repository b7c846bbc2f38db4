"""Location bits: where each object stands on the table, read from its own depth crop, to follow its learned code.

The effect model's 8-bit codes name objects by how they look and how they move. They do not always say where an
object stands: a stick at location 0 or 1 of the far row can get one code. A plan over such codes reaches the
goal's codes with an object one location (18-32 cm) off, which the benchmark counts as symbol aliasing
(docs/RESULTS.md, "Location bits"). `[transition] location_bits = N` in a settings file
(`symlearn train-transition --config FILE`) trains m(z) on codes followed by N bits that geometry gives: the
table location nearest the object (3 bits, 0-5; UNSEEN for an object with no visible pixel), then whether the
object stands more than OFF_LOCATION_M from it: with N = 4 one bit, off or not; with N = 5 two bits that also
say which way (OFF_DIRECTIONS: on, off toward -y, off toward +y, off mainly in x); with N = 6 three bits that
say which way and how far (OFF_PLACES: on, -y or +y by 5-9, 9-15 or over 15 cm, off mainly in x). Objects land
off a location by a few distances (a stick grasped at its end: 18 cm; tipped over a neighbour: 6-8 cm; pushed:
10-14 cm), and a plan that puts a stick off by the wrong one misses a 2 cm goal.
With N = 7 the 4-bit field is followed by 3 bits of height: the object's top above the table in 5 cm layers
(HEIGHT_STEP_M, 0-7), which tells a cube at the bottom of a stack from one on top of it. N = 9, the recommended
preset's (`train-transition`'s default; the lifted domain reads it), joins the two: the 3-bit place of N = 6,
then the 3 height bits of N = 7. Over three seeds 7 and 9 bits plan alike with m(z) itself, 9 better with the
exported rules (docs/RESULTS.md, "Location bits"); 4, 5, 6 and 7 are kept to compare. All come from the
same crops and window origins the encoder sees, back-projected through the camera, so stored samples and live
observations get the same bits. On the paper set they agree with the recorded poses for every object on a
location; the side of an off object agrees for all of them.

    >>> bits = location_bits(np.float32([[0.80, 0.19], [0.50, -0.20], [np.nan, np.nan]]), 5)
    >>> bits.astype(int).tolist()   # location 2, on it; location 3, 10 cm off toward +y; nothing visible
    [[0, 1, 0, 0, 0], [0, 1, 1, 1, 0], [1, 1, 1, 1, 1]]
"""
from __future__ import annotations

import numpy as np

from pddl_export.location_codec import encode_location, field_widths
from pddl_export.symbolic import bits_from_codes
from symlearn.world import LOCATIONS, TABLE_TOP_Z

OFF_LOCATION_M = 0.05  # as Problem.goal_off_locations: more than 5 cm (xy) from every location is off
OFF_DIRECTIONS = ("on", "-y", "+y", "x")  # the 2-bit off field of N = 5, in value order
OFF_DISTANCE_EDGES_M = (0.09, 0.15)  # N = 6: how far off in y, in three bands (5-9, 9-15, over 15 cm)
OFF_PLACES = ("on", "-y near", "-y mid", "-y far", "+y near", "+y mid", "+y far", "x")  # the 3-bit field of N = 6
HEIGHT_STEP_M = 0.05  # N = 7, 9: an object's top above the table, in layers of this height (a cube's half side)
HEIGHTED_BITS = (7, 9)  # the sizes that end with the 3 height bits, and so need each object's top


def location_bits(xy: np.ndarray, n_bits: int, top: np.ndarray | None = None) -> np.ndarray:
    """(..., 2) world xy (NaN: not seen) -> (..., n_bits) float32 0/1, MSB first: nearest location, then off field.

    N = 7 and 9 also need `top`, (...,) the world z of each object's highest visible point (camera.crop_tops_z).
    """
    widths = field_widths(n_bits)  # the format's fields (location_codec.FIELD_WIDTHS); refuses a size with none
    if n_bits in HEIGHTED_BITS and top is None:
        raise ValueError(f"{n_bits} location bits need each object's top height (top=...)")
    xy = np.asarray(xy, np.float64)
    locs = np.asarray(LOCATIONS, np.float64)  # (6, 2)
    seen = np.isfinite(xy).all(-1)
    delta = np.where(seen[..., None, None], xy[..., None, :], 0.0) - locs  # (..., 6, 2)
    dist = np.linalg.norm(delta, axis=-1)
    nearest = np.argmin(dist, -1)
    offset = np.take_along_axis(delta, nearest[..., None, None], -2)[..., 0, :]  # (..., 2) from that location
    off = dist.min(-1) > OFF_LOCATION_M
    in_x = np.abs(offset[..., 0]) > np.abs(offset[..., 1])
    if n_bits in (4, 7):  # the off flag
        field = off.astype(np.int64)
    elif n_bits == 5:
        way = np.where(in_x, 3, np.where(offset[..., 1] < 0, 1, 2))
        field = np.where(off, way, 0)
    else:  # 6 and 9: the place
        band = 1 + np.searchsorted(np.asarray(OFF_DISTANCE_EDGES_M), np.abs(offset[..., 1]), side="right")
        field = np.where(off, np.where(in_x, 7, np.where(offset[..., 1] < 0, band, 3 + band)), 0)
    fields = [nearest, field]
    if n_bits in HEIGHTED_BITS:  # then the top's layer above the table
        layers = np.rint((np.asarray(top, np.float64) - TABLE_TOP_Z) / HEIGHT_STEP_M)
        fields.append(np.clip(np.where(np.isfinite(layers), layers, 7), 0, 7).astype(np.int64))
    # an unseen object's fields are all ones (its location location_codec.UNSEEN)
    fields = [np.where(seen, f, (1 << w) - 1).astype(np.int64) for f, w in zip(fields, widths)]
    return bits_from_codes(encode_location(np.zeros_like(fields[0]), fields, n_bits), n_bits)
