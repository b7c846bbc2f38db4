"""Shortest plans: the stacking model's rules, scenes read as states, the A* search, the problem
file's fields, the check against the simulator, and stratified sets (cells, dev/test disjoint, resume)."""
from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from symlearn.problems.goals import ObjectGoal
from symlearn.problems.problem import (PROBLEM_VERSION, Problem, load_problem, load_problems, max_goal_distance,
                                       save_problem)
from symlearn.problems.problem_generation import add_shortest_plans, generate_problems
from symlearn.problems.shortest import (NotCovered, scene_state, shortest_plan, state_scene, with_shortest)
from symlearn.problems.stacking import act, check_state, drop_all, levels, successors
from symlearn.problems.stratified import MODEL_MAX_LENGTH, same_problem
from symlearn.world import ObjectState, ObjectType, Scene, action_id, decode_action

C, S = ObjectType.CUBE, ObjectType.STICK
ROOT = Path(__file__).resolve().parents[1]


def _problem(spec, goal_state, free=(), actions=(), name="p") -> Problem:
    types = [t for t, _ in spec]
    return Problem(name, 0, tuple(spec), state_scene(drop_all(spec), types), tuple(actions),
                   state_scene(goal_state, types), free=tuple(free))


# ------------------------------------------------------------------------------------------------ the model


def test_a_rider_on_the_end_of_a_raised_stick_is_refused():
    s = drop_all([(C, 1), (S, 1)])  # the stick balanced on a cube at the far middle
    assert s[1] == ObjectGoal(1, 0)
    with pytest.raises(ValueError, match="raised|standing on object 0"):
        act(s + (ObjectGoal(4),), [C, S, C], 4, 0)
    # a stick carrying an end rider is not put down on a column either
    s = drop_all([(S, 1), (C, 0), (C, 2)])
    with pytest.raises(ValueError, match="tip|leave"):
        act(s, [S, C, C], 1, 2)


def test_levels_count_layers_of_five_centimetres():
    s = drop_all([(S, 1), (C, 0), (C, 0), (C, 4)])  # the stick, a tower of two on its end, a cube
    assert levels(s, [S, C, C, C]) == (0, 1, 3, 0)
    assert s[1] == ObjectGoal(0, 0, True) and s[2] == ObjectGoal(0, 1)


@pytest.mark.parametrize("state, types, match", [
    ((ObjectGoal(3), ObjectGoal(3)), [C, C], "share one seat"),
    ((ObjectGoal(1), ObjectGoal(0)), [S, C], "under an end"),
    ((ObjectGoal(3, 1), ObjectGoal(4)), [C, C], "at 4"),
    ((ObjectGoal(0, 1, True), ObjectGoal(4)), [C, C], "not on an end"),
])
def test_check_state_refuses_what_the_rules_cannot_make(state, types, match):
    with pytest.raises(ValueError, match=match):
        check_state(state, types)


