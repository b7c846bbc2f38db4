"""Planning problems as JSON files: an initial scene, a goal scene, and the actions that made it.

A problem is generated in the simulator: a random scene of k objects is built by dropping
them (exploration.sample_scene_spec), a random sequence of L actions that each move something
is executed, and the scene it ends in is the goal. The generator's actions are kept as a known
valid plan (its length is a reference for plan lengths). Goal symbols are the effect model's
codes of the goal scene, rendered by placing the objects at the goal poses.

    >>> paths = generate_problems(Path("problems/p13"), n=20, objects=(1, 3), length=(1, 4), seed=0)  # doctest: +SKIP
    >>> problem = load_problem(paths[0])                                                               # doctest: +SKIP
    >>> problem.generator_length, problem.initial.k                                                    # doctest: +SKIP
    (3, 2)
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from symlearn.sim.exploration import MAX_OBJECTS, ExplorationConfig, sample_action, sample_scene_spec
from symlearn.provenance import atomic_write_json
from symlearn.world import N_ACTIONS, N_LOCATIONS, Action, ObjectType, Scene, decode_action

PROBLEM_FORMAT = "symlearn-problem"
PROBLEM_VERSION = 1
MOVE_EPS_M = 0.01  # an action "changes something" when some object moves farther than this
GOAL_TOLERANCE_M = 0.02  # success: every object within this distance of its goal position
_KEYS = ("format", "version", "name", "seed", "spec", "initial", "actions", "goal", "generator_length")


@dataclass(frozen=True)
class Problem:
    """A named planning problem: build `spec`, place `initial`, reach `goal` (object order is identity)."""

    name: str
    seed: int  # the generator's base seed: problem i of a set is drawn from default_rng([seed, i])
    spec: tuple[tuple[ObjectType, int], ...]  # objects dropped in order at (type, near-row location)
    initial: Scene  # poses after building and settling
    actions: tuple[int, ...]  # the generator's action ids: a known valid plan
    goal: Scene  # poses the generator's actions ended in

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError("problem name must be a non-empty string")
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
        types = tuple(t for t, _ in spec)
        for what, scene in (("initial", self.initial), ("goal", self.goal)):
            if not isinstance(scene, Scene):
                raise ValueError(f"{p}: {what} must be a Scene")
            if tuple(o.type for o in scene.objects) != types:
                raise ValueError(f"{p}: {what} scene objects {[o.type.name.lower() for o in scene.objects]} "
                                 f"do not match the spec {[t.name.lower() for t in types]}")
            if not np.all(np.isfinite(scene.positions())):
                raise ValueError(f"{p}: {what} scene has non-finite positions")

    @property
    def k(self) -> int:
        return len(self.spec)

    @property
    def generator_length(self) -> int:
        """Length of the generator's own plan."""
        return len(self.actions)

    def to_json(self) -> dict:
        return {"format": PROBLEM_FORMAT, "version": PROBLEM_VERSION, "name": self.name, "seed": self.seed,
                "spec": [[t.name.lower(), loc] for t, loc in self.spec], "initial": self.initial.to_json(),
                "actions": list(self.actions),
                "actions_readable": [f"pick {decode_action(a).pick} -> release {decode_action(a).release}"
                                     for a in self.actions],
                "goal": self.goal.to_json(), "generator_length": self.generator_length}

    @staticmethod
    def from_json(d: dict, where: str = "problem") -> "Problem":
        """Parse and validate; every refusal is a one-line ValueError that names the problem."""
        if not isinstance(d, dict):
            raise ValueError(f"{where}: expected a JSON object, got {type(d).__name__}")
        name = d.get("name") if isinstance(d.get("name"), str) else where
        p = f"problem {name}" if name != where else where
        missing = [k for k in _KEYS if k not in d]
        if missing:
            raise ValueError(f"{p}: missing keys {', '.join(missing)}")
        if d["format"] != PROBLEM_FORMAT:
            raise ValueError(f"{p}: not a symlearn problem (format {d['format']!r})")
        if d["version"] != PROBLEM_VERSION:
            raise ValueError(f"{p}: problem version {d['version']!r}, this symlearn reads version {PROBLEM_VERSION}")
        if not isinstance(d["name"], str) or not d["name"]:
            raise ValueError(f"{p}: name must be a non-empty string")
        if not _is_int(d["seed"]):
            raise ValueError(f"{p}: seed must be an integer, got {d['seed']!r}")
        spec = d["spec"]
        if not isinstance(spec, list) or not all(isinstance(e, list) and len(e) == 2 for e in spec):
            raise ValueError(f"{p}: spec must be a list of [type, location] pairs")
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
        if d["generator_length"] != len(actions):
            raise ValueError(f"{p}: generator_length {d['generator_length']!r} does not match "
                             f"{len(actions)} actions")
        scenes = {}
        for key in ("initial", "goal"):
            scenes[key] = _scene(d[key], f"{p}: {key} scene")
        try:
            return Problem(d["name"], int(d["seed"]), tuple(parsed), scenes["initial"], tuple(actions), scenes["goal"])
        except ValueError as e:
            msg = str(e)
            raise ValueError(msg if msg.startswith(p) else f"{p}: {msg}") from None


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _scene(d, where: str) -> Scene:
    """A scene from JSON with type and shape checks on every object."""
    if not isinstance(d, dict) or not isinstance(d.get("objects"), list):
        raise ValueError(f"{where} must be an object with an 'objects' list")
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
    try:
        d = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise ValueError(f"problem {path.name}: not valid JSON ({e})") from None
    return Problem.from_json(d, where=f"problem {path.name}")


