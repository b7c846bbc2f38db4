"""Goal files and the structure suite: every template's reference plan reaches its goal in the simulator,
goal files round-trip, arrangements the simulator cannot build are refused in one line naming the file,
and `symlearn problems --kind structures` writes problems that load and resume."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import cli
from symlearn.problems.goal_problems import goal_file_problem, goal_problem
from symlearn.problems.goals import Goal, ObjectGoal, arrangement_errors, drop_order, load_goal, parse_goal, save_goal
from symlearn.problems.problem import load_problem, load_problems, max_goal_distance
from symlearn.problems.stacking import run_script
from symlearn.problems.structure_suite import fitting_templates
from symlearn.problems.structures import TEMPLATES, structure_goal
from symlearn.world import LOCATIONS, ObjectType, decode_action

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "goals" / "fig6_composite.json"
CM = 0.01


def _replay(sim, problem):
    """The scene the problem's reference plan ends in, run from its initial poses."""
    sim.reset(problem.initial)
    for a in problem.actions:
        sim.step(decode_action(a))
    return sim.get_scene()


def _stacks(scene, idx):
    """Groups of the given objects standing over one point (within 1 cm in x and y), each sorted bottom up."""
    groups = []
    for i in sorted(idx, key=lambda i: scene.objects[i].position[2]):
        p = scene.objects[i].position
        for g in groups:
            q = scene.objects[g[0]].position
            if abs(p[0] - q[0]) < CM and abs(p[1] - q[1]) < CM:
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


@pytest.mark.parametrize("template", TEMPLATES, ids=lambda t: t.name)
@pytest.mark.parametrize("seed", [0, 1])
def test_reference_plan_reaches_goal(sim, template, seed):
    lo, hi = template.objects
    k = lo + (seed * 7 + 3) % (hi - lo + 1)  # spread the object counts over the seeds
    rng = np.random.default_rng([seed, k])
    goal = structure_goal(template.name, rng, k, seed)
    problem = goal_problem(sim, goal, f"{template.name}-{seed}", template.name)
    assert problem.task == template.name and problem.k == k and 1 <= problem.generator_length <= 8
    assert problem.free == goal.free and set(problem.fixed) | set(problem.free) == set(range(k))
    end = _replay(sim, problem)  # the recorded plan again, from the stored initial poses
    assert max_goal_distance(end, problem.goal, problem.free) < 2 * CM
    assert arrangement_errors(end, goal) == []
    moved = np.linalg.norm(problem.goal.positions() - problem.initial.positions(), axis=1)
    assert moved[list(problem.fixed)].max() > 5 * CM  # the goal is not the start


def _draw(task: str, k: int, seed: int = 3):
    goal = structure_goal(task, np.random.default_rng([seed, k]), k, seed)
    return goal, run_script(goal.spec, [(decode_action(a).pick, decode_action(a).release) for a in goal.plan])


def test_towers_stack_their_cubes(sim):
    for task, height in (("tower-2", 2), ("tower-3", 3)):
        goal = structure_goal(task, np.random.default_rng([5, height]), height, 0)
        scene = goal_problem(sim, goal, task, task).goal
        stacks = _stacks(scene, range(height))
        assert len(stacks) == 1 and len(stacks[0]) == height
        z = [scene.objects[i].position[2] for i in stacks[0]]
        np.testing.assert_allclose(np.diff(z), 0.10, atol=0.5 * CM)  # cube on cube, 10 cm apart


def test_two_riders_stand_on_the_stick_ends(sim):
    goal = Goal(((ObjectType.STICK, 4), (ObjectType.CUBE, 3), (ObjectType.CUBE, 5)),
                (ObjectGoal(1), ObjectGoal(0, 0, True), ObjectGoal(2, 0, True)), (25, 18, 32), "stick-two-riders")
    scene = goal_problem(sim, goal, "riders", "riders").goal
    stick = np.array(scene.objects[0].position)
    for i, loc in ((1, 0), (2, 2)):
        p = np.array(scene.objects[i].position)
        np.testing.assert_allclose(p[:2], LOCATIONS[loc], atol=1.5 * CM)
        assert abs(p[2] - (stick[2] + 0.025 + 0.05)) < 0.5 * CM  # resting on the stick's top
        assert abs(abs(p[1] - stick[1]) - 0.18) < 1.5 * CM


