"""Generating planning problems in the simulator.

A problem is generated in the simulator: a random scene of k objects is built by dropping
them (exploration.sample_scene_spec), a random sequence of L actions that each move something
is executed, and the scene it ends in is the goal. The generator's actions are kept as a known
valid plan (its length is a reference for plan lengths); the shortest plan is searched for in the
symbolic model and recorded too (symlearn.problems.shortest).

    >>> paths = generate_problems(Path("problems/p13"), n=20, objects=(1, 3), length=(1, 4), seed=0)  # doctest: +SKIP
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from symlearn.folder_lock import LOCK_NAME, folder_lock
from symlearn.problems.paths import path_under
from symlearn.problems.problem import (GOAL_TOLERANCE_M, MAX_ACTIONS, PROBLEM_VERSION, PROBLEMS_MANIFEST, OutOfReach,
                                       Problem, load_problem, load_problems, read_manifest, save_problem)
from symlearn.problems.shortest import with_shortest
from symlearn.provenance import atomic_write_json
from symlearn.sim.exploration import MAX_OBJECTS, ExplorationConfig, sample_action, sample_scene_spec
from symlearn.world import Action, Scene, decode_action

HORIZON_BUCKETS = ((1, 2), (3, 4), (5, 6), (7, 8))  # reference-length buckets of the depth benchmark
MOVE_EPS_M = 0.01  # an action "changes something" when some object moves farther than this
MAX_ACTION_DRAWS = 10_000  # draws of a random action before _changing_action gives up
N_PROBLEMS = 20  # random-walk problems drawn unless asked otherwise (`symlearn problems`, the paper pipeline)


@dataclass(frozen=True)
class ProblemConfig:
    """How problems are drawn: object count and generator-plan length ranges, retry bounds."""

    objects: tuple[int, int] = (1, 3)  # inclusive range of objects per scene
    length: tuple[int, int] = (1, 4)  # inclusive range of generator actions
    max_step_tries: int = 20  # draws per step before giving up on the scene
    max_scene_tries: int = 20  # fresh scenes per problem before giving up
    min_goal_distance_m: float = GOAL_TOLERANCE_M  # some object must end farther than this from its start
    on_locations: bool = False  # redraw a walk whose goal leaves an object off the table locations (goal_off_locations)

    def __post_init__(self) -> None:
        lo, hi = self.objects
        if not 1 <= lo <= hi <= MAX_OBJECTS:
            raise ValueError(f"object range {lo}-{hi} must lie within 1-{MAX_OBJECTS}")
        lo, hi = self.length
        if not 1 <= lo <= hi <= MAX_ACTIONS:  # a longer walk would write problems that plan and benchmark refuse
            raise ValueError(f"length range {lo}-{hi} must be non-empty and lie within 1-{MAX_ACTIONS} "
                             f"(the generator actions a problem file may list)")
        if self.max_step_tries < 1 or self.max_scene_tries < 1:
            raise ValueError("max_step_tries and max_scene_tries must be positive")


def _changing_action(rng: np.random.Generator, occupied: np.ndarray, cfg: ExplorationConfig) -> Action:
    """A random action with the exploration's rule, made likely to move something: pick occupied, release elsewhere.

    Draws at most MAX_ACTION_DRAWS actions; a scene where none qualifies (nothing occupied, or a
    config that never picks an occupied location) is refused with a RuntimeError.
    """
    for _ in range(MAX_ACTION_DRAWS):
        a = sample_action(rng, occupied, cfg)
        if occupied[a.pick] and a.release != a.pick:
            return a
    raise RuntimeError(f"no action picking an occupied location (occupied: {np.flatnonzero(occupied).tolist()}) "
                       f"and releasing elsewhere after {MAX_ACTION_DRAWS} draws")


def _replay(sim, initial: Scene, actions: list[int]) -> None:
    sim.reset(initial)
    for a in actions:
        sim.step(decode_action(a))


def _walk(sim, rng: np.random.Generator, cfg: ProblemConfig, expl: ExplorationConfig, initial: Scene,
          length: int) -> list[int] | None:
    """`length` actions from the scene `initial` (built and reset) that each move something, none off the table, the
    last leaving some object farther than cfg.min_goal_distance_m from its start; or None where a step finds none in
    cfg.max_step_tries draws, or nothing stands on a table location to pick (a scene of 9-10 objects can start so)."""
    actions: list[int] = []
    while len(actions) < length:
        for _ in range(cfg.max_step_tries):
            try:
                action = _changing_action(rng, sim.occupied(), expl)
            except RuntimeError:  # no draw picks an occupied location: this scene cannot be walked
                return None
            res = sim.step(action)
            moved = float(np.linalg.norm(res.effect, axis=1).max()) > MOVE_EPS_M
            last = len(actions) == length - 1
            far = float(np.linalg.norm(res.after.positions() - initial.positions(), axis=1).max())
            if moved and not res.off_table and (not last or far > cfg.min_goal_distance_m):
                actions.append(res.action.id)
                break
            _replay(sim, initial, actions)  # undo exactly: the recorded actions from the initial poses
        else:
            return None
    return actions


def generate_problem(sim, rng: np.random.Generator, cfg: ProblemConfig, name: str, seed: int) -> Problem:
    """One problem: build a random scene, execute L actions that each move something, keep the end as goal; a scene
    that cannot be walked so is replaced by another, at most cfg.max_scene_tries times."""
    expl = ExplorationConfig.with_k_range(*cfg.objects)
    expl = ExplorationConfig(k_values=expl.k_values, k_probs=expl.k_probs, pick_occupied_prob=1.0)
    for _ in range(cfg.max_scene_tries):
        spec = sample_scene_spec(rng, expl)
        length = int(rng.integers(cfg.length[0], cfg.length[1] + 1))
        sim.build(spec)
        initial = sim.get_scene()
        sim.reset(initial)  # execution starts from a reset to these poses, so generation does too
        actions = _walk(sim, rng, cfg, expl, initial, length)
        if actions is not None:
            try:
                problem = Problem(name, seed, tuple(spec), initial, tuple(actions), sim.get_scene())
            except OutOfReach:  # with 6-8 objects a walk can push one past the table's reach: another scene
                continue
            if not (cfg.on_locations and problem.goal_off_locations):
                return with_shortest(problem)
    where = " ending on the table locations" if cfg.on_locations else ""
    raise RuntimeError(f"problem {name}: no valid action sequence{where} after {cfg.max_scene_tries} scenes")


MANIFEST_FORMAT = "symlearn-problem-set"


def _settings(n: int, cfg: ProblemConfig, seed: int, stratify: bool = False) -> dict:
    d = {"format": MANIFEST_FORMAT, "problem_version": PROBLEM_VERSION, "n": n, "objects": list(cfg.objects),
         "length": list(cfg.length), "seed": seed}
    if stratify:
        d["stratify"] = True
    if cfg.on_locations:
        d["on_locations"] = True
    return d


def stratified_cells(cfg: ProblemConfig) -> list[tuple[int, tuple[int, int]]]:
    """(objects, length range) cells of a stratified set: every object count x every horizon bucket in range."""
    lo, hi = cfg.length
    buckets = [(max(a, lo), min(b, hi)) for a, b in HORIZON_BUCKETS if a <= hi and b >= lo]
    buckets += [(max(9, lo), hi)] if hi > HORIZON_BUCKETS[-1][1] else []
    return [(k, b) for k in range(cfg.objects[0], cfg.objects[1] + 1) for b in buckets]


def cell_name(k: int, length: tuple[int, int], i: int) -> str:
    """Problem name of a stratified set: objects, length range and index, e.g. k3_len5-6_0007."""
    return f"k{k}_len{length[0]}-{length[1]}_{i:04d}"


def _own_files(out_dir: Path) -> list[Path]:
    """The files a problem set of this module consists of: its problems, its manifest, stale temp files."""
    return [f for f in out_dir.iterdir() if f.is_file() and (
        re.fullmatch(_OWN_PROBLEM, f.name) or f.name == PROBLEMS_MANIFEST
        or re.fullmatch(rf"\.({_OWN_PROBLEM}|problems\.manifest)\..*\.tmp", f.name))]


_OWN_PROBLEM = r"(problem_\d{4,}|k\d_len\d+-\d+_\d{4,}|k\d_opt\d+-\d+_\d{4,}|k\d_off_\d{4,})\.json"


def prepare_problem_dir(out_dir: Path, settings: dict, overwrite: bool = False) -> None:
    """Make out_dir ready for a problem set: new, the same settings (resume), or cleared with overwrite.

    A non-empty folder holding anything but a problem set of the same settings is refused, so two
    generations are never mixed; `overwrite` first removes the old set's files (and only those).
    """
    manifest = out_dir / PROBLEMS_MANIFEST
    if out_dir.exists() and not out_dir.is_dir():
        raise ValueError(f"--out {out_dir} is a file, not a folder")
    if out_dir.is_dir() and any(f.name != LOCK_NAME for f in out_dir.iterdir()):
        old = read_manifest(out_dir)
        if overwrite:
            own = _own_files(out_dir)
            others = sorted(f.name for f in out_dir.iterdir() if f not in own and f.name != LOCK_NAME)
            if others:  # refused before anything is removed: the folder stays as it was
                raise ValueError(f"{out_dir} holds files that are not problems of a set ({', '.join(others[:3])}); "
                                 f"--overwrite removes only a set's own files: move those away, or choose an "
                                 f"empty --out")
            for f in own:
                f.unlink()
        elif not isinstance(old, dict):
            raise ValueError(f"{out_dir} already holds files but no problem manifest ({manifest.name}); "
                             f"use --overwrite to replace its problems, or another --out")
        elif old != settings:
            keys = [k for k in set(settings) | set(old) if old.get(k) != settings.get(k)]
            if keys == ["problem_version"]:
                raise ValueError(f"{out_dir} holds problems of version {old.get('problem_version')}, without shortest "
                                 f"plans: 'symlearn problems --kind annotate --out {out_dir}' adds them, then this command "
                                 f"completes the set; or --overwrite")
            diff = ", ".join(f"{k} {old.get(k)} (asked {v})" for k, v in settings.items() if old.get(k) != v)
            raise ValueError(f"{out_dir} already holds problems of other settings ({diff}); "
                             f"use --overwrite to replace them, or another --out")
    out_dir.mkdir(parents=True, exist_ok=True)
    for f in _own_files(out_dir):  # temp files of a killed run of the same set
        if f.name.endswith(".tmp"):
            f.unlink()
    atomic_write_json(manifest, settings)


def _done(path: Path, name: str) -> bool:
    """Whether a previous run already wrote a valid problem `name` at path."""
    if not path.is_file():
        return False
    try:
        return load_problem(path).name == name
    except ValueError:
        return False


def generate_problems(out_dir: Path, n: int, objects: tuple[int, int] = (1, 3), length: tuple[int, int] = (1, 4),
                      seed: int = 0, sim=None, overwrite: bool = False, stratify: bool = False,
                      on_locations: bool = False) -> list[Path]:
    """Write n problems to out_dir/problem_NNNN.json (problem i drawn from seed (seed, i)).

    With `stratify`, n problems per cell of object count x horizon bucket (HORIZON_BUCKETS cut to the
    length range) instead, named by cell (cell_name) and drawn from seed (seed, k, lo, hi, i).
    With `on_locations`, only goals that leave every object within ON_LOCATION_M of a table location
    are kept (a walk ending elsewhere is redrawn): the goals place-and-level symbols can name.

    Everything is validated before anything is created. A folder already holding the same set
    (same settings, recorded in out_dir/problems.manifest) is completed: problems already written
    are kept, so an interrupted run resumes. Another non-empty folder is refused unless `overwrite`.
    """
    if not _is_count(n):
        raise ValueError(f"n={n!r} must be an integer of at least 1")
    if not _is_count(seed, least=0):
        raise ValueError(f"seed={seed!r} must be a non-negative integer")
    cfg = ProblemConfig(objects=tuple(objects), length=tuple(length), on_locations=bool(on_locations))
    out_dir = Path(out_dir)
    with folder_lock(out_dir):  # one writer: a second `problems` into this folder is refused at once
        return _generate(out_dir, n, cfg, seed, sim, overwrite, stratify)


def _generate(out_dir: Path, n: int, cfg: ProblemConfig, seed: int, sim, overwrite: bool,
              stratify: bool) -> list[Path]:
    """generate_problems' work, inside the folder's lock."""
    from symlearn.sim.simulator import TabletopSimulator

    prepare_problem_dir(out_dir, _settings(n, cfg, seed, stratify), overwrite)
    if stratify:
        jobs = [(cell_name(k, b, i), ProblemConfig(objects=(k, k), length=b, on_locations=cfg.on_locations),
                 [seed, k, b[0], b[1], i])
                for k, b in stratified_cells(cfg) for i in range(n)]
    else:
        jobs = [(f"problem_{i:04d}", cfg, [seed, i]) for i in range(n)]
    own = sim is None
    paths = []
    try:
        for name, job_cfg, rng_seed in jobs:
            path = path_under(out_dir, f"{name}.json")
            if not _done(path, name):
                sim = sim or TabletopSimulator()
                save_problem(path, generate_problem(sim, np.random.default_rng(rng_seed), job_cfg, name, seed))
            paths.append(path)
    finally:
        if own and sim is not None:
            sim.close()
    return paths


def _is_count(x, least: int = 1) -> bool:
    return isinstance(x, (int, np.integer)) and not isinstance(x, bool) and x >= least


def add_shortest_plans(problems_dir: Path) -> dict[str, int]:
    """Record the shortest plan in every problem of a folder that lacks it (files of versions 1-2), in place.

    Each file is rewritten atomically at the current version, so a killed run resumes where it stopped; files
    that already record it are left untouched. A set's manifest is moved to the current problem version, so
    the command that made the set still completes it. Returns counts: annotated, kept, known, undecided.
    """
    problems_dir = Path(problems_dir)
    loaded = load_problems(problems_dir)  # refuses a missing folder or a malformed file before writing anything
    counts = {"annotated": 0, "kept": 0, "known": 0, "undecided": 0}
    for path, problem in loaded:
        if problem.optimal_known:
            counts["kept"] += 1
        else:
            problem = with_shortest(problem)
            save_problem(path, problem)
            counts["annotated"] += 1
        counts["known" if problem.optimal_length is not None else "undecided"] += 1
    settings = read_manifest(problems_dir)
    if isinstance(settings, dict) and settings.get("format") == MANIFEST_FORMAT:
        atomic_write_json(problems_dir / PROBLEMS_MANIFEST, {**settings, "problem_version": PROBLEM_VERSION})
    return counts
