"""Faults of the planning commands, each reproduced and now refused or survived.

Problem names that would become paths outside the run, rules exported from another
transition.pt, problem folders mixing two generations, impossible scenes, benchmarks killed
mid-run (SIGTERM, SIGKILL of the real `symlearn benchmark` process) and resumed, and timeouts
that are not a finite positive number of seconds.
"""
from __future__ import annotations

import copy
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import cli

ROOT = Path(__file__).resolve().parents[1]
TIMING_KEYS = {"planning_time_s", "timings", "expansions"}


@pytest.fixture(scope="module")
def problems(tmp_path_factory, sim) -> Path:
    """Four problems of 1-2 objects and 1-2 generator actions."""
    from symlearn.problems.problem_generation import generate_problems

    out = tmp_path_factory.mktemp("faults") / "p"
    generate_problems(out, 4, objects=(1, 2), length=(1, 2), seed=0, sim=sim)
    return out


def _problem_json(problems: Path) -> dict:
    return json.loads((problems / "problem_0000.json").read_text())


def _write(path: Path, d: dict, raw: str | None = None) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(raw if raw is not None else json.dumps(d))
    return path


def _tree(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def _one_line_error(capsys, command: str, *words: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()[-1]  # after any progress lines
    assert err.startswith(f"symlearn {command}: error: ") and "\n" not in err, err
    for w in words:
        assert w in err, err
    return err


def _subprocess_env() -> dict:
    return dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1")


# ------------------------------------------------------------------------------- 1. names that become paths


BAD_NAMES = ["../../../../escaped", "/tmp/symlearn_abs_escape", "..", ".hidden", "a/b", "", "x" * 101, "bad name",
             "evil\nname"]


@pytest.mark.parametrize("name", BAD_NAMES)
def test_unsafe_problem_names_are_refused_at_load(problems, tmp_path, name):
    from symlearn.problems.problem import load_problem

    d = _problem_json(problems)
    d["name"] = name
    path = _write(tmp_path / "bad.json", d)
    with pytest.raises(ValueError, match="is not a safe name") as info:
        load_problem(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["../../../../escaped", "/tmp/symlearn_abs_escape_plan"])
def test_plan_with_traversing_name_writes_nothing_outside_the_run(tiny_run_copy, problems, tmp_path, capsys, name):
    d = _problem_json(problems)
    d["name"] = name
    path = _write(tmp_path / "in" / "bad.json", d)
    before = _tree(tmp_path)
    rc, out = cli("plan", "--run", tiny_run_copy, "--problem", path, "--planner", "fast-downward",
                  "--timeout", "10")
    assert rc == 2 and out == ""
    _one_line_error(capsys, "plan", "is not a safe name", str(path))
    assert _tree(tmp_path) == before  # nothing created in or beside the run
    assert not Path("/tmp/symlearn_abs_escape_plan").exists()


@pytest.mark.parametrize("parts", [("..", "x"), ("/etc",), ("a", "..", "..", "b"), (".",), ("link", "x")])
def test_path_under_refuses_escapes(tmp_path, parts):
    from symlearn.problems.paths import path_under

    base = tmp_path / "base"
    base.mkdir()
    (base / "link").symlink_to(tmp_path)  # a link inside base pointing out of it
    with pytest.raises(ValueError, match="escapes"):
        path_under(base, *parts)


def test_path_under_keeps_inside_paths(tmp_path):
    from symlearn.problems.paths import path_under

    assert path_under(tmp_path, "problem_0000", "problem.pddl") == tmp_path / "problem_0000" / "problem.pddl"
    assert path_under(tmp_path, "a", "..", "b") == tmp_path / "a" / ".." / "b"  # stays inside: allowed


def test_problem_constructor_refuses_unsafe_name(problems):
    from symlearn.problems.problem import Problem, load_problem

    pr = load_problem(problems / "problem_0000.json")
    with pytest.raises(ValueError, match="is not a safe name"):
        Problem("../x", pr.seed, pr.spec, pr.initial, pr.actions, pr.goal)


# ------------------------------------------------------------------------------- 2. stale exports


def test_rules_from_a_retrained_transition_are_refused(tiny_run, tiny_run_copy, problems, tmp_path, capsys):
    import hashlib

    rules = json.loads((tiny_run_copy / "pddl" / "rules.json").read_text())
    (tmp_path / "e1.toml").write_text("[transition]\nepochs = 1\n")
    rc, _ = cli("train-transition", "--run", tiny_run_copy, "--data", tiny_run.data, "--preset", "quick",
                "--config", tmp_path / "e1.toml", "--seed", "1", "--quiet")
    assert rc == 0
    capsys.readouterr()
    new_hash = hashlib.sha256((tiny_run_copy / "transition.pt").read_bytes()).hexdigest()[:16]
    assert new_hash != rules["model_hash"]
    problem = problems / "problem_0000.json"
    rc, out = cli("plan", "--run", tiny_run_copy, "--problem", problem, "--planner", "fast-downward",
                  "--timeout", "10")
    assert rc == 2 and out == ""
    _one_line_error(capsys, "plan", "rules.json was exported from another transition.pt", "re-run 'symlearn export-pddl")
    assert not (tiny_run_copy / "pddl" / "problems").exists()
    out_file = tmp_path / "b.json"
    rc, out = cli("benchmark", "--run", tiny_run_copy, "--problems", problems, "--planners", "astar,rules-bfs",
                  "--out", out_file)
    assert rc == 2 and not out_file.exists() and not (tmp_path / "b.json.rows.jsonl").exists()
    _one_line_error(capsys, "benchmark", "was exported from another transition.pt")
    # the network planners do not read the rules; and rules re-stamped with the current hash are accepted
    rc, _ = cli("plan", "--run", tiny_run_copy, "--problem", problem, "--planner", "astar", "--timeout", "10")
    assert rc == 0
    (tiny_run_copy / "pddl" / "rules.json").write_text(json.dumps(dict(rules, model_hash=new_hash)))
    rc, _ = cli("plan", "--run", tiny_run_copy, "--problem", problem, "--planner", "fast-downward",
                "--timeout", "10")
    assert rc == 0


@pytest.mark.parametrize("recorded", ["0123456789abcdef", "", None])
def test_rules_hash_mismatch_or_missing_is_refused(tiny_run_copy, recorded):
    from symlearn.planning.planners import PlannerContext

    path = tiny_run_copy / "pddl" / "rules.json"
    d = json.loads(path.read_text())
    if recorded is None:
        del d["model_hash"]
    else:
        d["model_hash"] = recorded
    path.write_text(json.dumps(d))
    with pytest.raises(ValueError, match="was exported from another transition.pt"):
        PlannerContext.for_run(tiny_run_copy, ["fast-downward"])
    assert PlannerContext.for_run(tiny_run_copy, ["astar"]).rules is None  # not read when not needed


# ------------------------------------------------------------------------------- 3. problem folders


def _contents(d: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted(d.iterdir())}


def test_problems_into_a_folder_of_other_settings_is_refused(sim, tmp_path):
    from symlearn.problems.problem_generation import PROBLEMS_MANIFEST, generate_problems

    out = tmp_path / "p"
    generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=0, sim=sim)
    first = _contents(out)
    assert set(first) == {"problem_0000.json", "problem_0001.json", PROBLEMS_MANIFEST}
    for kwargs in (dict(seed=1), dict(length=(1, 2)), dict(objects=(1, 2)), dict(n=3)):
        args = dict(n=2, objects=(1, 1), length=(1, 1), seed=0) | kwargs
        with pytest.raises(ValueError, match="already holds problems of other settings.*--overwrite"):
            generate_problems(out, sim=sim, **args)
        assert _contents(out) == first  # nothing replaced, nothing mixed
    generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=0, sim=sim)  # same settings: idempotent
    assert _contents(out) == first
    (out / "problem_0001.json").unlink()  # an interrupted (killed) generation: resumed, the same problem again
    (out / ".problem_0001.json.abc123.tmp").write_text('{"half')
    generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=0, sim=sim)
    assert _contents(out) == first