def test_carried_stick_takes_its_rider_along(sim):
    goal = Goal(((ObjectType.STICK, 1), (ObjectType.CUBE, 0)), (ObjectGoal(2), ObjectGoal(1, 0, True)), (8,),
                "carry-loaded-stick")
    p = goal_problem(sim, goal, "carry", "carry")
    shift = p.goal.positions() - p.initial.positions()
    np.testing.assert_allclose(shift[:, :2], [[0, 0.18], [0, 0.18]], atol=1.5 * CM)


def test_swap_and_rotate_permute_places(sim):
    for task, k in (("swap", 2), ("rotate", 3)):
        goal = structure_goal(task, np.random.default_rng([2, k]), k, 0)
        p = goal_problem(sim, goal, task, task)
        start, end = p.initial.positions()[:, :2], p.goal.positions()[:, :2]
        d = np.linalg.norm(start[:, None] - end[None], axis=2)  # d[i, j]: start of i to end of j
        assert np.all(d.min(axis=1) < 1.5 * CM)  # every start place is filled again
        assert np.all(np.diag(d) > 10 * CM)  # by another cube


def test_near_to_far_empties_the_near_row(sim):
    goal = structure_goal("near-to-far", np.random.default_rng([0, 5]), 5, 0)
    p = goal_problem(sim, goal, "n2f", "n2f")
    assert p.generator_length == 5
    np.testing.assert_allclose(p.initial.positions()[:, 0], 0.50, atol=CM)
    np.testing.assert_allclose(p.goal.positions()[:, 0], 0.80, atol=CM)


def test_templates_cover_one_to_five_objects_and_lengths():
    assert [t.name for t in fitting_templates((1, 1))] == ["near-to-far"]
    assert len(fitting_templates((1, 5))) == len(TEMPLATES)
    lengths = {len(_draw(t.name, k, s)[0].plan) for t in TEMPLATES for k in range(t.objects[0], t.objects[1] + 1)
               for s in range(4)}
    assert lengths == {1, 2, 3, 4, 5, 6, 7}


def test_fig6_example_builds_its_arrangement(sim):
    goal = load_goal(EXAMPLE)
    assert drop_order(goal) == (0, 1, 2, 3)
    p = goal_file_problem(EXAMPLE, sim)
    assert (p.name, p.task, p.generator_length, p.free) == ("fig6_composite", "fig6-composite", 3, ())
    stick, rider = p.goal.objects[0].position, p.goal.objects[2].position
    assert abs(stick[0] - 0.80) < CM and abs(rider[1] - stick[1] + 0.18) < 1.5 * CM
    stacks = _stacks(p.goal, [1, 3])
    assert stacks == [[1, 3]]  # the tower of two in the near row


def test_goal_file_round_trip(tmp_path):
    goal = load_goal(EXAMPLE)
    again = parse_goal(json.loads(json.dumps(goal.to_json())))
    assert again == goal
    path = tmp_path / "copy.json"
    save_goal(path, goal)
    assert load_goal(path) == goal
    ids = parse_goal({**goal.to_json(), "reference_plan": list(goal.plan)})  # action ids instead of pairs
    assert ids.plan == goal.plan == (25, 18, 33)


def _goal_file(tmp_path, objects, plan=None, name="g") -> Path:
    d = {"format": "symlearn-goal", "version": 1, "objects": objects}
    if plan is not None:
        d["reference_plan"] = plan
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(d))
    return path


def _o(t, initial, goal):
    return {"type": t, "initial": initial, "goal": goal}


def _at(loc, on="table"):
    return {"location": loc, "on": on}


