"""User-written goal files: which objects there are, where they start, and the arrangement to reach.

A goal file (JSON, docs/PROBLEMS.md) lists the objects in identity order, each with its type, the
location it is dropped at to make the initial scene (as `Problem.spec`), and its goal: a location
and what it stands on ("table", another object's index, or {"stick_end": i}), or null for an object
the goal leaves free. This module parses and checks the format and derives what is pure: the drop
order of an arrangement (supports first) and each fixed object's expected position, with the
geometric check of a settled scene against them. Building in the simulator is goal_problems.py.

    >>> goal = load_goal(Path("examples/goals/fig6_composite.json"))  # doctest: +SKIP
    >>> drop_order(goal)                                              # doctest: +SKIP
    (0, 1, 3, 2)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pddl_export.bounded_json import MiB, read_json_file
from symlearn.problems.problem import check_no_overlap
from symlearn.provenance import atomic_write_json
from symlearn.sim.exploration import MAX_OBJECTS
from symlearn.world import (FAR_ROW, LOCATIONS, N_ACTIONS, N_LOCATIONS, OBJECT_SIZE, TABLE_TOP_Z, ObjectType, Scene,
                            action_id)

GOAL_FORMAT = "symlearn-goal"
GOAL_VERSION = 1
GOAL_TASK = "goal"  # the task name of a problem made from a goal file that names none
ARRANGEMENT_TOLERANCE_M = 0.02  # a settled object this far from where its arrangement puts it is refused
MAX_TILT_DEG = 10.0  # an object tilted more than this has fallen or leans on something
_OBJECT_KEYS = {"type", "initial", "goal"}
_TOP_KEYS = {"format", "version", "objects", "reference_plan", "task", "seed", "description"}
MAX_PLAN_STEPS = 100  # a reference plan is executed step by step in the simulator: a few dozen is plenty
MAX_TEXT = 10_000  # characters of a task name or description
GOAL_FILE_BYTES = 1 * MiB


@dataclass(frozen=True)
class ObjectGoal:
    """Where one object must end: a location and its support (None: the table; `end`: on that stick's end)."""

    location: int
    on: int | None = None
    end: bool = False  # `on` is a stick and this object stands on the end over `location`

    def to_json(self) -> dict:
        on = "table" if self.on is None else {"stick_end": self.on} if self.end else self.on
        return {"location": self.location, "on": on}


@dataclass(frozen=True)
class Goal:
    """Objects dropped in order at (type, location), the arrangement to reach (None: free), a reference plan."""

    spec: tuple[tuple[ObjectType, int], ...]
    targets: tuple[ObjectGoal | None, ...]
    plan: tuple[int, ...] | None = None  # action ids; None: no reference plan (its length is unknown)
    task: str = GOAL_TASK
    seed: int = 0

    @property
    def free(self) -> tuple[int, ...]:
        return tuple(i for i, t in enumerate(self.targets) if t is None)

    def to_json(self) -> dict:
        d = {"format": GOAL_FORMAT, "version": GOAL_VERSION, "task": self.task, "seed": self.seed,
             "objects": [{"type": t.name.lower(), "initial": loc, "goal": None if g is None else g.to_json()}
                         for (t, loc), g in zip(self.spec, self.targets)]}
        if self.plan is not None:
            d["reference_plan"] = [[a // N_LOCATIONS, a % N_LOCATIONS] for a in self.plan]
        return d


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _location(v, what: str, where: str) -> int:
    if not (_is_int(v) and 0 <= v < N_LOCATIONS):
        raise ValueError(f"{where}: {what} {v!r} is not a location 0..{N_LOCATIONS - 1}")
    return v


def _target(d, i: int, where: str) -> ObjectGoal | None:
    """One object's goal from JSON: null, or {"location": L, "on": "table" | j | {"stick_end": j}}."""
    if d is None:
        return None
    if not isinstance(d, dict) or set(d) != {"location", "on"}:
        raise ValueError(f"{where}: object {i} goal must be null or {{\"location\": L, \"on\": ...}}, got {d!r}")
    loc, on = _location(d["location"], f"object {i} goal location", where), d["on"]
    if on == "table":
        return ObjectGoal(loc)
    if _is_int(on):
        return ObjectGoal(loc, on)
    if isinstance(on, dict) and set(on) == {"stick_end"} and _is_int(on["stick_end"]):
        return ObjectGoal(loc, on["stick_end"], end=True)
    raise ValueError(f"{where}: object {i} stands on {on!r}: expected \"table\", an object index or "
                     f"{{\"stick_end\": index}}")


def _plan(v, where: str) -> tuple[int, ...] | None:
    """A reference plan: a list of [pick, release] pairs or action ids."""
    if v is None:
        return None
    if not isinstance(v, list):
        raise ValueError(f"{where}: reference_plan must be a list of [pick, release] pairs or action ids")
    if len(v) > MAX_PLAN_STEPS:
        raise ValueError(f"{where}: reference_plan has {len(v)} steps, more than the {MAX_PLAN_STEPS} a goal may carry")
    out = []
    for step, a in enumerate(v):
        if _is_int(a) and 0 <= a < N_ACTIONS:
            out.append(a)
        elif isinstance(a, list) and len(a) == 2:
            out.append(action_id(_location(a[0], f"reference_plan step {step} pick", where),
                                 _location(a[1], f"reference_plan step {step} release", where)))
        else:
            raise ValueError(f"{where}: reference_plan step {step} {a!r} is neither [pick, release] nor an action id "
                             f"0..{N_ACTIONS - 1}")
    return tuple(out)


def parse_goal(d, where: str = "goal") -> Goal:
    """A Goal from a goal file's JSON, checked (check_goal); every refusal is one line naming `where`."""
    if not isinstance(d, dict):
        raise ValueError(f"{where}: expected a JSON object, got {type(d).__name__}")
    version = d.get("version")
    if d.get("format") != GOAL_FORMAT or type(version) is not int or version != GOAL_VERSION:  # true == 1 in Python
        raise ValueError(f"{where}: not a symlearn goal file (expected format {GOAL_FORMAT!r}, version {GOAL_VERSION})")
    extra = sorted(set(d) - _TOP_KEYS)
    if extra:
        raise ValueError(f"{where}: unknown keys {', '.join(extra)}")
    objs, task, seed = d.get("objects"), d.get("task", GOAL_TASK), d.get("seed", 0)
    if not isinstance(objs, list) or not 1 <= len(objs) <= MAX_OBJECTS:
        raise ValueError(f"{where}: objects must be a list of 1..{MAX_OBJECTS} objects")
    if not isinstance(task, str) or not task or len(task) > MAX_TEXT:
        raise ValueError(f"{where}: task must be a non-empty string of at most {MAX_TEXT} characters, "
                         f"got {task[:40] + '...' if isinstance(task, str) and len(task) > 40 else task!r}")
    if not isinstance(d.get("description", ""), str) or len(d.get("description", "")) > MAX_TEXT:
        raise ValueError(f"{where}: description must be a string of at most {MAX_TEXT} characters")
    if not (_is_int(seed) and seed >= 0):
        raise ValueError(f"{where}: seed must be a non-negative integer, got {seed!r}")
    spec, targets = [], []
    for i, o in enumerate(objs):
        if not isinstance(o, dict) or set(o) != _OBJECT_KEYS:
            raise ValueError(f"{where}: object {i} must have exactly the keys type, initial, goal")
        if o["type"] not in ("cube", "stick"):
            raise ValueError(f"{where}: object {i} type {o['type']!r} is not cube or stick")
        spec.append((ObjectType[o["type"].upper()], _location(o["initial"], f"object {i} initial location", where)))
        targets.append(_target(o["goal"], i, where))
    goal = Goal(tuple(spec), tuple(targets), _plan(d.get("reference_plan"), where), task, seed)
    check_goal(goal, where)
    return goal


def load_goal(path: Path) -> Goal:
    """Read and check a goal file; refuses it with a one-line ValueError naming the file."""
    path = Path(path)
    where = f"goal file {path}"
    if not path.exists():
        raise ValueError(f"{where}: no such file")
    return parse_goal(read_json_file(path, what="goal file", max_bytes=GOAL_FILE_BYTES), where)


def save_goal(path: Path, goal: Goal) -> None:
    """Write a goal file atomically."""
    atomic_write_json(Path(path), goal.to_json())


def stick_covers(stick_loc: int, loc: int) -> bool:
    """Whether a stick lying at stick_loc has an end over loc (far-row neighbours only: 0.18 m apart)."""
    return stick_loc in FAR_ROW and loc in FAR_ROW and abs(stick_loc - loc) == 1


def check_goal(goal: Goal, where: str) -> None:
    """Refuse arrangements the simulator cannot build: bad supports, cycles, clashes on the table, overlaps."""
    types, targets = [t for t, _ in goal.spec], goal.targets
    if types.count(ObjectType.STICK) > 1:
        raise ValueError(f"{where}: more than one stick (objects {[i for i, t in enumerate(types) if t == ObjectType.STICK]})")
    if all(t is None for t in targets):
        raise ValueError(f"{where}: the goal leaves every object free")
    seats: dict[tuple, int] = {}
    for i, g in enumerate(targets):
        if g is None:
            continue
        if g.on is not None:
            j = g.on
            if not 0 <= j < len(targets) or j == i:
                raise ValueError(f"{where}: object {i} stands on object {j}, which is absent")
            if targets[j] is None:
                raise ValueError(f"{where}: object {i} stands on object {j}, which the goal leaves free")
            below = targets[j].location
            if g.end and (types[j] != ObjectType.STICK or not stick_covers(below, g.location)):
                raise ValueError(f"{where}: object {i} at location {g.location} is not on an end of "
                                 f"{types[j].name.lower()} {j} at location {below} (a stick's ends lie over the "
                                 f"far-row neighbours of a far-row stick)")
            if not g.end and below != g.location:
                raise ValueError(f"{where}: object {i} at location {g.location} stands on a {types[j].name.lower()} "
                                 f"(object {j}) at location {below}" + (" (use {\"stick_end\": j} for a stick's ends)"
                                                                        if types[j] == ObjectType.STICK else ""))
        seat = ("table", g.location) if g.on is None else (g.on, g.location)
        if seat in seats:
            what = f"on the table at location {g.location}" if g.on is None else f"on object {g.on} at {g.location}"
            raise ValueError(f"{where}: objects {seats[seat]} and {i} both stand {what}")
        seats[seat] = i
    _check_cycles(targets, where)
    sticks = [i for i, g in enumerate(targets) if g is not None and types[i] == ObjectType.STICK]
    for s in sticks:
        for i, g in enumerate(targets):
            if g is not None and g.on is None and i != s and stick_covers(targets[s].location, g.location):
                raise ValueError(f"{where}: object {i} on the table at location {g.location} lies under an end of "
                                 f"the stick (object {s}) at location {targets[s].location}")
    # the seats above keep objects apart; this states the physical rule itself, as problem files are checked
    check_no_overlap([(i, types[i], p) for i, p in expected_positions(goal).items()], where)


def _check_cycles(targets, where: str) -> None:
    for i in range(len(targets)):
        seen, j = [i], targets[i].on if targets[i] is not None else None
        while j is not None:
            if j in seen:
                raise ValueError(f"{where}: support cycle {' -> '.join(map(str, seen + [j]))}")
            seen.append(j)
            j = targets[j].on


def drop_order(goal: Goal) -> tuple[int, ...]:
    """The fixed objects, supports before what stands on them (ties in index order)."""
    depth = {}
    for i, g in enumerate(goal.targets):
        if g is not None:
            d, j = 0, g.on
            while j is not None:
                d, j = d + 1, goal.targets[j].on
            depth[i] = d
    return tuple(sorted(depth, key=lambda i: (depth[i], i)))


def expected_positions(goal: Goal) -> dict[int, tuple[float, float, float]]:
    """Centre of every fixed object as the arrangement puts it: over its location, resting on its support."""
    types = [t for t, _ in goal.spec]
    out: dict[int, tuple[float, float, float]] = {}
    for i in drop_order(goal):
        g = goal.targets[i]
        base = TABLE_TOP_Z if g.on is None else out[g.on][2] + OBJECT_SIZE[types[g.on]][2] / 2
        x, y = LOCATIONS[g.location]
        out[i] = (x, y, base + OBJECT_SIZE[types[i]][2] / 2)
    return out


def arrangement_errors(scene: Scene, goal: Goal) -> list[str]:
    """Why a settled scene is not the goal's arrangement: fixed objects off their place by more than 2 cm or tilted."""
    errors = []
    for i, pos in expected_positions(goal).items():
        o = scene.objects[i]
        off = float(np.linalg.norm(np.asarray(o.position) - pos))
        if off > ARRANGEMENT_TOLERANCE_M:
            errors.append(f"object {i} ended {off * 100:.1f} cm from where the arrangement puts it")
            continue
        x, y, z, w = o.orientation
        up_z = 1.0 - 2.0 * (x * x + y * y)  # z component of the body's z axis
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, up_z))))
        if tilt > MAX_TILT_DEG:
            errors.append(f"object {i} is tilted by {tilt:.0f} degrees")
    return errors
