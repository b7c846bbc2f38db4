"""Location bits: where each object stands on the table, read from its own depth crop, to follow its learned code.

The effect model's 8-bit codes name objects by how they look and how they move. They do not always say where an
object stands: a stick at location 0 or 1 of the far row can get one code. A plan over such codes reaches the
goal's codes with an object one location (18-32 cm) off, which the benchmark counts as symbol aliasing
(docs/RESULTS.md, "Location bits"). `symlearn train-transition --location-bits` trains m(z) on codes followed by
LOCATION_BITS bits that geometry gives: the table location nearest the object (3 bits, 0-5; UNSEEN for an object
with no visible pixel) and whether the object stands more than OFF_LOCATION_M from it (1 bit). Both come from the
same crops and window origins the encoder sees, back-projected through the camera, so stored samples and live
observations get the same bits. On the paper set they agree with the recorded poses for every object on a
location and for 97-100% of the flags.

    >>> bits = location_bits(np.float32([[0.80, 0.19], [0.50, -0.20], [np.nan, np.nan]]))
    >>> bits.astype(int).tolist()   # location 2, on it; location 3, 10 cm off; nothing visible
    [[0, 1, 0, 0], [0, 1, 1, 1], [1, 1, 1, 1]]
"""
from __future__ import annotations

import numpy as np

from symlearn.world import LOCATIONS

LOCATION_BITS = 4  # 3 bits of nearest location, 1 bit "off it"
OFF_LOCATION_M = 0.05  # as Problem.goal_off_locations: more than 5 cm (xy) from every location is off
UNSEEN = 7  # the nearest-location field of an object with no visible pixel (its flag is set too)


def location_bits(xy: np.ndarray) -> np.ndarray:
    """(..., 2) world xy (NaN: not seen) -> (..., LOCATION_BITS) float32 0/1, MSB first: nearest location, off flag."""
    xy = np.asarray(xy, np.float64)
    locs = np.asarray(LOCATIONS, np.float64)  # (6, 2)
    dist = np.linalg.norm(xy[..., None, :] - locs, axis=-1)  # (..., 6), NaN where not seen
    seen = np.isfinite(dist).all(-1)
    nearest = np.where(seen, np.argmin(np.where(seen[..., None], dist, 0.0), -1), UNSEEN)
    off = ~seen | (np.where(seen, dist.min(-1, initial=np.inf, where=np.isfinite(dist)), 0.0) > OFF_LOCATION_M)
    field = (nearest[..., None] >> np.arange(2, -1, -1)) & 1  # (..., 3)
    return np.concatenate([field, off[..., None]], -1).astype(np.float32)
