"""Plain data describing the tabletop world: locations, actions, object shapes and scenes.

No pybullet here: these types are shared by the simulator, the data set, the planners and tests.

    >>> action_id(pick=1, release=4)
    10
    >>> decode_action(10)
    Action(pick=1, release=4)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from pddl_export.symbolic import N_ACTIONS, N_LOCATIONS  # noqa: F401 (the action space, defined once)

TABLE_TOP_Z = 0.40
# Index order: far row (x = 0.80) left to right, then near row (x = 0.50); see docs/DESIGN.md.
LOCATIONS: tuple[tuple[float, float], ...] = (
    (0.80, -0.18), (0.80, 0.00), (0.80, 0.18),
    (0.50, -0.30), (0.50, 0.00), (0.50, 0.30),
)
if len(LOCATIONS) != N_LOCATIONS:
    raise ImportError("LOCATIONS must list one position per symbolic location")
NEAR_ROW = (3, 4, 5)
FAR_ROW = (0, 1, 2)


class ObjectType(IntEnum):
    CUBE = 0
    STICK = 1


# Full extents (x, y, z) in metres: a tall cube block and a stick lying along y.
OBJECT_SIZE: dict[ObjectType, tuple[float, float, float]] = {
    ObjectType.CUBE: (0.05, 0.05, 0.10),
    ObjectType.STICK: (0.05, 0.40, 0.05),
}
OBJECT_MASS = {ObjectType.CUBE: 0.10, ObjectType.STICK: 0.20}


@dataclass(frozen=True)
class Action:
    """A pick location and a release location, each an index into LOCATIONS."""

    pick: int
    release: int

    def __post_init__(self) -> None:
        for name in ("pick", "release"):
            v = getattr(self, name)
            if not (isinstance(v, (int, np.integer)) and 0 <= int(v) < N_LOCATIONS):
                raise ValueError(f"{name} location {v!r} is not in 0..{N_LOCATIONS - 1}")

    @property
    def id(self) -> int:
        return int(self.pick) * N_LOCATIONS + int(self.release)


def action_id(pick: int, release: int) -> int:
    """Index of (pick, release) in the 36-way one-hot encoding (pick-major)."""
    return Action(pick, release).id


def decode_action(aid: int) -> Action:
    """Inverse of action_id; refuses ids outside 0..35."""
    if not (isinstance(aid, (int, np.integer)) and 0 <= int(aid) < N_ACTIONS):
        raise ValueError(f"unknown action id {aid!r}: expected an integer in 0..{N_ACTIONS - 1}")
    return Action(int(aid) // N_LOCATIONS, int(aid) % N_LOCATIONS)


def one_hot_actions(ids: np.ndarray) -> np.ndarray:
    """(N,) action ids -> (N, 36) float32 one-hot rows."""
    ids = np.asarray(ids)
    if ids.size and (ids.min() < 0 or ids.max() >= N_ACTIONS):
        raise ValueError(f"unknown action id in {ids.min()}..{ids.max()}: expected 0..{N_ACTIONS - 1}")
    out = np.zeros((ids.shape[0], N_ACTIONS), np.float32)
    out[np.arange(ids.shape[0]), ids] = 1.0
    return out


@dataclass(frozen=True)
class ObjectState:
    """One object's type and pose (position xyz in metres, quaternion xyzw)."""

    type: ObjectType
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "type", ObjectType(self.type))
        if len(self.position) != 3 or len(self.orientation) != 4:
            raise ValueError("position needs 3 numbers and orientation 4 (xyzw)")
        object.__setattr__(self, "position", tuple(float(v) for v in self.position))
        object.__setattr__(self, "orientation", tuple(float(v) for v in self.orientation))


@dataclass(frozen=True)
class Scene:
    """Objects on the table, in a fixed order that is their identity."""

    objects: tuple[ObjectState, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        object.__setattr__(self, "objects", tuple(self.objects))
        if sum(o.type == ObjectType.STICK for o in self.objects) > 1:
            raise ValueError("a scene holds at most one stick")

    @property
    def k(self) -> int:
        return len(self.objects)

    def positions(self) -> np.ndarray:
        """(k, 3) positions in metres."""
        return np.array([o.position for o in self.objects], np.float64).reshape(-1, 3)

    def to_json(self) -> dict:
        return {"objects": [{"type": o.type.name.lower(), "position": list(o.position),
                             "orientation": list(o.orientation)} for o in self.objects]}

    @staticmethod
    def from_json(d: dict) -> "Scene":
        try:
            objs = [ObjectState(ObjectType[o["type"].upper()], tuple(o["position"]),
                                tuple(o.get("orientation", (0, 0, 0, 1)))) for o in d["objects"]]
        except (KeyError, TypeError, AttributeError) as e:
            raise ValueError(f"malformed scene description: {e!r}") from None
        return Scene(tuple(objs))