def test_successors_are_the_actions_that_change_something_and_stay_in_the_model():
    types = [S, C]
    s = drop_all([(S, 1), (C, 0)])  # a cube on the stick's end: location 0 holds it, 1 the stick's middle
    got = dict(successors(s, types))
    assert set(a // 6 for a in got) == {0, 1}  # picks at the occupied locations only (2 is the bare end)
    assert all(a // 6 != a % 6 for a in got)
    assert action_id(1, 0) not in got  # the rider would leave the locations
    assert got[action_id(1, 2)] == (ObjectGoal(2), ObjectGoal(1, 0, True))  # the loaded stick one place along
    for nxt in got.values():
        check_state(nxt, types)


# ------------------------------------------------------------------------------------------------ scenes


@pytest.mark.parametrize("spec", [[(C, 3)], [(S, 1), (C, 0), (C, 2)], [(C, 4), (S, 4), (C, 4)],
                                  [(C, 0), (C, 0), (C, 0), (C, 5), (S, 3)]])
def test_scene_state_reads_back_the_state_a_scene_was_drawn_from(spec):
    types = [t for t, _ in spec]
    s = drop_all(spec)
    assert scene_state(state_scene(s, types)) == s


def test_scene_state_refuses_poses_the_model_has_none_for():
    off = Scene((ObjectState(C, (0.5, -0.27, 0.45)),))  # 3 cm from location 3
    with pytest.raises(NotCovered, match="3.0 cm from the nearest location"):
        scene_state(off)
    tilted = Scene((ObjectState(C, (0.5, -0.3, 0.45), (0.2588, 0.0, 0.0, 0.9659)),))  # 30 degrees
    with pytest.raises(NotCovered, match="tilted by 30"):
        scene_state(tilted)
    hanging = Scene((ObjectState(C, (0.5, -0.3, 0.475)),))
    with pytest.raises(NotCovered, match="between layers"):
        scene_state(hanging)


# ------------------------------------------------------------------------------------------------ the search


def test_the_search_finds_the_shortest_plan_not_the_reference():
    spec = [(C, 3), (C, 3)]  # object 1 on object 0 at location 3
    # the tower upside down in place: both must leave, then come back: 4 actions
    sp = shortest_plan(_problem(spec, (ObjectGoal(3, 1), ObjectGoal(3))))
    assert sp.length == 4 and sp.reason is None and len(sp.plan) == 4
    # a reference plan of 3 (to 0, to 1, to 2) for what one action does
    p = _problem([(C, 4)], (ObjectGoal(2),), actions=(action_id(4, 0), action_id(0, 1), action_id(1, 2)))
    assert shortest_plan(p).plan == (action_id(4, 2),) and p.generator_length == 3


def test_free_objects_are_not_judged_and_any_of_them_may_hold_a_judged_one_up():
    spec = [(C, 3), (C, 4), (C, 5)]
    # judged: object 0 on top of a cube at location 1; objects 1 and 2 free (the goal shows 1 under it)
    goal = (ObjectGoal(1, 1), ObjectGoal(1), ObjectGoal(4))
    sp = shortest_plan(_problem(spec, goal, free=(1, 2)))
    assert sp.length == 2  # any cube to 1, then object 0 onto it
    assert shortest_plan(_problem(spec, goal)).length == 3  # all judged: 1 to location 1, 0 onto it, 2 to 4


def _bfs_length(start, types, want, max_length=12):
    """The shortest plan's length by plain breadth-first search (the reference the A* search must match)."""
    meets = lambda st: all(st[i].location == loc and levels(st, types)[i] == layer  # noqa: E731
                           for i, (loc, layer) in want.items())
    seen, frontier = {start}, [start]
    for depth in range(max_length + 1):
        if any(meets(st) for st in frontier):
            return depth
        nxt = [c for st in frontier for _, c in successors(st, types) if c not in seen]
        seen.update(nxt)
        frontier = list(dict.fromkeys(nxt))
    return None


def test_the_a_star_search_finds_what_breadth_first_search_finds_and_its_bound_holds():
    """On random problems of 1-5 objects (sticks, riders, free objects), the A* search's length is the
    breadth-first one, and the lower bound it is guided by never exceeds the actions still needed."""
    import numpy as np

    from symlearn.problems.shortest import lower_bound
    rng = np.random.default_rng(7)
    checked = 0
    while checked < 40:
        k = int(rng.integers(1, 6))
        types = [S if i == 0 and rng.random() < 0.6 else C for i in range(k)]
        spec = [(t, int(rng.choice((3, 4, 5)))) for t in types]
        goal = drop_all(spec)
        for _ in range(int(rng.integers(1, 9))):
            moves = list(successors(goal, types))
            goal = moves[int(rng.integers(len(moves)))][1] if moves else goal
        free = tuple(i for i in range(1, k) if rng.random() < 0.2)  # object 0 always judged
        p = _problem(spec, goal, free=free)
        want = {i: (goal[i].location, levels(goal, types)[i]) for i in range(k) if i not in free}
        sp = shortest_plan(p)
        assert sp.length == _bfs_length(drop_all(spec), types, want), (spec, goal, free)
        state = drop_all(spec)  # along the plan, the bound never exceeds the actions left
        for n, a in enumerate(sp.plan):
            assert lower_bound(state, types, want) <= sp.length - n
            state = act(state, types, a // 6, a % 6)
        assert lower_bound(state, types, want) == 0
        checked += 1


def test_undecidable_problems_say_why_and_have_no_length():
    spec = [(C, 3), (C, 4)]
    far = _problem(spec, (ObjectGoal(0), ObjectGoal(1, 0)))
    off_goal = Scene((far.goal.objects[0], ObjectState(C, (0.65, 0.0, 0.45))))  # 15 cm from every location
    off = Problem("off", 0, far.spec, far.initial, (), off_goal)
    assert off.goal_off_locations == 1
    assert shortest_plan(off).reason == "goal_off_locations" and shortest_plan(off).length is None
    near = Scene((far.goal.objects[0], ObjectState(C, (0.8, 0.15, 0.45))))  # 3 cm off location 2 (0 is taken)
    assert shortest_plan(Problem("near", 0, far.spec, far.initial, (), near)).reason == "pose_not_covered"
    capped = shortest_plan(_problem(spec, (ObjectGoal(3, 1), ObjectGoal(3))), max_length=2)
    assert capped.reason == "search_cap" and capped.length is None
    # a cube on the table under the end of the stick: no state of the model has it; all 42 states searched
    stuck = _problem([(S, 3), (C, 4)], (ObjectGoal(1), ObjectGoal(0)))
    sp = shortest_plan(stuck)
    assert sp.reason == "unreachable" and sp.states == 42


def test_the_model_bounds_are_its_state_spaces_diameters():
    """MODEL_MAX_LENGTH (the cells --stratify skips) is the longest shortest plan over all pairs of states."""
    def explore(start, types):
        seen, frontier, d = {start: 0}, [start], 0
        while frontier:
            d, nxt = d + 1, []
            for s in frontier:
                for _, c in successors(s, types):
                    if c not in seen:
                        seen[c] = d
                        nxt.append(c)
            frontier = nxt
        return seen

    for spec in ([(C, 3)], [(S, 3)], [(C, 3), (C, 4)], [(S, 3), (C, 4)]):
        types = [t for t, _ in spec]
        states = explore(drop_all(spec), types)
        assert max(max(explore(s, types).values()) for s in states) == MODEL_MAX_LENGTH[len(spec)], spec


# ------------------------------------------------------------------------------------------------ problem files


def test_problem_files_keep_the_shortest_plan_and_older_files_load_without_it(tmp_path):
    p = with_shortest(_problem([(C, 3), (C, 3)], (ObjectGoal(3, 1), ObjectGoal(3))))
    assert p.optimal_length == 4 and p.optimal_known
    save_problem(tmp_path / "p.json", p)
    d = json.loads((tmp_path / "p.json").read_text())
    assert d["version"] == PROBLEM_VERSION == 3 and d["optimal_length"] == 4 and len(d["optimal_plan"]) == 4
    assert load_problem(tmp_path / "p.json") == p
    old = {k: v for k, v in d.items() if not k.startswith("optimal_")} | {"version": 2}
    (tmp_path / "old.json").write_text(json.dumps(old))
    loaded = load_problem(tmp_path / "old.json")
    assert loaded.optimal_length is None and loaded.optimal_reason is None and not loaded.optimal_known


@pytest.mark.parametrize("change, match", [
    ({"optimal_length": 3}, "optimal_plan has 4 actions"),
    ({"optimal_reason": "search_cap"}, "comes with a reason"),
    ({"optimal_length": None, "optimal_reason": "tired"}, "not one of"),
    ({"optimal_length": -1}, "non-negative"),
    ({"optimal_plan": [0, 1, 2, 99]}, "action ids"),
    ({"optimal_length": None}, "without an optimal_length"),
])
def test_inconsistent_shortest_plans_are_refused(tmp_path, change, match):
    p = with_shortest(_problem([(C, 3), (C, 3)], (ObjectGoal(3, 1), ObjectGoal(3))))
    (tmp_path / "p.json").write_text(json.dumps(p.to_json() | change))
    with pytest.raises(ValueError, match=match) as e:
        load_problem(tmp_path / "p.json")
    assert "\n" not in str(e.value) and "p.json" in str(e.value)


def test_a_version_3_file_without_the_fields_is_refused(tmp_path):
    p = with_shortest(_problem([(C, 3)], (ObjectGoal(0),)))
    d = p.to_json()
    del d["optimal_reason"]
    (tmp_path / "p.json").write_text(json.dumps(d))
    with pytest.raises(ValueError, match="missing keys optimal_reason"):
        load_problem(tmp_path / "p.json")


def test_annotate_adds_shortest_plans_to_an_older_set_and_resumes(tmp_path):
    p = _problem([(C, 3), (C, 4)], (ObjectGoal(0), ObjectGoal(0, 0)), actions=(action_id(3, 0), action_id(4, 0)))
    d = {k: v for k, v in p.to_json().items() if not k.startswith("optimal_")} | {"version": 2}
    (tmp_path / "problem_0000.json").write_text(json.dumps(d))
    (tmp_path / "problems.manifest").write_text(json.dumps({"format": "symlearn-problem-set", "problem_version": 2}))
    assert add_shortest_plans(tmp_path) == {"annotated": 1, "kept": 0, "known": 1, "undecided": 0}
    assert load_problem(tmp_path / "problem_0000.json").optimal_length == 2
    assert json.loads((tmp_path / "problems.manifest").read_text())["problem_version"] == PROBLEM_VERSION
    before = (tmp_path / "problem_0000.json").stat().st_mtime_ns
    # a set of the older version is completed only once annotated: its command says how
    from symlearn.problems.problem_generation import prepare_problem_dir
    old = tmp_path / "old"
    old.mkdir()
    (old / "problem_0000.json").write_text(json.dumps(d))
    (old / "problems.manifest").write_text(json.dumps({"format": "symlearn-problem-set", "problem_version": 2}))
    with pytest.raises(ValueError, match="version 2, without shortest plans: 'symlearn problems --kind annotate --out"):
        prepare_problem_dir(old, {"format": "symlearn-problem-set", "problem_version": PROBLEM_VERSION})
    add_shortest_plans(old)
    prepare_problem_dir(old, {"format": "symlearn-problem-set", "problem_version": PROBLEM_VERSION})
    assert add_shortest_plans(tmp_path)["kept"] == 1
    assert (tmp_path / "problem_0000.json").stat().st_mtime_ns == before


# ------------------------------------------------------------------------------------------------ the simulator


def test_shortest_plans_reach_their_goals_in_the_simulator(tmp_path, sim):
    """The model against the simulator: the plans it finds for small walks and structure tasks, executed there,
    end within 2 cm of the goal on every judged object, and are never longer than the reference plan."""
    from symlearn.problems.structure_suite import generate_structures

    paths = generate_problems(tmp_path / "walks", 4, objects=(1, 3), length=(2, 5), seed=11, sim=sim)
    paths += generate_structures(tmp_path / "tasks", 3, objects=(2, 3), seed=2, sim=sim)
    checked, shorter = 0, 0
    for path in paths:
        pr = load_problem(path)
        assert pr.optimal_known, pr.name
        if pr.optimal_length is None:
            continue
        sim.reset(pr.initial)
        for a in pr.optimal_plan:
            sim.step(decode_action(a))
        assert max_goal_distance(sim.get_scene(), pr.goal, pr.free) <= 0.02, (path, pr.optimal_plan)
        assert pr.optimal_length <= pr.generator_length, path
        checked += 1
        shorter += pr.optimal_length < pr.generator_length
    assert checked >= 5 and shorter >= 1, (checked, shorter)


# ------------------------------------------------------------------------------------------------ stratified sets


def _doc_command(out: str) -> list[str]:
    """The documented command that builds problems/<out> (docs/PROBLEMS.md), as argv after `symlearn`."""
    text = (ROOT / "docs" / "PROBLEMS.md").read_text()
    lines = [ln for block in re.findall(r"```[^\n]*\n(.*?)```", text, re.S) for ln in block.splitlines()
             if ln.startswith("symlearn problems ") and f"--out problems/{out} " in ln + " "]
    assert len(lines) == 1, lines
    return shlex.split(lines[0].split("  #")[0])[1:]


def test_dev_and_test_sets_as_documented_share_no_problem(tmp_path, monkeypatch, capsys):
    from conftest import cli

    monkeypatch.chdir(tmp_path)
    for out in ("dev", "test"):
        argv = _doc_command(out)
        argv[argv.index("--n") + 1] = "1"  # a tiny n, 1-2 objects: the commands' seeds and exclusion as written
        argv[argv.index("--objects") + 1] = "1-2"
        rc, printed = cli(*argv)
        assert rc == 0 and "k1   3-4: 0/1 (no goal of 1 object needs more than 1 action" in printed, printed
    dev, test = load_problems(tmp_path / "problems/dev"), load_problems(tmp_path / "problems/test")
    assert len(dev) == len(test) == 5  # k1 1-2, k1 off, k2 1-2, k2 3-4, k2 off
    shared = [(a.name, b.name) for _, a in dev for _, b in test if same_problem(a, b)]
    assert not shared
    for _, pr in dev + test:
        k, cell = re.fullmatch(r"k(\d)_(opt\d+-\d+|off)_0000", pr.name).groups()
        assert pr.k == int(k)
        if cell == "off":
            assert pr.goal_off_locations > 0 and pr.optimal_reason == "goal_off_locations"
        else:
            lo, hi = map(int, cell[3:].split("-"))
            assert lo <= pr.optimal_length <= hi, pr.name
    manifest = json.loads((tmp_path / "problems/test/problems.manifest").read_text())
    assert manifest["stratify"] == "shortest" and manifest["exclude"][0]["folder"] == "problems/dev"
    # the same command completes (here: keeps) the set; another dev set behind it is refused
    stamp = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "problems/test").glob("*.json")}
    argv = _doc_command("test")
    argv[argv.index("--n") + 1], argv[argv.index("--objects") + 1] = "1", "1-2"
    assert cli(*argv)[0] == 0
    assert stamp == {p.name: p.stat().st_mtime_ns for p in (tmp_path / "problems/test").glob("*.json")}
    (tmp_path / "problems/dev/k1_off_0000.json").unlink()
    capsys.readouterr()
    assert cli(*argv)[0] == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]  # the line before it says what was asked
    assert err.startswith("symlearn problems: error: problems/test already holds problems of other settings "
                          "(exclude"), err


def test_same_problem_compares_scenes_not_names():
    a = _problem([(C, 3)], (ObjectGoal(0),), name="a")
    assert same_problem(a, _problem([(C, 3)], (ObjectGoal(0),), name="b"))
    assert not same_problem(a, _problem([(C, 3)], (ObjectGoal(1),), name="a"))
    assert not same_problem(a, _problem([(S, 3)], (ObjectGoal(0),), name="a"))
