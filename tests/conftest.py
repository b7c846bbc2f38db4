"""Shared fixtures: one simulator, ONE tiny data set and ONE tiny trained run for the whole session.

The data set and the run are built once, through the `symlearn` CLI (so the fixtures survive moves of
library modules), and their JSON outputs are kept for the tests to check. Nothing here imports the
simulator (pybullet) at module level: the search and PDDL tests run without pybullet installed.
Tests that write into a run (evaluate, symbols, export, plan) take `tiny_run_copy` instead of
writing into the shared one.
"""
from __future__ import annotations

import contextlib
import io
import json
import shutil
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

# The tiny run: a one-epoch quick effect model, a 3-epoch quick transition model, rules for scenes of <= 2 objects
# (the levers that are not flags are in tests/tiny.toml).
TINY_CONFIG = Path(__file__).resolve().parent / "tiny.toml"
TINY_TABLES = tomllib.loads(TINY_CONFIG.read_text())
# The tiny data set: 48 samples in 12 shards (40 train, 4 val, 4 test).
TINY_DATA_ARGS = ("--n", "48", "--seed", "5", "--config", str(TINY_CONFIG))
TINY_TRAIN_ARGS = ("--preset", "quick", "--epochs", "1", "--config", str(TINY_CONFIG))
TINY_TRANSITION_ARGS = ("--preset", "quick", "--seed", "0", "--config", str(TINY_CONFIG))
TINY_EXPORT_ARGS = ("--rules", "--config", str(TINY_CONFIG))


def write_config(path: Path, tables: dict) -> Path:
    """A settings file (--config) at `path` holding `tables` ({table: {key: value}}, a dict value a sub-table) over
    the tiny run's (TINY_TABLES); returns the path."""
    merged = {t: dict(v) for t, v in TINY_TABLES.items()}
    for table, values in tables.items():
        merged.setdefault(table, {}).update(values)

    def lines(name: str, values: dict) -> list[str]:
        plain = [f"{k} = {json.dumps(v)}" for k, v in values.items() if not isinstance(v, dict)]
        subs = [line for k, v in values.items() if isinstance(v, dict) for line in lines(f"{name}.{k}", v)]
        return [f"[{name}]", *plain, *subs]

    path.write_text("\n".join(line for t, v in merged.items() for line in lines(t, v)) + "\n")
    return path


def cli(*args) -> tuple[int, str]:
    """Run `symlearn ARGS` in this process; returns its exit code and what it printed on stdout."""
    from symlearn.cli.main import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main([str(a) for a in args])
    return rc, out.getvalue()


def cli_json(*args) -> dict:
    """Run a `symlearn` command that prints one JSON document, refusing a non-zero exit code."""
    rc, out = cli(*args)
    assert rc == 0, f"symlearn {' '.join(map(str, args))} exited {rc}"
    return json.loads(out)


def recomputed_transition_accuracy(run: Path, data: Path, split: str = "test") -> dict[str, float]:
    """m(z)'s one-step accuracy on a split, recomputed apart from symlearn's metrics code, for checking its reports.

    The split's objects are encoded to integer codes (symlearn.symbolic.symbols.encode_codes), each sample's real
    objects alone (no padding, no mask) go through the run's m(z) as a planner calls it (LearnedTransition on
    codes), and the bits of its predictions are compared here with the bits of the encoded after-codes: bit,
    object (all bits right) and scene (all objects right) accuracy, plus the copy baseline's scene accuracy.
    """
    import numpy as np

    from pddl_export.symbolic import bits_from_codes
    from symlearn.data.dataset import load_split
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.symbols import encode_codes

    reader, transition = planning_models(run)
    d = load_split(data, split)
    before = encode_codes(reader, d.pre_depth, d.pre_origin, d.mask)
    after = encode_codes(reader, d.post_depth, d.post_origin, d.mask)
    bits_ok, objects_ok, scenes_ok, copies_ok = [], [], [], []
    for pre, post, mask, action in zip(before, after, d.mask, d.action):
        pre, post = pre[mask], post[mask]
        pred = transition(pre[None], np.array([int(action)]))[0]
        ok = bits_from_codes(pred, transition.bits) == bits_from_codes(post, transition.bits)  # (k, bits)
        bits_ok.append(ok.ravel())
        objects_ok.append(ok.all(1))
        scenes_ok.append(ok.all())
        copies_ok.append((pre == post).all())
    return {"bit_accuracy": float(np.concatenate(bits_ok).mean()),
            "object_accuracy": float(np.concatenate(objects_ok).mean()),
            "scene_accuracy": float(np.mean(scenes_ok)), "copy_scene_accuracy": float(np.mean(copies_ok)),
            "n": len(scenes_ok)}


