"""Planning problems: generation in the simulator, JSON round trip, replay, refusal of malformed files."""
from __future__ import annotations

import copy
import json
import re

import numpy as np
import pytest

from symlearn.problems.problem import (GOAL_TOLERANCE_M, PROBLEM_VERSION, Problem, load_problem, load_problems,
                                       max_goal_distance, save_problem)
from symlearn.problems.problem_generation import (MAX_ACTION_DRAWS, ProblemConfig, _changing_action, generate_problem,
                                                  generate_problems)
from symlearn.sim.exploration import ExplorationConfig
from symlearn.world import N_LOCATIONS, ObjectType, Scene, decode_action


@pytest.fixture(scope="module")
def problem_dir(tmp_path_factory, sim):
    out = tmp_path_factory.mktemp("problems") / "p13"
    generate_problems(out, 4, objects=(1, 3), length=(1, 4), seed=3, sim=sim)
    return out


def _replay(sim, problem: Problem) -> Scene:
    sim.reset(problem.initial)
    for a in problem.actions:
        sim.step(decode_action(a))
    return sim.get_scene()


def test_generation_writes_valid_problems(problem_dir):
    loaded = load_problems(problem_dir)
    assert [p.name for p, _ in loaded] == ["problem_0000.json", "problem_0001.json", "problem_0002.json",
                                        "problem_0003.json"]
    for _, pr in loaded:
        assert 1 <= pr.k <= 3 and 1 <= pr.generator_length <= 4
        assert pr.initial.k == pr.goal.k == pr.k
        assert max_goal_distance(pr.initial, pr.goal) > GOAL_TOLERANCE_M  # never trivially solved


def test_round_trip(problem_dir, tmp_path):
    for path, pr in load_problems(problem_dir):
        assert Problem.from_json(json.loads(json.dumps(pr.to_json()))) == pr
        save_problem(tmp_path / path.name, pr)
        assert load_problem(tmp_path / path.name) == pr
        assert (tmp_path / path.name).read_text() == path.read_text()


def test_generator_actions_reach_the_goal(problem_dir, sim):
    for _, pr in load_problems(problem_dir):
        assert max_goal_distance(_replay(sim, pr), pr.goal) <= GOAL_TOLERANCE_M, pr.name


def test_generation_is_reproducible(problem_dir, tmp_path, sim):
    generate_problems(tmp_path / "again", 2, objects=(1, 3), length=(1, 4), seed=3, sim=sim)
    for name in ("problem_0000.json", "problem_0001.json"):
        a, b = load_problem(problem_dir / name), load_problem(tmp_path / "again" / name)
        assert a.spec == b.spec and a.actions == b.actions
        np.testing.assert_allclose(a.goal.positions(), b.goal.positions(), atol=1e-4)


def test_ten_object_walks_are_built_and_replayed(tmp_path, sim):
    # the largest scene the simulator builds (MAX_OBJECTS): six locations, so towers up to four high
    paths = generate_problems(tmp_path / "p10", 1, objects=(10, 10), length=(1, 2), seed=904, sim=sim, on_locations=True)
    pr = load_problem(paths[0])
    assert pr.k == 10 and max(pr.initial.positions()[:, 2]) > 0.6  # some cube stands three or more high
    assert max_goal_distance(_replay(sim, pr), pr.goal) <= GOAL_TOLERANCE_M


def test_four_to_five_objects(tmp_path, sim):
    paths = generate_problems(tmp_path / "p45", 2, objects=(4, 5), length=(1, 2), seed=1, sim=sim)
    for p in paths:
        pr = load_problem(p)
        assert pr.k in (4, 5) and sum(t == ObjectType.STICK for t, _ in pr.spec) <= 1
        assert max_goal_distance(_replay(sim, pr), pr.goal) <= GOAL_TOLERANCE_M


