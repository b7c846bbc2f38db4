"""The shipped pretrained run: small, safely loadable, and it solves its problem in simulation right away."""
from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pytest

from conftest import cli
from pddl_export.files import sha256_file
from pddl_export.rules_io import load_rules

if TYPE_CHECKING:
    from symlearn.planning.execution import ProblemRun
    from symlearn.problems.problem import Problem
    from symlearn.world import Scene

PRETRAINED = Path(__file__).resolve().parents[1] / "pretrained" / "quick-authors12k"
PROBLEM = PRETRAINED / "problems" / "three_objects_two_actions.json"


@dataclass(frozen=True)
class Executed:
    """What planning and executing one problem in simulation gave: the row, the scene the arm left, its codes."""

    row: ProblemRun  # as `symlearn plan` prints it and `symlearn benchmark` writes it
    problem: Problem
    scene: Scene  # the poses after execution
    codes: tuple[int, ...]  # the encoder's codes of the executed scene
    goal_codes: tuple[int, ...]  # the encoder's codes of the problem's goal scene


def _plan_and_execute(sim, tmp_path: Path, run: Path, problem_path: Path, planner: str, closed_loop: bool = False,
                      recorder=None) -> Executed:
    """What `symlearn plan` does, through the library calls it makes, on a copy of the run (planners write their
    task files under it): plan, execute in the session's simulator, and read back the executed scene and codes."""
    from symlearn.planning.execution import ExecutionConfig, run_problem
    from symlearn.planning.planners import make_planners
    from symlearn.problems.problem import load_problem
    from symlearn.symbolic.scenes import scene_codes
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_data import encode_observation

    copy = tmp_path / "run"
    shutil.copytree(run, copy)
    problem = load_problem(problem_path)
    fn = make_planners([planner], copy, write_dir=copy / "pddl" / "problems" / problem.name)[planner]
    encoder, transition = planning_models(copy)
    row = run_problem(sim, encoder, transition, problem, planner, fn, ExecutionConfig(closed_loop=closed_loop),
                      recorder=recorder)
    scene, codes = sim.get_scene(), tuple(encode_observation(encoder, sim.observe()).tolist())
    return Executed(row, problem, scene, codes, tuple(scene_codes(sim, encoder, problem.goal).tolist()))


def _assert_goal_reached(ex: Executed) -> None:
    """The row says success, and the executed scene shows it: every judged object within the 2 cm tolerance of its
    goal position (the largest distance is the row's), and the executed scene's codes are the goal scene's."""
    from symlearn.problems.problem import GOAL_TOLERANCE_M

    row, problem = ex.row, ex.problem
    assert row.found and row.status == "solved" and row.success and row.symbolic_match, row
    assert row.failure_stage is None and row.failure_cause is None, row
    judged = [i for i in range(problem.k) if i not in problem.free]
    dist = np.linalg.norm(ex.scene.positions()[judged] - problem.goal.positions()[judged], axis=1)
    assert dist.max() < GOAL_TOLERANCE_M, dist
    assert row.max_distance_m == pytest.approx(dist.max(), abs=1e-5)
    assert [ex.codes[i] for i in judged] == [ex.goal_codes[i] for i in judged]
    assert row.executed_length is not None and row.executed_length >= row.plan_length >= 1


def _rests_on(scene: Scene, top: int, bottom: int) -> bool:
    """Whether object `top` stands on object `bottom`: its base within 1.5 cm of bottom's top face, its centre over
    bottom's footprint (objects upright, sticks along y, as the simulator places them)."""
    from symlearn.world import OBJECT_SIZE

    t, b = scene.objects[top], scene.objects[bottom]
    (tx, ty, tz), (bx, by, bz) = t.position, b.position
    bw, bl, bh = OBJECT_SIZE[b.type]
    base = tz - OBJECT_SIZE[t.type][2] / 2
    return abs(base - (bz + bh / 2)) < 0.015 and abs(tx - bx) < bw / 2 and abs(ty - by) < bl / 2