@dataclass(frozen=True)
class TinyData:
    """The session's tiny data set and the summary `symlearn collect` printed for it."""

    path: Path
    summary: dict


@dataclass(frozen=True)
class TinyRun:
    """The session's tiny run (best.pt, transition.pt, pddl/), its data set, and the commands' JSON outputs."""

    path: Path
    data: Path
    train: dict  # what `symlearn train` printed
    transition: dict  # what `symlearn train-transition` printed
    export_report: dict  # RUN/pddl/report.json


@pytest.fixture
def tiny_preset(monkeypatch):
    """`--preset tiny`: the demo preset with 1-object problems and a short planner timeout, for the test that asks
    for it (the pipeline tests of test_report and test_faults_resume)."""
    import dataclasses

    from symlearn.pipeline_presets import PRESETS
    from symlearn.planning.execution import EXECUTION_PRESETS

    short = dataclasses.replace(EXECUTION_PRESETS[PRESETS["demo"].execution], timeout_s=2.0)
    monkeypatch.setitem(EXECUTION_PRESETS, "tiny", short)
    tiny = dataclasses.replace(PRESETS["demo"], problem_objects=(1, 1), execution="tiny")
    monkeypatch.setitem(PRESETS, "tiny", tiny)
    return tiny


@pytest.fixture(scope="session")
def sim():
    """One simulator for the session: every scenario rebuilds its own scene."""
    from symlearn.sim.simulator import TabletopSimulator

    s = TabletopSimulator()
    yield s
    s.close()


@pytest.fixture(scope="session")
def tiny_data(tmp_path_factory) -> TinyData:
    """A 48-sample data set collected once per session (read only: copy it before writing into it)."""
    path = tmp_path_factory.mktemp("tiny") / "data"
    summary = cli_json("collect", "--out", path, *TINY_DATA_ARGS, "--quiet")
    return TinyData(path, summary)


@pytest.fixture(scope="session")
def tiny_k45(tmp_path_factory) -> Path:
    """A 16-sample data set of 4-5-object scenes (4 shards), collected once per session (read only)."""
    path = tmp_path_factory.mktemp("tiny_k45") / "k45"
    cli_json("collect", "--out", path, "--n", "16", "--objects", "4-5", "--seed", "5", "--config", TINY_CONFIG, "--quiet")
    return path


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory, tiny_data) -> TinyRun:
    """Effect model, transition network and exported rules trained once per session on tiny_data (read only)."""
    path = tmp_path_factory.mktemp("tiny_run") / "run"
    train = cli_json("train", "--data", tiny_data.path, "--out", path, *TINY_TRAIN_ARGS, "--quiet")
    transition = cli_json("train-transition", "--run", path, "--data", tiny_data.path, *TINY_TRANSITION_ARGS, "--quiet")
    rc, _ = cli("export-pddl", "--run", path, "--data", tiny_data.path, *TINY_EXPORT_ARGS)
    assert rc == 0
    report = json.loads((path / "pddl" / "report.json").read_text())
    return TinyRun(path, tiny_data.path, train, transition, report)


@pytest.fixture
def tiny_run_copy(tiny_run, tmp_path) -> Path:
    """A private copy of the tiny run's directory, for tests that write into a run."""
    dst = tmp_path / "run"
    shutil.copytree(tiny_run.path, dst)
    return dst
