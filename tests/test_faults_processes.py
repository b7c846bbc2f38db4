"""Fault probes of processes and outputs (issue 36): signals, locks, output paths, time limits, error reporting.

Each probe reproduces a careful (or hostile) user's mistake and checks the guarantee of
docs/RELIABILITY.md: a signal the caller ignores stays ignored and a planner killed by a signal
is never a benchmark row; output paths are checked before any work; a second writer of a folder
is refused with the holder's pid; every planner's time limit covers all of its work; and a
failure reaches the terminal in one line with a non-zero exit code.
"""
from __future__ import annotations

import fcntl
import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from conftest import cli
from search.processes import PlannerInterrupted, planner_guard, run_group
from search.result import PlanStatus, failed

ROOT = Path(__file__).resolve().parents[1]
GUARDED = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)


def _one_line_error(capsys, command: str, *words: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert err, "nothing was printed on stderr"
    line = err[-1]
    assert line.startswith(f"symlearn {command}: error: "), err
    for w in words:
        assert w in line, line
    return line


@pytest.fixture(scope="module")
def problems(tmp_path_factory, sim) -> Path:
    """Two problems of 1 object and 1 generator action."""
    from symlearn.planning.problem_generation import generate_problems

    out = tmp_path_factory.mktemp("faults_processes") / "p"
    generate_problems(out, 2, objects=(1, 1), length=(1, 1), seed=0, sim=sim)
    return out


# ------------------------------------------------------------------------------- 1. signals


@pytest.mark.parametrize("sig", GUARDED, ids=[s.name for s in GUARDED])
def test_planner_guard_leaves_an_ignored_signal_ignored(sig):
    """nohup ignores SIGHUP, a background job SIGINT: the guard must not put a handler in their place."""
    before = {s: signal.getsignal(s) for s in GUARDED}
    signal.signal(sig, signal.SIG_IGN)
    try:
        with planner_guard():
            assert signal.getsignal(sig) == signal.SIG_IGN
            for other in GUARDED:  # the signals not ignored are still guarded
                if other != sig and before[other] != signal.SIG_IGN:
                    assert signal.getsignal(other) != before[other]
        assert signal.getsignal(sig) == signal.SIG_IGN
    finally:
        for s, h in before.items():
            signal.signal(s, h)


SIGHUP_DRIVER = """
import sys
sys.path[:0] = [{repo!r}, {tests!r}]
import signal
signal.signal(signal.SIGHUP, signal.SIG_IGN)  # as under nohup
from pathlib import Path
import search.sas_planners as sp
from pddl_export.enumeration import enumerate_transitions
from pddl_export.distil import distil_rules
from pddl_export.sas_writer import SASEncoder
from test_pddl_export import FAR, NEAR, UNDER, TOY_VOCAB, ToyRobot
rules = distil_rules(enumerate_transitions(ToyRobot(), TOY_VOCAB, max_objects=2))
sp.search_binary = lambda package="": Path({fake!r})
print(sp.solve_sas(SASEncoder(rules), [UNDER, FAR], [NEAR, NEAR], "symk-sas", {timeout}).to_json()["status"],
      flush=True)
"""


def test_sighup_under_nohup_does_not_kill_the_planner(tmp_path):
    """The planner runs on to its own time limit (TIMEOUT), not cut off by the ignored SIGHUP (an ERROR row)."""
    from test_faults_search import _alive, _fake_planner, _start_driver, _wait_dead, _wait_for

    fake = _fake_planner(tmp_path)
    src = SIGHUP_DRIVER.format(repo=str(ROOT), tests=str(ROOT / "tests"), fake=str(fake), timeout=4)
    proc, pids_file, _ = _start_driver(src, tmp_path)
    pids = _wait_for(pids_file, proc)
    os.kill(proc.pid, signal.SIGHUP)
    time.sleep(0.5)
    assert _alive(pids[0]), "the ignored SIGHUP killed the planner"
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err[-2000:]
    assert out.strip().splitlines()[-1] == "timeout"
    assert _wait_dead([pids[0], pids[2]]) == []


def test_a_handler_that_returns_still_ends_the_planner_call(tmp_path):
    """The caller's own SIGTERM handler lets the program go on: the killed planner call raises, it returns nothing."""
    calls: list[int] = []
    before = signal.signal(signal.SIGTERM, lambda signum, frame: calls.append(signum))
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGTERM))
    try:
        with pytest.raises(PlannerInterrupted) as info:
            with planner_guard():
                timer.start()
                run_group([sys.executable, "-c", "import time; time.sleep(60)"], "", 60.0, cwd=tmp_path)
        assert calls == [signal.SIGTERM] and info.value.signum == signal.SIGTERM
    finally:
        timer.cancel()
        signal.signal(signal.SIGTERM, before)


SELF_KILLING_PLANNER = "import os, signal; os.kill(os.getpid(), signal.SIGKILL)\n"