def test_pretrained_run_is_small_and_consistent():
    size = sum(p.stat().st_size for p in PRETRAINED.rglob("*") if p.is_file())
    assert size <= 10.5e6, size
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.symbolic.learned_transition import LearnedTransition
    model, ck = load_effect_model(PRETRAINED)
    assert ck.config.crop == 32 and ck.config.bits == 8  # the quick preset
    LearnedTransition.from_run(PRETRAINED)  # refuses a transition network of another effect model
    rules, model_hash = load_rules(PRETRAINED)
    assert model_hash == sha256_file(PRETRAINED / "transition.pt")[:16]  # the export is not stale
    assert len(rules.rules) > 100 and len(rules.codes) > 20
    ev = json.loads((PRETRAINED / "eval.json").read_text())
    assert ev["effect_model_sha256"] == sha256_file(PRETRAINED / "best.pt")[:16]
    assert all(ev["effect_mae_mm"][a] < lim for a, lim in zip("xyz", (8.6, 15, 6)))  # the paper's errors


@pytest.mark.parametrize("planner", ["astar", "rules-bfs"])
def test_pretrained_run_solves_its_problem_in_simulation(sim, tmp_path, planner):
    """Open loop, a shortest (2-action) plan brings every object to its goal position and codes; 3 frames recorded."""
    from PIL import Image

    from symlearn.planning.recording import PlanRecorder

    recorder = PlanRecorder()
    ex = _plan_and_execute(sim, tmp_path, PRETRAINED, PROBLEM, planner, recorder=recorder)
    assert ex.problem.name == ex.row.problem == "problem_0008" and ex.row.generator_length == 2
    _assert_goal_reached(ex)
    assert ex.row.plan_length == ex.row.executed_length == 2 and ex.row.replans == 0 and not ex.row.closed_loop
    assert len(recorder.frames) == 3  # the start and one frame per action
    with Image.open(recorder.save_gif(tmp_path / "p.gif")) as gif:
        assert gif.n_frames == 3


# Both structures take two picks at least, and two suffice: each of the tower's cubes leaves its location (a pick
# moves one cube), and the stick must be carried and the cube put onto it (the generator took 3 for the latter).
STRUCTURE_MOVES = 2


def _assert_structure(ex: Executed, name: str) -> None:
    """The executed scene holds the structure the problem is named after, checked on the poses themselves."""
    scene, start = ex.scene, ex.problem.initial
    if name == "tower_of_two":  # cube 1 stands on cube 0
        assert _rests_on(scene, 1, 0) and not _rests_on(start, 1, 0), scene
    else:  # the cube stands on the stick, which was carried more than 20 cm from where it lay
        assert name == "cube_on_carried_stick" and _rests_on(scene, 1, 0) and not _rests_on(start, 1, 0), scene
        assert np.linalg.norm(scene.positions()[0] - start.positions()[0]) > 0.2, scene


@pytest.mark.parametrize("name", ["tower_of_two", "cube_on_carried_stick"])
def test_pretrained_run_builds_structures_in_simulation(sim, tmp_path, name):
    """Structure goals (a tower of two cubes; a cube standing on a stick carried to another location), built by a
    plan that breadth-first search finds on the shipped rules and the simulated arm executes."""
    ex = _plan_and_execute(sim, tmp_path, PRETRAINED, PRETRAINED / "problems" / f"{name}.json",
                           "rules-bfs", closed_loop=True)
    _assert_goal_reached(ex)
    assert ex.row.plan_length == STRUCTURE_MOVES and ex.row.closed_loop  # shortest plans: the fewest moves
    _assert_structure(ex, name)


def test_plan_sets_torch_threads_one_by_default(tmp_path):
    """Search-time inference runs on one thread unless --threads asks for more (small batches on 2 busy cores crawl)."""
    import torch
    run = tmp_path / "run"
    shutil.copytree(PRETRAINED, run)
    before = torch.get_num_threads()
    try:
        assert cli("plan", "--run", run, "--problem", PROBLEM, "--threads", "2")[0] == 0
        assert torch.get_num_threads() == 2
        assert cli("plan", "--run", run, "--problem", PROBLEM)[0] == 0
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(before)