def test_problems_overwrite_clears_the_old_set(sim, tmp_path):
    from symlearn.problems.problem import load_problems
    from symlearn.problems.problem_generation import generate_problems

    out = tmp_path / "p"
    generate_problems(out, 3, objects=(1, 1), length=(1, 1), seed=0, sim=sim)
    generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=4, sim=sim, overwrite=True)
    loaded = load_problems(out)
    assert [p.name for p, _ in loaded] == ["problem_0000.json", "problem_0001.json"]  # the old third one is gone
    assert {pr.seed for _, pr in loaded} == {4}
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="not problems of a set"):  # never deletes what it did not write
        generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=5, sim=sim, overwrite=True)
    assert (out / "notes.txt").read_text() == "mine"


def test_problems_refuse_a_folder_without_manifest(tmp_path, capsys):
    out = tmp_path / "p"
    out.mkdir()
    (out / "problem_0000.json").write_text("{}")
    rc, _ = cli("problems", "--kind", "walks", "--out", out, "--n", 1, "--seed", 0)
    assert rc == 2
    _one_line_error(capsys, "problems", "files but no problem manifest", "--overwrite")
    assert _contents(out) == {"problem_0000.json": "{}"}


@pytest.mark.parametrize("args", [("--seed", "-1"), ("--n", "0"), ("--n", "-3"), ("--objects", "0-2"),
                                  ("--length", "0-1"), ("--objects", "3-11")])
