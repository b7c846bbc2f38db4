"""Planning problems as JSON files: an initial scene, a goal scene, and the actions that made it.

This module holds the problem format: the Problem dataclass, its validation, loading and saving,
and the distance by which success is judged (max_goal_distance). Problems are drawn in the
simulator by symlearn.problems.problem_generation; scenes are placed and encoded by
symlearn.symbolic.scenes.

    >>> problem = load_problem(Path("problems/p13/problem_0000.json"))  # doctest: +SKIP
    >>> problem.generator_length, problem.initial.k                     # doctest: +SKIP
    (3, 2)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from pddl_export.bounded_json import DEFAULT_MAX_BYTES, JsonFileError, MiB, read_json_file
from symlearn.problems.paths import check_safe_name, is_safe_name
from symlearn.sim.exploration import MAX_OBJECTS
from symlearn.provenance import atomic_write_json
from symlearn.world import (LOCATIONS, N_ACTIONS, N_LOCATIONS, OBJECT_SIZE, TABLE_TOP_Z, ObjectType, Scene,
                            decode_action)

PROBLEM_FORMAT = "symlearn-problem"
PROBLEM_VERSION = 3  # 2 added "task" and "free", 3 the shortest plan; version 1 and 2 files still load (not computed)
READABLE_VERSIONS = (1, 2, 3)
# why a problem has no shortest-plan length (symlearn.problems.shortest explains each)
OPTIMAL_REASONS = ("goal_off_locations", "pose_not_covered", "search_cap", "unreachable")
RANDOM_WALK = "random-walk"  # the task of problems drawn by random actions
GOAL_TOLERANCE_M = 0.02  # success: every object within this distance of its goal position
ON_LOCATION_M = 0.05  # an object whose xy lies farther than this from every table location is "off the locations"
# The reach of a valid scene: object centres over the table, at most this far from the middle of the
# location grid (x, y), and between the table top and REACH_Z_MAX; orientations unit quaternions.
REACH_CENTER_X = (min(x for x, _ in LOCATIONS) + max(x for x, _ in LOCATIONS)) / 2  # 0.65
REACH_HALF_X, REACH_HALF_Y = 0.5, 0.6
REACH_Z_MAX = 1.0
QUATERNION_NORM_TOL = 1e-3
# Two objects overlap when their centres lie closer than the balls inscribed in their boxes allow (a box holds
# the ball of half its smallest side around its centre, whatever its orientation: 2.5 cm for a cube and a stick),
# less what settling presses objects into each other (shipped problems keep >= 7.5 cm between centres, 36
# random walks of 4-8 objects >= 6.3 cm).
OVERLAP_SLACK_M = 0.005
_KEYS = ("format", "version", "name", "seed", "spec", "initial", "actions", "goal", "generator_length")
MAX_ACTIONS = 100  # generator actions a problem file may list (random walks take a handful)
MAX_TASK_CHARS = 10_000
PROBLEM_FILE_BYTES = 4 * MiB  # a problem file is a few kilobytes
PROBLEMS_MANIFEST = "problems.manifest"  # a generated set's settings (JSON, not *.json: never read as a problem)


@dataclass(frozen=True)
class Problem:
    """A named planning problem: build `spec`, place `initial`, reach `goal` (object order is identity)."""

    name: str
    seed: int  # the generator's base seed: problem i of a set is drawn from default_rng([seed, i])
    spec: tuple[tuple[ObjectType, int], ...]  # objects dropped in order at (type, near-row location)
    initial: Scene  # poses after building and settling
    actions: tuple[int, ...]  # the generator's action ids: a known valid plan
    goal: Scene  # poses the generator's actions ended in
    task: str = RANDOM_WALK  # what made it: "random-walk", or a structure suite's task name ("tower-2", ...)
    free: tuple[int, ...] = ()  # objects the goal leaves free: their goal poses and codes are not judged
    # The shortest plan in the world (symlearn.problems.shortest): its length and one such plan, or no length
    # and the reason (OPTIMAL_REASONS) the model cannot decide; all three None: not computed (a version 1-2 file).
    optimal_length: int | None = None
    optimal_reason: str | None = None
    optimal_plan: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        check_safe_name(self.name, "problem")
        self._check_optimal()
        if not isinstance(self.task, str) or not self.task:
            raise ValueError(f"problem {self.name}: task must be a non-empty string, got {self.task!r}")
        if not all(_is_int(i) for i in self.free):
            raise ValueError(f"problem {self.name}: free must list object indices, got {list(self.free)!r}")
        object.__setattr__(self, "free", tuple(sorted(set(int(i) for i in self.free))))
        if not _is_int(self.seed):
            raise ValueError(f"problem {self.name}: seed must be an integer, got {self.seed!r}")
        spec = tuple((ObjectType(t), int(loc)) for t, loc in self.spec)
        object.__setattr__(self, "spec", spec)
        object.__setattr__(self, "actions", tuple(int(a) for a in self.actions))
        p = f"problem {self.name}"
        if not 1 <= len(spec) <= MAX_OBJECTS:
            raise ValueError(f"{p}: {len(spec)} objects, expected 1..{MAX_OBJECTS}")
        bad = [loc for _, loc in spec if not 0 <= loc < N_LOCATIONS]
        if bad:
            raise ValueError(f"{p}: object location {bad[0]} is out of range 0..{N_LOCATIONS - 1}")
        bad = [a for a in self.actions if not 0 <= a < N_ACTIONS]
        if bad:
            raise ValueError(f"{p}: action id {bad[0]} is out of range 0..{N_ACTIONS - 1}")
        bad = [i for i in self.free if not 0 <= i < len(spec)]
        if bad:
            raise ValueError(f"{p}: free object {bad[0]} is out of range 0..{len(spec) - 1}")
        if len(self.free) == len(spec):
            raise ValueError(f"{p}: the goal leaves every object free")
        types = tuple(t for t, _ in spec)
        for what, scene in (("initial", self.initial), ("goal", self.goal)):
            if not isinstance(scene, Scene):
                raise ValueError(f"{p}: {what} must be a Scene")
            if tuple(o.type for o in scene.objects) != types:
                raise ValueError(f"{p}: {what} scene objects {[o.type.name.lower() for o in scene.objects]} "
                                 f"do not match the spec {[t.name.lower() for t in types]}")
            check_scene(scene, f"{p}: {what} scene")

    def _check_optimal(self) -> None:
        p = f"problem {self.name}"
        n, why, plan = self.optimal_length, self.optimal_reason, self.optimal_plan
        if why is not None and why not in OPTIMAL_REASONS:
            raise ValueError(f"{p}: optimal_reason {why!r} is not one of {', '.join(OPTIMAL_REASONS)}")
        if n is not None:
            if not (_is_int(n) and n >= 0):
                raise ValueError(f"{p}: optimal_length must be a non-negative integer or null, got {n!r}")
            if why is not None:
                raise ValueError(f"{p}: optimal_length {n} comes with a reason ({why}); one or the other")
            if not isinstance(plan, (tuple, list)) or not all(_is_int(a) and 0 <= a < N_ACTIONS for a in plan):
                raise ValueError(f"{p}: optimal_plan must list action ids 0..{N_ACTIONS - 1}, got {plan!r}")
            if len(plan) != n:
                raise ValueError(f"{p}: optimal_plan has {len(plan)} actions, optimal_length says {n}")
            object.__setattr__(self, "optimal_plan", tuple(int(a) for a in plan))
        elif plan is not None:
            raise ValueError(f"{p}: optimal_plan given without an optimal_length")

    @property
    def k(self) -> int:
        return len(self.spec)

    @property
    def optimal_known(self) -> bool:
        """Whether the shortest plan was searched for (a length or a reason), as version 3 files record."""
        return self.optimal_length is not None or self.optimal_reason is not None

    @property
    def generator_length(self) -> int:
        """Length of the generator's own plan (the reference plan): an upper bound on the optimum."""
        return len(self.actions)

    @property
    def fixed(self) -> tuple[int, ...]:
        """Objects whose goal pose is judged (all but the free ones)."""
        return tuple(i for i in range(self.k) if i not in self.free)

    @property
    def goal_off_locations(self) -> int:
        """How many judged objects the goal puts more than ON_LOCATION_M (in xy) from every table location.

        A random walk can leave a stick across two places or an object pushed aside; symbols of place and
        level cannot name such a pose, so the benchmark reports success on these goals apart.
        """
        return sum(min(math.hypot(self.goal.objects[i].position[0] - x, self.goal.objects[i].position[1] - y)
                       for x, y in LOCATIONS) > ON_LOCATION_M for i in self.fixed)

    def to_json(self) -> dict:
        return {"format": PROBLEM_FORMAT, "version": PROBLEM_VERSION, "name": self.name, "seed": self.seed,
                "spec": [[t.name.lower(), loc] for t, loc in self.spec], "initial": self.initial.to_json(),
                "actions": list(self.actions),
                "actions_readable": [f"pick {decode_action(a).pick} -> release {decode_action(a).release}"
                                     for a in self.actions],
                "goal": self.goal.to_json(), "generator_length": self.generator_length,
                "task": self.task, "free": list(self.free), "optimal_length": self.optimal_length,
                "optimal_reason": self.optimal_reason,
                "optimal_plan": None if self.optimal_plan is None else list(self.optimal_plan)}

    @staticmethod
    def from_json(d: dict, where: str = "problem") -> "Problem":
        """Parse and validate; every refusal is a one-line ValueError that names the problem."""
        if not isinstance(d, dict):
            raise ValueError(f"{where}: expected a JSON object, got {type(d).__name__}")
        name = d.get("name") if is_safe_name(d.get("name")) else None
        p = where if name is None else f"problem {name}" if where == "problem" else f"{where} (problem {name})"
        missing = [k for k in _KEYS if k not in d]
        if missing:
            raise ValueError(f"{p}: missing keys {', '.join(missing)}")
        if d["format"] != PROBLEM_FORMAT:
            raise ValueError(f"{p}: not a symlearn problem (format {d['format']!r})")
        if not _is_int(d["version"]) or d["version"] not in READABLE_VERSIONS:  # true == 1 in Python
            raise ValueError(f"{p}: problem version {d['version']!r}, this symlearn reads versions "
                             f"{', '.join(map(str, READABLE_VERSIONS))}")
        task, free = d.get("task", RANDOM_WALK), d.get("free", [])
        if d["version"] >= 3:
            missing = [k for k in ("optimal_length", "optimal_reason", "optimal_plan") if k not in d]
            if missing:
                raise ValueError(f"{p}: missing keys {', '.join(missing)} (a version 3 problem records its "
                                 f"shortest plan, or null)")
        optimal = (d.get("optimal_length"), d.get("optimal_reason"), d.get("optimal_plan"))
        if optimal[2] is not None and not isinstance(optimal[2], list):
            raise ValueError(f"{p}: optimal_plan must be a list of action ids or null")
        if not isinstance(task, str) or not task or len(task) > MAX_TASK_CHARS:
            raise ValueError(f"{p}: task must be a non-empty string of at most {MAX_TASK_CHARS} characters")
        if not isinstance(free, list) or len(free) > MAX_OBJECTS or not all(_is_int(i) for i in free):
            raise ValueError(f"{p}: free must be a list of object indices, got {free!r}")
        check_safe_name(d["name"], where)  # the name becomes a folder (RUN/pddl/problems/NAME)
        if not _is_int(d["seed"]):
            raise ValueError(f"{p}: seed must be an integer, got {d['seed']!r}")
        spec = d["spec"]
        if not isinstance(spec, list) or not all(isinstance(e, list) and len(e) == 2 for e in spec):
            raise ValueError(f"{p}: spec must be a list of [type, location] pairs")
        if not 1 <= len(spec) <= MAX_OBJECTS:
            raise ValueError(f"{p}: spec lists {len(spec)} objects, expected 1..{MAX_OBJECTS}")
        parsed = []
        for t, loc in spec:
            if not isinstance(t, str) or t.upper() not in ObjectType.__members__:
                raise ValueError(f"{p}: unknown object type {t!r} (expected cube or stick)")
            if not _is_int(loc) or not 0 <= loc < N_LOCATIONS:
                raise ValueError(f"{p}: object location {loc!r} is out of range 0..{N_LOCATIONS - 1}")
            parsed.append((ObjectType[t.upper()], loc))
        actions = d["actions"]
        if not isinstance(actions, list) or not all(_is_int(a) for a in actions):
            raise ValueError(f"{p}: actions must be a list of integer action ids")
        if len(actions) > MAX_ACTIONS:
            raise ValueError(f"{p}: {len(actions)} actions, more than the {MAX_ACTIONS} a problem may list")
        if d["generator_length"] != len(actions):
            raise ValueError(f"{p}: generator_length {d['generator_length']!r} does not match "
                             f"{len(actions)} actions")
        scenes = {}
        for key in ("initial", "goal"):
            scenes[key] = _scene(d[key], f"{p}: {key} scene")
        try:
            return Problem(d["name"], int(d["seed"]), tuple(parsed), scenes["initial"], tuple(actions), scenes["goal"],
                           task, tuple(free), *optimal)
        except ValueError as e:
            msg = str(e).removeprefix(f"problem {name}: ")
            raise ValueError(msg if msg.startswith(p) else f"{p}: {msg}") from None