def test_stratified_sets_fill_every_cell(tmp_path, sim):
    paths = generate_problems(tmp_path / "grid", 1, objects=(2, 3), length=(2, 5), seed=4, sim=sim, stratify=True)
    cells = {}
    for p in paths:
        pr = load_problem(p)
        k, lo, hi = map(int, re.fullmatch(r"k(\d)_len(\d+)-(\d+)_0000", pr.name).groups())
        assert pr.k == k and lo <= pr.generator_length <= hi and pr.task == "random-walk", pr.name
        assert max_goal_distance(_replay(sim, pr), pr.goal) <= GOAL_TOLERANCE_M, pr.name
        cells[(k, lo, hi)] = p.name
    # buckets 1-2, 3-4, 5-6 cut to the asked length range 2-5, for 2 and 3 objects
    assert sorted(cells) == [(k, lo, hi) for k in (2, 3) for lo, hi in ((2, 2), (3, 4), (5, 5))]
    again = generate_problems(tmp_path / "grid", 1, objects=(2, 3), length=(2, 5), seed=4, sim=sim, stratify=True)
    assert again == paths  # the same command completes (here: keeps) the set
    with pytest.raises(ValueError, match="other settings"):
        generate_problems(tmp_path / "grid", 1, objects=(2, 3), length=(2, 5), seed=4, sim=sim)


def test_on_locations_redraws_a_walk_that_leaves_a_stick_off_the_locations(tmp_path, sim):
    # the depth benchmark's k1_len1-2_0000 (this seed and cell) ends with its stick 18 cm past location 5
    off = load_problem(generate_problems(tmp_path / "all", 1, objects=(1, 1), length=(1, 2), seed=0, sim=sim,
                                         stratify=True)[0])
    assert off.goal_off_locations == 1
    paths = generate_problems(tmp_path / "on", 1, objects=(1, 1), length=(1, 2), seed=0, sim=sim, stratify=True,
                              on_locations=True)
    on = load_problem(paths[0])
    assert on.name == off.name and on.goal_off_locations == 0 and on.actions != off.actions
    assert max_goal_distance(_replay(sim, on), on.goal) <= GOAL_TOLERANCE_M
    manifest = json.loads((tmp_path / "on" / "problems.manifest").read_text())
    assert manifest["on_locations"] is True and "on_locations" not in json.loads(
        (tmp_path / "all" / "problems.manifest").read_text())
    with pytest.raises(ValueError, match="other settings"):  # the flag is part of the set's settings
        generate_problems(tmp_path / "on", 1, objects=(1, 1), length=(1, 2), seed=0, sim=sim, stratify=True)


@pytest.mark.parametrize("objects, length", [((0, 2), (1, 2)), ((3, 11), (1, 2)), ((2, 1), (1, 2)),
                                             ((1, 3), (0, 2)), ((1, 3), (3, 2))])
def test_problem_config_refuses_bad_ranges(objects, length):
    with pytest.raises(ValueError, match="range"):
        ProblemConfig(objects=objects, length=length)


def test_a_walk_that_leaves_nothing_on_a_table_location_is_drawn_again_in_another_scene(sim):
    # seed 994, problem 9 (9-10 objects): a step of the first scene's walk, undone, leaves all nine objects between
    # the table locations, so no action picks anything there; that scene is given up for another, where the set's
    # generation used to stop with "no action picking an occupied location"
    cfg = ProblemConfig(objects=(9, 10), length=(1, 4), on_locations=True)
    pr = generate_problem(sim, np.random.default_rng([994, 9]), cfg, "problem_0009", 994)
    assert pr.k == 9 and 1 <= len(pr.actions) <= 4
    assert max_goal_distance(_replay(sim, pr), pr.goal) <= GOAL_TOLERANCE_M


def test_a_set_with_fewer_problems_than_its_manifest_lists_is_refused_until_completed(tmp_path, sim):
    out = tmp_path / "p"
    generate_problems(out, 3, objects=(1, 2), length=(1, 2), seed=5, sim=sim)
    (out / "problem_0002.json").unlink()  # as a generation that stopped after two problems leaves it
    with pytest.raises(ValueError, match=r"holds 2 of the 3 problems its problems.manifest lists.*same command again"):
        load_problems(out)
    generate_problems(out, 3, objects=(1, 2), length=(1, 2), seed=5, sim=sim)  # the same command completes it
    assert [pr.name for _, pr in load_problems(out)] == ["problem_0000", "problem_0001", "problem_0002"]


def test_generate_refuses_zero_problems(tmp_path):
    with pytest.raises(ValueError, match="at least 1"):
        generate_problems(tmp_path / "none", 0)


def test_changing_action_is_bounded():
    rng = np.random.default_rng(0)
    occupied = np.zeros(N_LOCATIONS, bool)
    occupied[4] = True
    a = _changing_action(rng, occupied, ExplorationConfig())
    assert a.pick == 4 and a.release != 4
    with pytest.raises(RuntimeError, match=f"after {MAX_ACTION_DRAWS} draws"):  # nothing to pick: no endless loop
        _changing_action(rng, np.zeros(N_LOCATIONS, bool), ExplorationConfig())