def test_a_planner_killed_from_outside_is_marked_not_a_result(tmp_path, monkeypatch):
    from pddl_export.distil import distil_rules
    from pddl_export.enumeration import enumerate_transitions
    from pddl_export.sas_writer import SASEncoder
    from search.sas_planners import solve_sas
    from test_pddl_export import FAR, NEAR, TOY_VOCAB, UNDER, ToyRobot

    fake = tmp_path / "fake_planner"
    fake.write_text(f"#!{sys.executable}\n" + SELF_KILLING_PLANNER)
    fake.chmod(0o755)
    monkeypatch.setattr("search.sas_planners.search_binary", lambda package="": fake)
    rules = distil_rules(enumerate_transitions(ToyRobot(), TOY_VOCAB, max_objects=2))
    res = solve_sas(SASEncoder(rules), [UNDER, FAR], [NEAR, NEAR], "symk-sas", 20.0)
    assert res.status is PlanStatus.ERROR and res.extra["killed_by_signal"] == signal.SIGKILL, res
    assert "killed by SIGKILL" in res.message


def test_benchmark_never_records_a_planner_killed_by_a_signal(tiny_run, problems, tmp_path, monkeypatch):
    """The row is not saved: the benchmark stops, and the same command again redoes it."""
    import symlearn.planning.benchmark as bm

    real = bm.make_planners

    def killed(transition, start, goal, timeout_s):
        return failed("astar", PlanStatus.ERROR, time.perf_counter(), "killed", killed_by_signal=int(signal.SIGHUP))

    out = tmp_path / "b.json"
    monkeypatch.setattr(bm, "make_planners", lambda names, run, **kw: {"astar": killed})
    with pytest.raises(PlannerInterrupted, match="astar was killed by SIGHUP"):
        bm.benchmark(tiny_run.path, problems, ["astar"], out, timeout_s=10, show_progress=False)
    log = bm.rows_path(out).read_text().splitlines()
    assert len(log) == 1 and json.loads(log[0])["format"] == bm.ROWS_FORMAT  # the settings, no row
    monkeypatch.setattr(bm, "make_planners", real)
    res = bm.benchmark(tiny_run.path, problems, ["astar"], out, timeout_s=10, show_progress=False)
    assert [r["status"] for r in res["rows"]] != ["error", "error"] and len(res["rows"]) == 2
    assert all("killed" not in (r["message"] or "") for r in res["rows"])


# ------------------------------------------------------------------------------- 10. pipeline errors reach the terminal


@pytest.mark.parametrize("flag, value", [("--workers", "0"), ("--shard-size", "0"), ("--seed", "-1"), ("--n", "0"),
                                         ("--problems", "-2"), ("--workers", "two")])
def test_pipeline_bad_flag_is_one_line_and_leaves_nothing(tmp_path, capsys, flag, value):
    out = tmp_path / "pipe"
    with pytest.raises(SystemExit) as info:
        cli("pipeline", "--out", out, f"{flag}={value}")
    err = capsys.readouterr().err.strip().splitlines()
    assert info.value.code == 2 and len(err) == 1 and f"argument {flag}: '{value}'" in err[0], err
    assert not out.exists()


@pytest.mark.parametrize("kw", [dict(workers=0), dict(shard_size=0), dict(seed=-1), dict(workers=1.5), dict(n=0)])
def test_pipeline_settings_refuse_bad_values_before_any_folder(tmp_path, kw):
    from symlearn.pipeline import PipelineSettings

    with pytest.raises(ValueError, match="must be an integer of at least"):
        PipelineSettings(preset="quick", out=tmp_path / "pipe", **kw)
    assert not (tmp_path / "pipe").exists()


def test_a_failing_pipeline_stage_prints_its_reason(tmp_path, capsys):
    out = tmp_path / "pipe"
    out.mkdir()
    (out / "data").write_text("not a folder")  # the collect stage cannot write its data set here
    rc, _ = cli("pipeline", "--out", out, "--n", "4", "--shard-size", "4")
    line = _one_line_error(capsys, "pipeline", "'symlearn collect' exited 2: ", str(out / "data"),
                           str(out / "logs" / "collect.log"))
    assert rc == 2 and line.count("symlearn") == 2, line


def test_a_stage_that_crashes_prints_one_line_and_keeps_the_traceback_in_its_log(tmp_path, capsys, monkeypatch):
    import symlearn.cli.main as main_mod

    def crash(args):
        raise IndexError("index 0 is out of bounds\nfor axis 0")

    monkeypatch.setattr(main_mod, "cmd_collect", crash)
    out = tmp_path / "pipe"
    rc, _ = cli("pipeline", "--out", out, "--n", "4", "--shard-size", "4")
    line = _one_line_error(capsys, "pipeline", "'symlearn collect' failed: IndexError: index 0 is out of bounds; see")
    assert rc == 2 and "for axis 0" not in line
    assert "Traceback (most recent call last)" in (out / "logs" / "collect.log").read_text()