class OutOfReach(ValueError):
    """A scene with an object past the table's reach: refused as a problem; a generator draws again instead."""


def check_scene(scene: Scene, where: str) -> None:
    """Refuse (one-line ValueError) non-finite poses, non-unit quaternions, positions out of the table's reach
    (OutOfReach) and objects that overlap (check_no_overlap)."""
    for i, o in enumerate(scene.objects):
        pos, quat = np.asarray(o.position, np.float64), np.asarray(o.orientation, np.float64)
        if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(quat))):
            raise ValueError(f"{where}: object {i} has a non-finite pose")
        norm = float(np.linalg.norm(quat))
        if abs(norm - 1.0) > QUATERNION_NORM_TOL:
            raise ValueError(f"{where}: object {i} orientation {list(o.orientation)} is not a unit quaternion "
                             f"(norm {norm:.4g})")
        x, y, z = pos
        if not (abs(x - REACH_CENTER_X) < REACH_HALF_X and abs(y) < REACH_HALF_Y and TABLE_TOP_Z <= z <= REACH_Z_MAX):
            raise OutOfReach(f"{where}: object {i} position {list(o.position)} is out of the table's reach "
                             f"(|x-{REACH_CENTER_X:.2f}| < {REACH_HALF_X}, |y| < {REACH_HALF_Y}, "
                             f"{TABLE_TOP_Z} <= z <= {REACH_Z_MAX})")
    check_no_overlap([(i, o.type, o.position) for i, o in enumerate(scene.objects)], where)


