"""The robot's exploration protocol: random initial scenes and random actions (no pybullet).

The authors' protocol (docs/DESIGN.md, reference facts), which reproduces the paper's 28,607 objects in 10,000
samples: 1, 2, 3 objects with probability 0.1, 0.2, 0.7; episodes of 4, 8, 20 actions; object
types the first k of a random permutation of (stick, cube, cube), so every 3-object scene holds
exactly one stick; the pick location is an occupied one with probability 0.8; the release
location is uniform over all six.

    >>> cfg = ExplorationConfig()
    >>> rng = np.random.default_rng(0)
    >>> spec = sample_scene_spec(rng, cfg)
    >>> 1 <= len(spec) <= 3
    True
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from symlearn.config_file import Bound, check_bounds
from symlearn.world import FAR_ROW, N_LOCATIONS, NEAR_ROW, Action, ObjectType

MAX_OBJECTS = 10  # the largest scene the simulator builds, a problem holds and the planners take; the data sets
# are collected at 1-5 objects, so 6-10-object scenes are zero-shot for every learned model
TYPE_DRAWS = ("authors", "independent")
# "near-row": the paper's scenes, every object dropped in the near row; "far-stick": a stick dropped in the far
# row and each other object (cubes) dropped in the far row with probability far_prob (on the stick, beside it or on
# each other), else in the near row: scenes where picking the stick carries what rests on it, an event random
# near-row episodes reach about once in 33 actions (367 of 12,000 in data/k15; far-stick: 2,391 of 12,000)
SCENE_DRAWS = ("near-row", "far-stick")


@dataclass(frozen=True)
class ExplorationConfig:
    """How scenes are drawn and actions chosen while collecting data."""

    k_values: tuple[int, ...] = (1, 2, 3)  # numbers of objects a scene may hold
    k_probs: tuple[float, ...] = (0.1, 0.2, 0.7)  # the paper's mix gives about 2.86 objects/sample
    episode_lengths: tuple[int, ...] = (4, 8, 20)  # actions per scene, by k (last one for larger k)
    # "authors": the first k of a shuffled (stick, cube, cube) (one stick in every scene of 3 or more
    # objects, a third of all objects sticks; 4-5 object scenes add cubes to the pool);
    # "independent": each object a stick with probability stick_prob while none is present (this
    # toolkit's protocol before 2026-11-28: 24.6% sticks, 27.5% of 3-object scenes without one)
    type_draw: str = "authors"
    stick_prob: float = 0.35  # used by type_draw="independent" only
    pick_occupied_prob: float = 0.8  # else the pick location is uniform over all six
    scene_draw: str = "near-row"  # where objects are dropped (SCENE_DRAWS)
    far_prob: float = 0.7  # scene_draw="far-stick": a cube dropped in the far row with this probability

    def __post_init__(self) -> None:
        if len(self.k_values) != len(self.k_probs) or not self.k_values:
            raise ValueError("k_values and k_probs must have the same, non-zero length")
        check_bounds(self, {"k_probs": Bound(0.0, 1.0), "episode_lengths": Bound(1, 10_000, integer=True)})
        for k in self.k_values:
            if not (isinstance(k, (int, np.integer)) and 1 <= k <= MAX_OBJECTS):
                raise ValueError(f"number of objects k={k!r} is out of range 1..{MAX_OBJECTS}")
        if abs(sum(self.k_probs) - 1.0) > 1e-6 or min(self.k_probs) < 0:
            raise ValueError(f"k_probs {self.k_probs} must be non-negative and sum to 1")
        if self.type_draw not in TYPE_DRAWS:
            raise ValueError(f"type_draw={self.type_draw!r}: expected one of {', '.join(TYPE_DRAWS)}")
        if self.scene_draw not in SCENE_DRAWS:
            raise ValueError(f"scene_draw={self.scene_draw!r}: expected one of {', '.join(SCENE_DRAWS)}")
        if not all(0.0 <= p <= 1.0 for p in (self.stick_prob, self.pick_occupied_prob, self.far_prob)):
            raise ValueError("stick_prob, pick_occupied_prob and far_prob must lie in [0, 1]")

    def episode_length(self, k: int) -> int:
        return self.episode_lengths[min(k, len(self.episode_lengths)) - 1]

    @staticmethod
    def with_k_range(lo: int, hi: int, type_draw: str = "authors") -> "ExplorationConfig":
        """Uniform over lo..hi objects (e.g. 4-5 for generalization scenes)."""
        return ExplorationConfig(type_draw=type_draw).over_objects(lo, hi)

    def over_objects(self, lo: int, hi: int) -> "ExplorationConfig":
        """These settings with scenes of lo..hi objects, uniformly (what `collect --objects` sets)."""
        ks = tuple(range(lo, hi + 1))
        if not ks:
            raise ValueError(f"empty object range {lo}-{hi}")
        return dataclasses.replace(self, k_values=ks, k_probs=tuple([1.0 / len(ks)] * len(ks)))

    @staticmethod
    def far_stick(lo: int = 2, hi: int = 4) -> "ExplorationConfig":
        """Carrying scenes: a stick in the far row with lo-1..hi-1 cubes, short episodes (4 actions) so most
        actions meet the scene while the cubes still rest on or beside the stick. The same from the command line:
        `collect --objects 2-4 --config F` with F's `[collect.exploration]` holding `scene_draw = "far-stick"` and
        `episode_lengths = [4]`."""
        return ExplorationConfig(episode_lengths=(4,), scene_draw="far-stick").over_objects(lo, hi)


def sample_types(rng: np.random.Generator, cfg: ExplorationConfig, k: int) -> list[ObjectType]:
    """Types of a k-object scene, drawn as `cfg.type_draw` says (see ExplorationConfig)."""
    if cfg.type_draw == "authors":
        pool = [ObjectType.STICK] + [ObjectType.CUBE] * (max(k, 3) - 1)
        return [pool[i] for i in rng.permutation(len(pool))[:k]]
    types, has_stick = [], False
    for _ in range(k):
        is_stick = (not has_stick) and rng.random() < cfg.stick_prob
        has_stick |= is_stick
        types.append(ObjectType.STICK if is_stick else ObjectType.CUBE)
    return types


def sample_scene_spec(rng: np.random.Generator, cfg: ExplorationConfig,
                      k: int | None = None) -> list[tuple[ObjectType, int]]:
    """Objects to drop, in order: (type, location). "near-row" scenes: near-row locations, distinct while they
    last, then stacked on a random one; at most one stick (types by `sample_types`). "far-stick" scenes: the stick
    first, in the far row, then cubes (see SCENE_DRAWS)."""
    if k is None:
        k = int(rng.choice(cfg.k_values, p=cfg.k_probs))
    if not 1 <= k <= MAX_OBJECTS:
        raise ValueError(f"number of objects k={k} is out of range 1..{MAX_OBJECTS}")
    if cfg.scene_draw == "far-stick":
        spec = [(ObjectType.STICK, int(rng.choice(FAR_ROW)))]
        for _ in range(k - 1):
            row = FAR_ROW if rng.random() < cfg.far_prob else NEAR_ROW
            spec.append((ObjectType.CUBE, int(rng.choice(row))))
        return spec
    locs = list(rng.permutation(NEAR_ROW))
    types = sample_types(rng, cfg, k)
    return [(t, int(locs[i]) if i < len(locs) else int(rng.choice(NEAR_ROW))) for i, t in enumerate(types)]


def sample_action(rng: np.random.Generator, occupied: np.ndarray, cfg: ExplorationConfig) -> Action:
    """A random action: pick an occupied location with probability p, else any; release anywhere."""
    occ = np.flatnonzero(occupied)
    if occ.size and rng.random() < cfg.pick_occupied_prob:
        pick = int(rng.choice(occ))
    else:
        pick = int(rng.integers(N_LOCATIONS))
    return Action(pick, int(rng.integers(N_LOCATIONS)))