def load_problems(problems_dir: Path) -> list[tuple[Path, Problem]]:
    """All *.json problems of a directory, in name order."""
    problems_dir = Path(problems_dir)
    if not problems_dir.is_dir():
        raise ValueError(f"no problem directory at {problems_dir}; run 'symlearn problems' first")
    paths = sorted(problems_dir.glob("*.json"))
    if not paths:
        raise ValueError(f"{problems_dir} holds no problem files (*.json)")
    return [(p, load_problem(p)) for p in paths]


# ------------------------------------------------------------------------------- generation


@dataclass(frozen=True)
class ProblemConfig:
    """How problems are drawn: object count and generator-plan length ranges, retry bounds."""

    objects: tuple[int, int] = (1, 3)  # inclusive range of objects per scene
    length: tuple[int, int] = (1, 4)  # inclusive range of generator actions
    max_step_tries: int = 20  # draws per step before giving up on the scene
    max_scene_tries: int = 20  # fresh scenes per problem before giving up
    min_goal_distance_m: float = GOAL_TOLERANCE_M  # some object must end farther than this from its start

    def __post_init__(self) -> None:
        lo, hi = self.objects
        if not 1 <= lo <= hi <= MAX_OBJECTS:
            raise ValueError(f"object range {lo}-{hi} must lie within 1-{MAX_OBJECTS}")
        lo, hi = self.length
        if not 1 <= lo <= hi:
            raise ValueError(f"length range {lo}-{hi} must be non-empty and start at 1 or more")
        if self.max_step_tries < 1 or self.max_scene_tries < 1:
            raise ValueError("max_step_tries and max_scene_tries must be positive")


def _changing_action(rng: np.random.Generator, occupied: np.ndarray, cfg: ExplorationConfig) -> Action:
    """A random action with the exploration's rule, made likely to move something: pick occupied, release elsewhere."""
    while True:
        a = sample_action(rng, occupied, cfg)
        if occupied[a.pick] and a.release != a.pick:
            return a


def _replay(sim, initial: Scene, actions: list[int]) -> None:
    sim.reset(initial)
    for a in actions:
        sim.step(decode_action(a))


def generate_problem(sim, rng: np.random.Generator, cfg: ProblemConfig, name: str, seed: int) -> Problem:
    """One problem: build a random scene, execute L actions that each move something, keep the end as goal."""
    expl = ExplorationConfig.with_k_range(*cfg.objects)
    expl = ExplorationConfig(k_values=expl.k_values, k_probs=expl.k_probs, pick_occupied_prob=1.0)
    for _ in range(cfg.max_scene_tries):
        spec = sample_scene_spec(rng, expl)
        length = int(rng.integers(cfg.length[0], cfg.length[1] + 1))
        sim.build(spec)
        initial = sim.get_scene()
        sim.reset(initial)  # execution starts from a reset to these poses, so generation does too
        actions: list[int] = []
        while len(actions) < length:
            for _ in range(cfg.max_step_tries):
                res = sim.step(_changing_action(rng, sim.occupied(), expl))
                moved = float(np.linalg.norm(res.effect, axis=1).max()) > MOVE_EPS_M
                last = len(actions) == length - 1
                far = float(np.linalg.norm(res.after.positions() - initial.positions(), axis=1).max())
                if moved and not res.off_table and (not last or far > cfg.min_goal_distance_m):
                    actions.append(res.action.id)
                    break
                _replay(sim, initial, actions)  # undo exactly: the recorded actions from the initial poses
            else:
                break
        if len(actions) == length:
            return Problem(name, seed, tuple(spec), initial, tuple(actions), sim.get_scene())
    raise RuntimeError(f"problem {name}: no valid action sequence after {cfg.max_scene_tries} scenes")


def generate_problems(out_dir: Path, n: int, objects: tuple[int, int] = (1, 3), length: tuple[int, int] = (1, 4),
                      seed: int = 0, sim=None) -> list[Path]:
    """Write n problems to out_dir/problem_NNNN.json (problem i drawn from seed (seed, i))."""
    from symlearn.sim.simulator import TabletopSimulator

    if n < 1:
        raise ValueError(f"n={n} must be at least 1")
    cfg = ProblemConfig(objects=tuple(objects), length=tuple(length))
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    own = sim is None
    sim = sim or TabletopSimulator()
    paths = []
    try:
        for i in range(n):
            name = f"problem_{i:04d}"
            problem = generate_problem(sim, np.random.default_rng([seed, i]), cfg, name, seed)
            path = out_dir / f"{name}.json"
            save_problem(path, problem)
            paths.append(path)
    finally:
        if own:
            sim.close()
    return paths


# ------------------------------------------------------------------------------- scenes and symbols


def place_scene(sim, scene: Scene) -> None:
    """Put the scene's objects at their poses (the arm at home) and let them settle."""
    sim.reset(scene)


def scene_codes(sim, encoder, scene: Scene) -> np.ndarray:
    """(k,) int64 codes of a scene: place it, render, encode with the effect model."""
    from symlearn.symbolic.transition_data import encode_observation

    place_scene(sim, scene)
    return encode_observation(encoder, sim.observe())


def goal_codes(sim, encoder, problem: Problem) -> np.ndarray:
    """The goal symbols of a problem: the encoder's codes of the goal scene's crops."""
    return scene_codes(sim, encoder, problem.goal)


def max_goal_distance(scene: Scene, goal: Scene) -> float:
    """Largest distance (m) between an object's position and its goal position."""
    if scene.k != goal.k:
        raise ValueError(f"scene has {scene.k} objects, goal {goal.k}")
    return float(np.linalg.norm(scene.positions() - goal.positions(), axis=1).max()) if scene.k else 0.0
