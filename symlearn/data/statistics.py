"""What a data set holds beyond effect sizes: shares of sticks, stacked objects and riders.

A *rider* is an object that was not held and still moved at least `RIDE_MIN_M` horizontally
while another object was carried: it stood on the carried object (Table I's cubes on a moved
stick). Objects knocked over by a released one count too; in this protocol that is rare. A
*stacked* object starts at least `STACK_MIN_M` above its resting height on the table, i.e.
on another object. Both are computed from poses, which the models never see.

    >>> shares = object_shares(load_split(Path("data/paper"), "all"))   # doctest: +SKIP
    >>> shares["stick_share"]                                           # doctest: +SKIP
    0.333
"""
from __future__ import annotations

import numpy as np

from symlearn.data.dataset import InteractionData
from symlearn.world import LOCATIONS, OBJECT_SIZE, TABLE_TOP_Z, ObjectType

STILL_M = 0.01  # an object that moved less than this (and was not held) stayed where it was
RIDE_MIN_M = 0.05  # a rider moves with the carried object: 5 cm is far above settling jitter (< 1 cm)
STACK_MIN_M = 0.02  # an object on another one starts at least its support's height (>= 5 cm) higher
LEVEL_M = 0.05  # height step of an arrangement label: a cube is 5 cm tall


def held_mask(data: InteractionData) -> np.ndarray:
    """(N, K) bool: the object the suction tool held in each sample (none where nothing was grasped)."""
    return data.grasped[:, None] == np.arange(data.effect.shape[1])[None, :]


def rider_mask(data: InteractionData) -> np.ndarray:
    """(N, K) bool: real objects that moved >= 5 cm horizontally while another object was held."""
    moved = np.linalg.norm(data.effect[..., :2], axis=-1) >= RIDE_MIN_M
    return data.mask & ~held_mask(data) & moved & (data.grasped[:, None] >= 0)


def still_mask(data: InteractionData) -> np.ndarray:
    """(N, K) bool: real objects that moved less than STILL_M and were not held: their arrangement is unchanged."""
    return data.mask & ~held_mask(data) & (np.linalg.norm(data.effect, axis=-1) < STILL_M)


def _rest_z(data: InteractionData) -> np.ndarray:
    """(N, K) height of each object's centre lying on the table (inf for padding)."""
    rest = np.full(data.obj_type.shape, np.inf, np.float32)
    for t in ObjectType:
        rest[data.obj_type == t] = TABLE_TOP_Z + OBJECT_SIZE[t][2] / 2
    return rest


def stacked_mask(data: InteractionData) -> np.ndarray:
    """(N, K) bool: real objects that start on top of another object rather than on the table."""
    return data.mask & (data.pre_pose[..., 2] - _rest_z(data) >= STACK_MIN_M)


def arrangement_labels(data: InteractionData, after: bool = False) -> np.ndarray:
    """(N, K) int64 name of each object's arrangement read from its pose: type, nearest location, height level.

    type * 1000 + location * 10 + level, the level counting 5 cm steps above the type's resting height
    on the table (0..9); -1 for padding. Symbols an ideal observer would give; the models never see poses.
    """
    pose = data.post_pose if after else data.pre_pose
    dist = np.linalg.norm(pose[..., None, :2] - np.asarray(LOCATIONS, np.float32)[None, None], axis=-1)  # (N, K, 6)
    level = np.clip(np.round((pose[..., 2] - _rest_z(data)) / LEVEL_M), 0, 9).astype(np.int64)
    label = data.obj_type.astype(np.int64) * 1000 + dist.argmin(-1) * 10 + level
    return np.where(data.mask, label, -1)


def object_shares(data: InteractionData) -> dict:
    """Counts and shares of sticks, stacked objects and riders, and how many scenes of each size hold a stick."""
    mask = data.mask
    n_obj = int(mask.sum())
    sticks = mask & (data.obj_type == ObjectType.STICK)
    riders, stacked = rider_mask(data), stacked_mask(data)
    with_stick = {}
    for k in np.unique(data.n_objects):
        rows = data.n_objects == k
        with_stick[str(int(k))] = round(float(sticks[rows].any(axis=1).mean()), 3)
    share = lambda m: round(float(m.sum() / max(n_obj, 1)), 4)  # noqa: E731
    return {"objects": n_obj, "sticks": int(sticks.sum()), "stick_share": share(sticks),
            "stacked": int(stacked.sum()), "stacked_share": share(stacked),
            "riders": int(riders.sum()), "rider_share": share(riders),
            "riders_on_stick": int((riders & (data.obj_type == ObjectType.CUBE)
                                    & (data.obj_type[np.arange(len(data)), np.maximum(data.grasped, 0)]
                                       == ObjectType.STICK)[:, None]).sum()),
            "scenes_with_stick_by_objects": with_stick}