def test_problems_bad_settings_create_nothing(tmp_path, capsys, args):
    out = tmp_path / "p"
    try:
        rc, _ = cli("problems", "--kind", "walks", "--out", out, *args)
    except SystemExit as e:  # an argparse type error
        rc = e.code
    assert rc == 2 and not out.exists()
    assert "error" in capsys.readouterr().err


# ------------------------------------------------------------------------------- 4. impossible scenes


SCENE_FAULTS = {
    "zero_quaternion": (lambda o: o.__setitem__("orientation", [0, 0, 0, 0]), "not a unit quaternion"),
    "long_quaternion": (lambda o: o.__setitem__("orientation", [0, 0, 0, 2]), "not a unit quaternion"),
    "x_100m_off": (lambda o: o["position"].__setitem__(0, 100.65), "out of the table's reach"),
    "y_off": (lambda o: o["position"].__setitem__(1, -0.7), "out of the table's reach"),
    "under_table": (lambda o: o["position"].__setitem__(2, 0.1), "out of the table's reach"),
    "above_reach": (lambda o: o["position"].__setitem__(2, 1.5), "out of the table's reach"),
    "huge": (lambda o: o["position"].__setitem__(2, 1e308), "out of the table's reach"),
}


@pytest.mark.parametrize("fault", list(SCENE_FAULTS))
@pytest.mark.parametrize("scene", ["initial", "goal"])
def test_impossible_scenes_are_refused_at_load(problems, tmp_path, fault, scene):
    from symlearn.problems.problem import load_problem

    d = copy.deepcopy(_problem_json(problems))
    change, message = SCENE_FAULTS[fault]
    change(d[scene]["objects"][0])
    path = _write(tmp_path / "bad.json", d)
    with pytest.raises(ValueError, match=message) as info:
        load_problem(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value) and scene in str(info.value)


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_non_finite_numbers_in_problem_files_are_refused(problems, tmp_path, literal):
    from symlearn.problems.problem import load_problem

    d = _problem_json(problems)
    text = json.dumps(d).replace(json.dumps(d["initial"]["objects"][0]["position"][0]), literal, 1)
    path = _write(tmp_path / "bad.json", d, raw=text)
    with pytest.raises(ValueError) as info:
        load_problem(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_plan_refuses_impossible_scene_with_one_line(tiny_run, problems, tmp_path, capsys):
    d = _problem_json(problems)
    d["goal"]["objects"][0]["orientation"] = [0, 0, 0, 0]
    path = _write(tmp_path / "bad.json", d)
    rc, out = cli("plan", "--run", tiny_run.path, "--problem", path, "--planner", "astar")
    assert rc == 2 and out == ""
    _one_line_error(capsys, "plan", str(path), "not a unit quaternion")


def _moved(scene, i: int, axis: int, value: float):
    """The scene with object i's position on `axis` (0 x, 1 y, 2 z) set to value."""
    import dataclasses

    o = scene.objects[i]
    pos = list(o.position)
    pos[axis] = value
    objs = list(scene.objects)
    objs[i] = dataclasses.replace(o, position=tuple(pos))
    return dataclasses.replace(scene, objects=tuple(objs))


def test_valid_problem_scenes_pass_the_reach_check(problems):
    """The simulator's generated scenes (initial and goal) pass check_scene, with room to spare: each object rests
    on the table, more than 15 cm inside the reach box's sides. The check is no rubber stamp: the same scenes with
    one object moved 1 um past any edge of the reach box are refused, and 1 um inside it they still pass."""
    from symlearn.problems.problem import (REACH_CENTER_X, REACH_HALF_X, REACH_HALF_Y, REACH_Z_MAX, OutOfReach,
                                           check_scene, load_problems)
    from symlearn.world import TABLE_TOP_Z

    loaded = load_problems(problems)
    assert [p.name for p, _ in loaded] == [f"problem_{i:04d}.json" for i in range(4)]
    eps = 1e-6
    edges = [(0, REACH_CENTER_X + REACH_HALF_X, -1.0), (0, REACH_CENTER_X - REACH_HALF_X, 1.0),
             (1, REACH_HALF_Y, -1.0), (1, -REACH_HALF_Y, 1.0), (2, TABLE_TOP_Z, 1.0), (2, REACH_Z_MAX, -1.0)]
    for _, pr in loaded:
        for scene in (pr.initial, pr.goal):
            assert scene.k == pr.k and 1 <= scene.k <= 2
            assert check_scene(scene, pr.name) is None
            pos = scene.positions()
            margin = np.minimum(REACH_HALF_X - np.abs(pos[:, 0] - REACH_CENTER_X), REACH_HALF_Y - np.abs(pos[:, 1]))
            assert (margin > 0.15).all(), pos  # the grid spans x 0.5-0.8, y -0.3-0.3: a stick's centre may lie between
            assert ((pos[:, 2] > TABLE_TOP_Z) & (pos[:, 2] < TABLE_TOP_Z + 0.2)).all(), pos  # on the table, not flung
            for axis, edge, inward in edges:
                with pytest.raises(OutOfReach, match="out of the table's reach"):  # 1 um past the edge: its own
                    # ValueError, which the generators catch to draw again
                    check_scene(_moved(scene, 0, axis, edge - inward * eps), pr.name)
                assert check_scene(_moved(scene, 0, axis, edge + inward * eps), pr.name) is None


# ------------------------------------------------------------------------------- 5. interrupted benchmarks


def test_strict_json_replaces_non_finite_floats():
    from pddl_export.files import finite_or_null as strict_json

    d = strict_json({"a": float("nan"), "b": [1.0, float("inf"), {"c": -float("inf")}], "d": 2, "e": "NaN"})
    assert d == {"a": None, "b": [1.0, None, {"c": None}], "d": 2, "e": "NaN"}
    json.dumps(d, allow_nan=False)


def test_row_log_cuts_a_torn_row_and_refuses_other_settings(tmp_path):
    from symlearn.planning.benchmark_rows import RowLog

    path = tmp_path / "b.json.rows.jsonl"
    log = RowLog(path, {"planners": ["astar"], "timeout_s": 10.0})
    assert log.open() == {}
    row = {"problem": "p0", "planner": "astar", "found": True, "status": "solved", "plan_length": 1,
           "planning_time_s": 0.1, "expansions": 2, "success": True, "symbolic_match": True, "max_distance_m": 0.01,
           "closed_loop": False, "replans": 0, "failure_stage": None, "generator_length": 1}
    log.append(("p0.json", "astar", False), {**row, "max_distance_m": float("nan")})
    log.close()
    with open(path, "a") as f:
        f.write('{"key": ["p1.json", "ast')  # a kill in the middle of a row
    log = RowLog(path, {"planners": ["astar"], "timeout_s": 10.0})
    assert log.open() == {("p0.json", "astar", False): {**row, "max_distance_m": None}}
    log.close()
    assert path.read_text().endswith("}\n")
    for line in path.read_text().splitlines():
        json.loads(line, parse_constant=lambda c: pytest.fail(f"non-strict JSON {c}"))
    with pytest.raises(ValueError, match="other settings \\(differing: timeout_s\\)"):
        RowLog(path, {"planners": ["astar"], "timeout_s": 20.0}).open()


def _bench_cmd(run: Path, problems: Path, out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "symlearn.cli.main", "benchmark", "--run", str(run), "--problems", str(problems),
            "--planners", "astar", "--timeout", "10", "--out", str(out), *extra]


def _rows_done(rows_file: Path) -> int:
    if not rows_file.exists():
        return 0
    return max(rows_file.read_text().count("\n") - 1, 0)


def _children(pid: int) -> list[int]:
    r = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True)
    return [int(x) for x in r.stdout.split()]


