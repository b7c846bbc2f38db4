"""Runs are read-only inputs: `plan` and `benchmark` on the shipped pretrained/recommended, in place or as a read-only
copy, leave every byte of it as it was; the task files go beside the recording or into a removed work folder.

Any write under the run fails loudly while a command runs: the folder is made read-only (chmod), and since root
ignores that, an audit hook also refuses every write, rename, removal or new folder under it in this process.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

import pytest

from conftest import cli

RECOMMENDED = Path(__file__).resolve().parents[1] / "pretrained" / "recommended"
PROBLEM = "tower_of_two"  # two actions; stock Fast Downward and astar-outcomes both build it

_GUARDED: list[str] = []  # folders no write may reach while a command runs (the audit hook below)
_WRITE_FLAGS = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND
_PATH_EVENTS = {"os.mkdir": (0,), "os.remove": (0,), "os.rmdir": (0,), "os.rename": (0, 1), "os.replace": (0, 1),
                "os.chmod": (0,), "os.truncate": (0,), "os.link": (1,), "os.symlink": (1,), "shutil.rmtree": (0,),
                "os.utime": (0,), "os.chown": (0,)}


def _guarded(path) -> bool:
    if not isinstance(path, (str, bytes, os.PathLike)):
        return False  # a file descriptor
    full = os.path.abspath(os.fsdecode(path))
    return any(full == root or full.startswith(root + os.sep) for root in _GUARDED)


def _refuse_writes(event: str, args: tuple) -> None:
    """The audit hook: a PermissionError for any write into a guarded folder (root's writes included)."""
    if not _GUARDED:
        return
    if event == "open" and len(args) >= 3:
        path, mode, flags = args[:3]
        writes = any(c in mode for c in "wax+") if isinstance(mode, str) else bool((flags or 0) & _WRITE_FLAGS)
        if writes and _guarded(path):
            raise PermissionError(f"test_run_readonly: {event} writes {path} inside a run")
    for i in _PATH_EVENTS.get(event, ()):
        if i < len(args) and _guarded(args[i]):
            raise PermissionError(f"test_run_readonly: {event} on {args[i]} inside a run")


sys.addaudithook(_refuse_writes)  # inert while _GUARDED is empty; audit hooks cannot be removed


@contextlib.contextmanager
def no_writes_under(folder: Path):
    """While inside: every write under `folder` in this process raises PermissionError."""
    _GUARDED.append(os.path.abspath(folder))
    try:
        yield
    finally:
        _GUARDED.pop()


def digest(folder: Path) -> dict[str, str]:
    """Every file and folder under `folder`: relative path -> sha256 of its bytes ('dir' for a folder)."""
    return {str(p.relative_to(folder)): "dir" if p.is_dir() else hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*"))}


def _set_writable(folder: Path, writable: bool) -> None:
    """chmod -R a-w (or u+w back) on a folder tree."""
    for p in [folder, *folder.rglob("*")]:
        mode = p.stat().st_mode
        p.chmod(mode | stat.S_IWUSR if writable else mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))


def _work_folders() -> set[Path]:
    return set(Path(tempfile.gettempdir()).glob("symlearn-plan-*"))


def _plan_and_benchmark(run: Path, tmp_path: Path) -> None:
    """`symlearn plan` with stock Fast Downward on the lifted domain (recorded) and with astar-outcomes (the
    learned-net family, not recorded), then a tiny `symlearn benchmark` of both; each must succeed."""
    problem = run / "problems" / f"{PROBLEM}.json"
    gif = tmp_path / "rec" / "plan.gif"
    rc, out = cli("plan", "--run", run, "--problem", problem, "--planner", "fast-downward-lifted", "--record", gif)
    assert rc == 0 and "success True" in out, out
    tasks = tmp_path / "rec" / "plan_tasks"  # kept beside the recording: the domain it ran and the problem
    assert f"wrote {tasks / 'problem.pddl'}" in out
    assert (tasks / "domain.pddl").read_text() == (RECOMMENDED / "pddl" / "lifted" / "domain.pddl").read_text()
    assert (tasks / "problem.pddl").read_text().startswith("(define (problem")
    assert sorted(p.name for p in tasks.iterdir()) == ["domain.pddl", "problem.pddl"]

    before = _work_folders()
    rc, out = cli("plan", "--run", run, "--problem", problem, "--planner", "astar-outcomes")
    assert rc == 0 and "success True" in out and "wrote" not in out, out
    assert _work_folders() == before  # its work folder is gone

    problems = tmp_path / "problems"
    problems.mkdir()
    shutil.copy(problem, problems)
    result = tmp_path / "bench" / "b.json"
    rc, out = cli("benchmark", "--run", run, "--problems", problems, "--planners",
                  "fast-downward-lifted,astar-outcomes", "--timeout", "20", "--out", result)
    assert rc == 0 and result.is_file(), out
    assert sorted(p.name for p in result.parent.iterdir()) == ["b.json"]  # no log, lock or task left behind


def test_planning_on_the_shipped_run_in_place_leaves_it_byte_identical(tmp_path):
    before = digest(RECOMMENDED)
    with no_writes_under(RECOMMENDED):
        _plan_and_benchmark(RECOMMENDED, tmp_path)
    assert digest(RECOMMENDED) == before


def test_planning_on_a_read_only_copy_works_and_leaves_it_byte_identical(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(RECOMMENDED, run)
    before = digest(run)
    _set_writable(run, False)
    try:
        with no_writes_under(run):
            _plan_and_benchmark(run, tmp_path / "out")
    finally:
        _set_writable(run, True)
    assert digest(run) == before == digest(RECOMMENDED)


def test_the_guard_itself_refuses_writes_into_the_run(tmp_path):
    """The guard fails loudly (as a write a planner made into the run would) and lets reads through."""
    run = tmp_path / "run"
    run.mkdir()
    (run / "a.txt").write_text("x")
    with no_writes_under(run):
        assert (run / "a.txt").read_text() == "x"
        for write in (lambda: (run / "b.txt").write_text("y"), lambda: (run / "pddl").mkdir(),
                      lambda: os.replace(run / "a.txt", run / "c.txt"), lambda: (run / "a.txt").unlink()):
            with pytest.raises(PermissionError, match="inside a run"):
                write()
    assert digest(run) == {"a.txt": hashlib.sha256(b"x").hexdigest()}


def _plan_recorded(planner: str, gif: Path) -> tuple[int, str]:
    """`symlearn plan` on the shipped run itself with `planner`, recorded to `gif`; any write under the run raises."""
    with no_writes_under(RECOMMENDED):
        return cli("plan", "--run", RECOMMENDED, "--problem", RECOMMENDED / "problems" / f"{PROBLEM}.json",
                   "--planner", planner, "--record", gif)


def test_a_task_folder_beside_the_recording_holding_other_files_is_refused_before_any_work(tmp_path, capsys):
    tasks = tmp_path / "plan_tasks"
    tasks.mkdir()
    (tasks / "notes.txt").write_text("mine")
    rc, out = _plan_recorded("fast-downward-lifted", tmp_path / "plan.gif")
    err = capsys.readouterr().err.strip()
    assert rc == 2 and out == "" and len(err.splitlines()) == 1, err
    assert f"--record's task folder {tasks} holds notes.txt" in err and "refusing to replace it" in err
    assert (tasks / "notes.txt").read_text() == "mine" and not (tmp_path / "plan.gif").exists()


def test_the_run_refuses_a_lifted_domain_of_another_transition_model(tmp_path):
    """Run's hash check: a lifted.json whose model_hash is not transition.pt's is named, in one line."""
    from pddl_export.bounded_json import read_json_file
    from pddl_export.files import atomic_write_json
    from symlearn.planning.run_folder import Run

    run = tmp_path / "run"
    shutil.copytree(RECOMMENDED, run)
    lifted = read_json_file(run / "pddl" / "lifted.json", what="lifted rules")
    lifted["model_hash"] = "0" * 16
    atomic_write_json(run / "pddl" / "lifted.json", lifted)
    with pytest.raises(ValueError, match=r"lifted\.json was exported from another transition\.pt") as e:
        Run(run).lifted()
    assert "\n" not in str(e.value) and Run(RECOMMENDED).lifted().model_hash == Run(RECOMMENDED).transition_hash()


def test_one_guarded_loader_refuses_each_kind_of_checkpoint_given_for_the_other():
    """best.pt and transition.pt go through the one guarded loader, each refused where the other is expected."""
    from symlearn.learning.checkpoint import CheckpointError, load_checkpoint
    from symlearn.symbolic.transition_checkpoint import TransitionError, load_transition

    with pytest.raises(CheckpointError, match="is not a symlearn effect-model checkpoint"):
        load_checkpoint(RECOMMENDED / "transition.pt")
    with pytest.raises(TransitionError, match="is not a symlearn transition-model checkpoint"):
        load_transition(RECOMMENDED / "best.pt")
    with pytest.raises(TransitionError, match="no transition model at .*; run 'symlearn train-transition' first"):
        load_transition(RECOMMENDED / "missing.pt")


def test_the_docs_and_examples_no_longer_ask_for_a_copy_of_the_run():
    """README and the shipped run's README plan on pretrained/recommended itself; no example copies a run."""
    root = RECOMMENDED.parents[1]
    for readme in (root / "README.md", RECOMMENDED / "README.md"):
        text = readme.read_text()
        assert "copy" not in text.lower() and "cp -r" not in text, readme
        assert "plan --run pretrained/recommended" in text, readme
    for example in sorted((root / "examples").glob("*.py")):
        assert "copytree" not in example.read_text(), example


def test_a_recorded_plan_that_writes_no_task_drops_an_earlier_plans_task_folder(tmp_path):
    """The task folder beside a GIF is that plan's: astar-outcomes writes none, so an earlier one is not left there."""
    tasks = tmp_path / "plan_tasks"
    tasks.mkdir()
    (tasks / "problem.pddl").write_text("(define (problem old))")
    rc, out = _plan_recorded("astar-outcomes", tmp_path / "plan.gif")
    assert rc == 0 and "success True" in out and "problem.pddl" not in out, out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.gif", "plan.png"]