def _corrupt(d: dict, how: str) -> dict:
    d = copy.deepcopy(d)
    if how == "missing_goal":
        del d["goal"]
    elif how == "wrong_version":
        d["version"] = PROBLEM_VERSION + 1
    elif how == "wrong_format":
        d["format"] = "pddl"
    elif how == "seed_not_int":
        d["seed"] = "three"
    elif how == "location_out_of_range":
        d["spec"][0][1] = 9
    elif how == "unknown_type":
        d["spec"][0][0] = "sphere"
    elif how == "action_out_of_range":
        d["actions"][0] = 36
    elif how == "action_not_int":
        d["actions"][0] = 1.5
    elif how == "length_mismatch":
        d["generator_length"] = len(d["actions"]) + 1
    elif how == "short_position":
        d["goal"]["objects"][0]["position"] = [0.5, 0.0]
    elif how == "nan_position":
        d["initial"]["objects"][0]["position"][2] = float("nan")
    elif how == "scene_type_mismatch":
        d["goal"]["objects"] = d["goal"]["objects"][:-1] or [{"type": "cube", "position": [0.5, 0, 0.45]}] * 2
    elif how == "spec_not_list":
        d["spec"] = {"cube": 3}
    return d


CORRUPTIONS = ["missing_goal", "wrong_version", "wrong_format", "seed_not_int", "location_out_of_range",
               "unknown_type", "action_out_of_range", "action_not_int", "length_mismatch", "short_position",
               "nan_position", "scene_type_mismatch", "spec_not_list"]


@pytest.mark.parametrize("how", CORRUPTIONS)
def test_malformed_problem_files_are_refused(problem_dir, tmp_path, how):
    good = json.loads((problem_dir / "problem_0000.json").read_text())
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(_corrupt(good, how)))
    with pytest.raises(ValueError, match="problem") as info:
        load_problem(path)
    msg = str(info.value)
    assert "\n" not in msg and ("problem_0000" in msg or "bad.json" in msg), msg


def test_unreadable_files_are_refused(tmp_path):
    (tmp_path / "x.json").write_text("{not json")
    with pytest.raises(ValueError, match="x.json: not valid JSON"):
        load_problem(tmp_path / "x.json")
    with pytest.raises(ValueError, match="no such file"):
        load_problem(tmp_path / "missing.json")
    (tmp_path / "list.json").write_text("[1, 2]")
    with pytest.raises(ValueError, match="expected a JSON object"):
        load_problem(tmp_path / "list.json")
    with pytest.raises(ValueError, match="no problem directory"):
        load_problems(tmp_path / "missing_dir")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no problem files"):
        load_problems(tmp_path / "empty")


def test_problem_validation_fails_on_purpose(problem_dir):
    pr = load_problem(problem_dir / "problem_0000.json")
    with pytest.raises(ValueError, match="out of range"):
        Problem(pr.name, pr.seed, pr.spec, pr.initial, (99,), pr.goal)
    with pytest.raises(ValueError, match="do not match the spec"):
        Problem(pr.name, pr.seed, pr.spec, Scene(), pr.actions, pr.goal)
    with pytest.raises(ValueError, match="objects"):
        Problem(pr.name, pr.seed, (), Scene(), pr.actions, Scene())


def test_goal_off_locations_counts_judged_objects_away_from_every_location():
    from symlearn.problems.problem import ON_LOCATION_M
    from symlearn.world import LOCATIONS, ObjectState

    def problem(dy: float, free: tuple[int, ...] = ()) -> Problem:
        """Two cubes on locations 3 and 4; in the goal on locations 0 and 1, cube 0 shifted sideways by dy."""
        at = lambda loc, d=0.0: ObjectState(ObjectType.CUBE, (LOCATIONS[loc][0], LOCATIONS[loc][1] + d, 0.425))
        return Problem("p", 0, ((ObjectType.CUBE, 3), (ObjectType.CUBE, 4)), Scene((at(3), at(4))), (0,),
                       Scene((at(0, dy), at(1))), free=free)

    assert problem(0.0).goal_off_locations == 0
    assert problem(ON_LOCATION_M - 0.01).goal_off_locations == 0
    assert problem(-(ON_LOCATION_M + 0.01)).goal_off_locations == 1  # 6 cm from location 0, 24 cm from 1
    assert problem(-(ON_LOCATION_M + 0.01), free=(0,)).goal_off_locations == 0  # a free object is not judged