def _comparable(result: dict) -> dict:
    """A benchmark result without what differs between two runs of the same settings (times, paths of the run)."""
    rows = [{k: v for k, v in r.items() if k not in TIMING_KEYS} for r in result["rows"]]
    summary = {p: {k: v for k, v in s.items() if "time" not in k} for p, s in result["summary"].items()}
    keep = {k: v for k, v in result.items() if k not in ("rows", "summary", "wall_time_s", "run", "versions")}
    return _untimed(dict(keep, rows=rows, summary=summary))


def _untimed(obj):
    """obj without its timing entries at any depth (the grid's and tasks' median planning times)."""
    if isinstance(obj, dict):
        return {k: _untimed(v) for k, v in obj.items() if "time" not in k}
    if isinstance(obj, list):
        return [_untimed(v) for v in obj]
    return obj


@pytest.fixture(scope="module")
def uninterrupted(tiny_run, problems, tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("bench_ref") / "b.json"
    rc, _ = cli("benchmark", "--run", tiny_run.path, "--problems", problems, "--planners", "astar",
                "--timeout", "10", "--out", out)
    assert rc == 0
    return json.loads(out.read_text())


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_benchmark_killed_mid_run_resumes_to_the_same_result(tiny_run, problems, uninterrupted, tmp_path, sig):
    out = tmp_path / "b.json"
    rows_file = tmp_path / "b.json.rows.jsonl"
    cmd = _bench_cmd(tiny_run.path, problems, out)
    proc = subprocess.Popen(cmd, cwd=ROOT, env=_subprocess_env(), start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 240
    while _rows_done(rows_file) < 2 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, proc.stderr.read().decode()[-2000:]
    os.killpg(proc.pid, sig)
    proc.wait(timeout=30)
    assert proc.returncode == -sig
    assert not _children(proc.pid)
    with pytest.raises(ProcessLookupError):
        os.killpg(proc.pid, 0)  # the whole group is gone
    finished = _rows_done(rows_file)
    assert 2 <= finished < 8 and not out.exists()
    assert not [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    # another setting cannot resume this run
    open_loop = tmp_path / "open.toml"
    open_loop.write_text("[execution]\nclosed_loop = false\n")
    r = subprocess.run(_bench_cmd(tiny_run.path, problems, out, "--config", str(open_loop)), cwd=ROOT, env=_subprocess_env(),
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "other settings (differing: closed_loop)" in r.stderr
    assert r.stderr.strip().count("\n") == 0 and _rows_done(rows_file) == finished
    r = subprocess.run(cmd, cwd=ROOT, env=_subprocess_env(), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert f"[{finished + 1}/8]" in r.stdout and f"[{finished}/8]" not in r.stdout  # finished rows skipped
    resumed = json.loads(out.read_text(), parse_constant=lambda c: pytest.fail(f"non-strict JSON {c}"))
    assert _comparable(resumed) == _comparable(uninterrupted)
    assert len(resumed["rows"]) == 8 and not rows_file.exists()


# ------------------------------------------------------------------------------- 6. timeouts


@pytest.mark.parametrize("timeout", ["inf", "-inf", "0", "-1", "nan", "1e9", "soon"])
@pytest.mark.parametrize("command", ["plan", "benchmark"])
def test_timeouts_must_be_finite_positive_seconds(tiny_run, problems, tmp_path, capsys, timeout, command):
    args = (["plan", "--run", tiny_run.path, "--problem", problems / "problem_0000.json"] if command == "plan" else
            ["benchmark", "--run", tiny_run.path, "--problems", problems, "--out", tmp_path / "b.json"])
    with pytest.raises(SystemExit) as info:
        cli(*args, f"--timeout={timeout}")  # = so that -inf is not read as an option
    assert info.value.code == 2 and not (tmp_path / "b.json").exists()
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and (f"argument --timeout: timeout {timeout!r} "
                              + ("is not a number of seconds" if timeout == "soon" else
                                 "must be a finite number of seconds in (0, 86400]")) in err[0], err


def test_benchmark_library_refuses_non_finite_timeout(tiny_run, problems, tmp_path):
    from symlearn.planning.benchmark import benchmark

    for t in (math.inf, math.nan, 0.0):
        with pytest.raises(ValueError, match="finite positive"):
            benchmark(tiny_run.path, problems, ["astar"], tmp_path / "b.json", timeout_s=t)
    assert not list(tmp_path.iterdir())