def check_no_overlap(objects: Sequence[tuple[int, ObjectType, Sequence[float]]], where: str) -> None:
    """Refuse (one-line ValueError naming both objects) two of `objects` (index, type, centre) whose centres lie
    closer than their shapes allow: nearer than the sum of their inscribed balls' radii (half the smallest side)
    less OVERLAP_SLACK_M. Such a scene cannot stand on the table, and symbols would put both objects at one
    location and level."""
    for a, (i, ti, pi) in enumerate(objects):
        for j, tj, pj in objects[a + 1:]:
            least = (min(OBJECT_SIZE[ObjectType(ti)]) + min(OBJECT_SIZE[ObjectType(tj)])) / 2 - OVERLAP_SLACK_M
            dist = math.dist(pi, pj)
            if dist < least:
                raise ValueError(f"{where}: objects {i} ({ObjectType(ti).name.lower()}) and {j} "
                                 f"({ObjectType(tj).name.lower()}) overlap: their centres lie {dist * 100:.1f} cm "
                                 f"apart, less than the {least * 100:.1f} cm their shapes allow")


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _scene(d, where: str) -> Scene:
    """A scene from JSON with type and shape checks on every object."""
    if not isinstance(d, dict) or not isinstance(d.get("objects"), list):
        raise ValueError(f"{where} must be an object with an 'objects' list")
    if len(d["objects"]) > MAX_OBJECTS:
        raise ValueError(f"{where}: {len(d['objects'])} objects, more than {MAX_OBJECTS}")
    for o in d["objects"]:
        if not isinstance(o, dict) or not isinstance(o.get("type"), str):
            raise ValueError(f"{where}: every object needs a type")
        for key, n in (("position", 3), ("orientation", 4)):
            v = o.get(key, [0, 0, 0, 1] if key == "orientation" else None)
            if (not isinstance(v, list) or len(v) != n
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
                raise ValueError(f"{where}: object {key} must be {n} finite numbers, got {v!r}")
    try:
        return Scene.from_json(d)
    except (ValueError, KeyError) as e:
        raise ValueError(f"{where}: {str(e).splitlines()[0]}") from None


def save_problem(path: Path, problem: Problem) -> None:
    """Write one problem file atomically."""
    atomic_write_json(Path(path), problem.to_json())


def load_problem(path: Path) -> Problem:
    """Read and validate one problem file; refuses malformed files with a one-line ValueError."""
    path = Path(path)
    if not path.exists():
        raise ValueError(f"problem {path.name}: no such file {path}")
    d = read_json_file(path, what="problem file", max_bytes=PROBLEM_FILE_BYTES)
    return Problem.from_json(d, where=f"problem file {path}")


def load_problems(problems_dir: Path) -> list[tuple[Path, Problem]]:
    """All *.json problems of a directory, in name order. A generated set that holds fewer problems than its
    manifest lists (its `symlearn problems` stopped early) is refused: a benchmark over part of a set would report
    figures for problems it never ran."""
    problems_dir = Path(problems_dir)
    if not problems_dir.is_dir():
        raise ValueError(f"no problem directory at {problems_dir}; run 'symlearn problems' first")
    paths = sorted(problems_dir.glob("*.json"))
    if not paths:
        raise ValueError(f"{problems_dir} holds no problem files (*.json)")
    listed = _listed(problems_dir)
    if listed is not None and len(paths) < listed:
        raise ValueError(f"{problems_dir} holds {len(paths)} of the {listed} problems its {PROBLEMS_MANIFEST} lists: the "
                         f"`symlearn problems` that made it stopped early; run the same command again to complete it")
    return [(p, load_problem(p)) for p in paths]


def read_manifest(problems_dir: Path, max_bytes: int = DEFAULT_MAX_BYTES):
    """The JSON value of a set's manifest (PROBLEMS_MANIFEST), or None where it is missing or cannot be read: its
    readers decide what a missing one means."""
    manifest = Path(problems_dir) / PROBLEMS_MANIFEST
    if not manifest.is_file():
        return None
    try:
        return read_json_file(manifest, max_bytes=max_bytes, what="problem manifest")
    except JsonFileError:
        return None


def _listed(problems_dir: Path) -> int | None:
    """How many problems a set's manifest says it holds: its n, for a random-walk set or a structure suite (a
    stratified set's n counts per cell); None where there is no such manifest, or it cannot be read (the generator
    refuses that one itself)."""
    m = read_manifest(problems_dir, max_bytes=MiB)
    if not isinstance(m, dict) or m.get("stratify"):
        return None
    n = m.get("n")
    return n if isinstance(n, int) and not isinstance(n, bool) else None


def max_goal_distance(scene: Scene, goal: Scene, free: tuple[int, ...] = ()) -> float:
    """Largest distance (m) between an object's position and its goal position, free objects not counted."""
    if scene.k != goal.k:
        raise ValueError(f"scene has {scene.k} objects, goal {goal.k}")
    fixed = [i for i in range(scene.k) if i not in free]
    if not fixed:
        return 0.0
    return float(np.linalg.norm(scene.positions()[fixed] - goal.positions()[fixed], axis=1).max())