REFUSED = {
    "cycle": ([_o("cube", 3, _at(3, 1)), _o("cube", 4, _at(3, 0))], None, "support cycle 0 -> 1 -> 0"),
    "free support": ([_o("cube", 3, None), _o("cube", 4, _at(3, 0))], None, "which the goal leaves free"),
    "absent support": ([_o("cube", 3, _at(3, 4))], None, "object 0 stands on object 4, which is absent"),
    "two on the table": ([_o("cube", 3, _at(0)), _o("cube", 4, _at(0))], None, "both stand on the table at location 0"),
    "cube on far cube": ([_o("cube", 3, _at(3)), _o("cube", 4, _at(4, 0))], None, "stands on a cube (object 0) at location 3"),
    "not an end": ([_o("stick", 4, _at(1)), _o("cube", 3, _at(3, {"stick_end": 0}))], None, "is not on an end"),
    "near stick": ([_o("stick", 4, _at(4)), _o("cube", 3, _at(3, {"stick_end": 0}))], None, "is not on an end"),
    "under an end": ([_o("stick", 4, _at(1)), _o("cube", 3, _at(2))], None, "lies under an end of the stick"),
    "two sticks": ([_o("stick", 4, _at(1)), _o("stick", 3, _at(4))], None, "more than one stick"),
    "all free": ([_o("cube", 3, None)], None, "leaves every object free"),
    "does not settle": ([_o("cube", 2, _at(2)), _o("stick", 4, _at(2, 0)), _o("cube", 3, _at(1, {"stick_end": 1}))],
                        None, "does not settle as stated"),
    "plan misses": ([_o("cube", 3, _at(3)), _o("cube", 4, _at(3, 0))], [[4, 5]], "does not reach the goal"),
    "plan id": ([_o("cube", 3, _at(3)), _o("cube", 4, _at(3, 0))], [36], "neither [pick, release] nor an action id"),
    "bad type": ([_o("ball", 3, _at(3))], None, "type 'ball' is not cube or stick"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_unbuildable_goal_refused_in_one_line(sim, tmp_path, case):
    objects, plan, reason = REFUSED[case]
    path = _goal_file(tmp_path, objects, plan)
    with pytest.raises(ValueError) as e:
        goal_file_problem(path, sim)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"goal file {path}: ") and reason in msg, msg


def test_goal_file_without_plan_uses_the_built_arrangement(sim, tmp_path):
    path = _goal_file(tmp_path, [_o("cube", 3, _at(5)), _o("cube", 4, _at(5, 0)), _o("cube", 0, None)], name="pair")
    p = goal_file_problem(path, sim)
    assert p.actions == () and p.free == (2,) and p.fixed == (0, 1)
    np.testing.assert_allclose(p.goal.positions()[:2], [[0.5, 0.3, 0.45], [0.5, 0.3, 0.55]], atol=CM)


def test_cli_suite_writes_loadable_problems_and_resumes(tmp_path):
    out = tmp_path / "s"
    args = ("problems", "--kind", "structures", "--out", out, "--n", 4, "--objects", "4-5", "--seed", 2)
    rc, text = cli(*args)
    assert rc == 0 and f"wrote 4 problems to {out}" in text
    problems = load_problems(out)
    tasks = [p.task for _, p in problems]
    assert tasks == [t.name for t in fitting_templates((4, 5))][:4]
    assert all(4 <= p.k <= 5 and p.generator_length >= 1 for _, p in problems)
    before = {p.name: p.read_bytes() for p in out.glob("*.json")}
    (out / "problem_0002.json").unlink()
    (out / "problem_0003.json").write_text("{")  # a file cut short by a kill
    assert cli(*args)[0] == 0
    assert {p.name: p.read_bytes() for p in out.glob("*.json")} == before  # the same problems, redrawn
    assert cli(*args[:-1], 3)[0] == 2  # other settings are refused
    assert cli(*args[:-1], 3, "--overwrite")[0] == 0 and load_problem(out / "problem_0000.json").seed == 3
    assert cli("problems", "--kind", "structures", "--out", tmp_path / "x", "--length", "1-2")[0] == 2


def test_cli_goal_file(tmp_path):
    rc, text = cli("problems", EXAMPLE, "--out", tmp_path)
    assert rc == 0 and text.strip() == f"wrote {tmp_path / 'fig6_composite.json'}"
    p = load_problem(tmp_path / "fig6_composite.json")
    assert p.task == "fig6-composite" and p.actions == (25, 18, 33)
    assert cli("problems", EXAMPLE, "--out", tmp_path, "--n", 3)[0] == 2
    assert cli("problems", EXAMPLE, "--out", tmp_path, "--kind", "walks")[0] == 2
