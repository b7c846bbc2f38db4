"""Generating planning problems in the simulator.

A problem is generated in the simulator: a random scene of k objects is built by dropping
them (exploration.sample_scene_spec), a random sequence of L actions that each move something
is executed, and the scene it ends in is the goal. The generator's actions are kept as a known
valid plan (its length is a reference for plan lengths).

    >>> paths = generate_problems(Path("problems/p13"), n=20, objects=(1, 3), length=(1, 4), seed=0)  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from symlearn.planning.problem import GOAL_TOLERANCE_M, Problem, save_problem
from symlearn.sim.exploration import MAX_OBJECTS, ExplorationConfig, sample_action, sample_scene_spec
from symlearn.world import Action, Scene, decode_action

MOVE_EPS_M = 0.01  # an action "changes something" when some object moves farther than this
MAX_ACTION_DRAWS = 10_000  # draws of a random action before _changing_action gives up


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
