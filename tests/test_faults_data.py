"""Fault probes of collection, data sets, checkpoints and training: kills, bad files, bad flags, wrong folders.

Every probe reproduces a defect a reliability review found, and checks the real behaviour: the
processes alive after a real signal, the files left in the folder, the one-line refusal and its
exit code, the numbers in the JSON written.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import cli

REPO = Path(__file__).resolve().parents[1]
# 24 shards of 2 samples: long enough for a kill to land in the middle with two workers.
FAULTS_CONFIG = Path(__file__).resolve().parent / "faults.toml"  # shards of 2; small training runs
COLLECT_ARGS = ("--n", "48", "--config", str(FAULTS_CONFIG), "--seed", "7", "--quiet")


# ----------------------------------------------------------------------------------------------
# helpers


def _session_processes(sid: int) -> list[tuple[int, str]]:
    """(pid, command) of every live (not zombie) process in session `sid`, from /proc."""
    found = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
            cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        state, session = fields[0], int(fields[3])
        if session == sid and state != "Z":
            found.append((int(d.name), cmd))
    return found


def _wait_until(cond, timeout: float, step: float = 0.05) -> bool:
    """Poll `cond` until true or `timeout` seconds passed; returns its last value."""
    end = time.monotonic() + timeout
    while True:
        value = cond()
        if value or time.monotonic() > end:
            return value
        time.sleep(step)


def _env(tmpdir: Path) -> dict:
    """Environment of a CLI subprocess: this checkout first on the path, a private TMPDIR, one thread."""
    tmpdir.mkdir(exist_ok=True)
    return {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(tmpdir), "OMP_NUM_THREADS": "1"}


def _default_signals() -> None:
    """In the child: SIGINT and SIGTERM as a user's terminal gives them. A suite started in the background (`cmd &`)
    hands its children SIGINT ignored, and collect keeps an ignored signal ignored (docs/RELIABILITY.md)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _start_collect(out: Path, tmpdir: Path, stderr_path: Path) -> subprocess.Popen:
    """`symlearn collect` with two workers, in a new session, stderr to a file."""
    return subprocess.Popen([sys.executable, "-m", "symlearn.cli.main", "collect", "--out", str(out), *COLLECT_ARGS,
                             "--workers", "2"],
                            start_new_session=True, env=_env(tmpdir), cwd=REPO, stdout=subprocess.DEVNULL,
                            stderr=stderr_path.open("w"), preexec_fn=_default_signals)


def _temp_files(folder: Path) -> list[str]:
    """Names of hidden temp files (of the manifest or of shards) in a folder."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".") and "tmp" in p.name)


@pytest.fixture
def sessions():
    """Session ids of the subprocesses a test starts; whatever of them is still alive at its end is killed."""
    started: list[int] = []
    yield started
    for sid in started:
        for pid, _ in _session_processes(sid):
            os.kill(pid, signal.SIGKILL)


def _kill_mid_collection(tmp_path: Path, sig: int, sessions: list) -> tuple[subprocess.Popen, Path, Path]:
    """Start a collection, wait for its first shard, send `sig` to the parent only and reap it."""
    out, tmpdir, err = tmp_path / "data", tmp_path / "tmp", tmp_path / "stderr.txt"
    proc = _start_collect(out, tmpdir, err)
    sessions.append(proc.pid)
    try:
        assert _wait_until(lambda: any(out.glob("shard_*.npz")), 120), err.read_text()
        os.kill(proc.pid, sig)
        proc.wait(timeout=20)
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    return proc, out, tmpdir


def _resume_and_load(out: Path) -> None:
    """Re-running the same collection finishes it and the whole data set loads, 48 samples."""
    from symlearn.data.dataset import load_manifest, load_split

    rc, _ = cli("collect", "--out", out, *COLLECT_ARGS)  # in this process, one worker: the settings are the same
    assert rc == 0
    assert load_manifest(out)["complete"] and len(load_split(out, "all")) == 48
    assert _temp_files(out) == []


# ----------------------------------------------------------------------------------------------
# 1. killed collections leave no process, no temp folder, no temp file; the resume completes


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_to_collect_parent_ends_everything(tmp_path, sig, sessions):
    proc, out, tmpdir = _kill_mid_collection(tmp_path, sig, sessions)
    err = (tmp_path / "stderr.txt").read_text().strip().splitlines()
    assert proc.returncode in (128 + sig, 130), err
    assert err[-1].startswith("symlearn collect: interrupted") and "Traceback" not in "\n".join(err)
    left = _wait_until(lambda: not _session_processes(proc.pid), 5) or _session_processes(proc.pid)
    assert left is True, f"processes left after the parent ended: {left}"
    assert sorted(p.name for p in tmpdir.iterdir()) == [], "multiprocessing left its temp folder"
    assert _temp_files(out) == []
    shards = sorted(p.name for p in out.glob("shard_*.npz"))
    time.sleep(1.0)
    assert sorted(p.name for p in out.glob("shard_*.npz")) == shards, "shards written after the parent died"
    m = json.loads((out / "manifest.json").read_text())
    assert not m["complete"] and len(m["shards"]) < 24
    _resume_and_load(out)


def test_sigkill_of_collect_parent_stops_workers_and_resume_removes_temp_files(tmp_path, sessions):
    proc, out, tmpdir = _kill_mid_collection(tmp_path, signal.SIGKILL, sessions)
    assert proc.returncode == -signal.SIGKILL
    left = _wait_until(lambda: not _session_processes(proc.pid), 8) or _session_processes(proc.pid)
    assert left is True, f"workers outlived a killed parent: {left}"
    # What a kill in the middle of a write leaves: temp files of the manifest (old and mkstemp style) and of shards.
    stale = [".manifest.json.tmp4242", ".manifest.json.k2j4x9.tmp", ".shard_00023.tmp4242.npz",
             ".shard_00023.npz.a8f3kq.tmp"]
    for name in stale:
        (out / name).write_bytes(b"half")
    _resume_and_load(out)


# ----------------------------------------------------------------------------------------------
# 2. damaged manifests and checkpoints: one line naming the file, no traceback

RUN_ARGS = ("--preset", "quick", "--epochs", "1", "--config", FAULTS_CONFIG, "--quiet")


def _error_line(capsys, command: str, rc: int) -> str:
    """The refusal of a CLI command: exit code 2, no traceback, its last stderr line says 'symlearn CMD: error: ...'."""
    lines = capsys.readouterr().err.strip().splitlines()
    assert rc == 2, lines
    assert "Traceback" not in "\n".join(lines) and len(lines) <= 2, lines  # at most the command's info line first
    assert lines[-1].startswith(f"symlearn {command}: error: "), lines
    return lines[-1]


@pytest.fixture
def data_copy(tiny_data, tmp_path) -> Path:
    """A writable copy of the session's tiny data set."""
    dst = tmp_path / "data"
    shutil.copytree(tiny_data.path, dst)
    return dst


@pytest.fixture(scope="module")
def effect_run(tiny_data, tmp_path_factory) -> Path:
    """A one-epoch effect model on 16 samples of the tiny data set (read only)."""
    run = tmp_path_factory.mktemp("faults") / "run"
    rc, _ = cli("train", "--data", tiny_data.path, "--out", run, *RUN_ARGS)
    assert rc == 0
    return run


MANIFEST_DAMAGE = {
    "no shards": lambda m: m.pop("shards"),
    "shards not a list": lambda m: m.update(shards={"shard_00000.npz": {}}),
    "entry without name": lambda m: m["shards"][0].pop("name"),
    "entry without sha256": lambda m: m["shards"][3].pop("sha256"),
    "entry not an object": lambda m: m["shards"].__setitem__(2, "shard_00002.npz"),
    "name outside the folder": lambda m: m["shards"][0].update(name="../elsewhere.npz"),
}


@pytest.mark.parametrize("command", ["train", "collect"])
@pytest.mark.parametrize("damage", list(MANIFEST_DAMAGE))
def test_damaged_manifest_is_one_line_error(data_copy, tmp_path, capsys, damage, command):
    """A manifest whose shard list is missing or malformed: one line naming manifest.json, nothing written."""
    from conftest import TINY_DATA_ARGS

    mpath = data_copy / "manifest.json"
    m = json.loads(mpath.read_text())
    MANIFEST_DAMAGE[damage](m)
    mpath.write_text(json.dumps(m))
    before = sorted(p.name for p in data_copy.iterdir())
    if command == "train":
        rc, _ = cli("train", "--data", data_copy, "--out", tmp_path / "run", *RUN_ARGS)
    else:
        rc, _ = cli("collect", "--out", data_copy, *TINY_DATA_ARGS, "--quiet")
    line = _error_line(capsys, command, rc)
    assert str(mpath) in line and ("shard" in line)
    assert not (tmp_path / "run").exists() and sorted(p.name for p in data_copy.iterdir()) == before
    assert json.loads(mpath.read_text()) == m  # the refusal rewrote nothing


def _edit_blob(path: Path, edit) -> None:
    import torch

    blob = torch.load(path, map_location="cpu", weights_only=True)
    edit(blob)
    torch.save(blob, path)


def _other_width(blob: dict) -> None:
    cfg = json.loads(blob["config"])
    cfg["decoder_hidden"] = [32, 32, 32]
    cfg["n_layers"] += 1
    blob["config"] = json.dumps(cfg)


CHECKPOINT_DAMAGE = {
    "0 bytes": (lambda p: p.write_bytes(b""), "not a readable checkpoint"),
    "truncated": (lambda p: p.write_bytes(p.read_bytes()[:1000]), "not a readable checkpoint"),
    "no config": (lambda p: _edit_blob(p, lambda b: b.pop("config")), "field 'config' missing"),
    "config not JSON": (lambda p: _edit_blob(p, lambda b: b.update(config="{")), "damaged checkpoint"),
    "weights of another config": (lambda p: _edit_blob(p, _other_width), "weights do not fit"),
}


@pytest.mark.parametrize("damage", list(CHECKPOINT_DAMAGE))
def test_damaged_checkpoint_is_one_line_error(effect_run, tmp_path, capsys, damage):
    run = tmp_path / "run"
    shutil.copytree(effect_run, run)
    edit, expected = CHECKPOINT_DAMAGE[damage]
    edit(run / "best.pt")
    rc, _ = cli("table1", "--run", run)
    line = _error_line(capsys, "table1", rc)
    assert str(run / "best.pt") in line and expected in line, line
    if damage == "weights of another config":  # the first mismatching keys, named
        assert "missing attn.layers." in line and "shape differs decoder." in line, line
    assert not (run / "table1.json").exists()


# ----------------------------------------------------------------------------------------------
# 3. bad flag values: refused by argparse (exit code 2, one line) before anything is written

BAD_TRAIN_FLAGS = [("--epochs", "0"), ("--epochs", "-1"), ("--seed", "-1"), ("--threads", "0"), ("--epochs", "1.5")]
BAD_TRAIN_SETTINGS = [("batch_size", "0"), ("batch_size", "-2"), ("max_train_samples", "0"), ("max_train_samples", "-5"),
                      ("lr", "inf"), ("lr", "nan"), ("lr", "0"), ("lr", "-1e-3"), ("batch_size", "1.5"),
                      ("lr", "'fast'")]
BAD_COLLECT_FLAGS = [("--seed", "-1"), ("--n", "0"), ("--n", "-12"), ("--workers", "0")]


def _argparse_refusal(capsys, args: list) -> str:
    with pytest.raises(SystemExit) as exc:
        cli(*args)
    lines = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(lines) == 1, lines  # no usage block, no traceback
    return lines[0]


@pytest.mark.parametrize("flag,value", BAD_TRAIN_FLAGS, ids=[f"{f}={v}" for f, v in BAD_TRAIN_FLAGS])
def test_bad_train_flag_refused(tiny_data, tmp_path, capsys, flag, value):
    run = tmp_path / "run"
    line = _argparse_refusal(capsys, ["train", "--data", tiny_data.path, "--out", run, "--preset", "quick",
                                      "--quiet", f"{flag}={value}"])
    assert line.startswith("symlearn train: error: argument") and flag in line and repr(value) in line, line
    assert not run.exists()


@pytest.mark.parametrize("key,value", BAD_TRAIN_SETTINGS, ids=[f"{k}={v}" for k, v in BAD_TRAIN_SETTINGS])
def test_bad_train_setting_refused(tiny_data, tmp_path, capsys, key, value):
    """A bad value in --config's [train] table: one line naming the setting, before any folder is made."""
    run, config = tmp_path / "run", tmp_path / "bad.toml"
    config.write_text(f"[train]\n{key} = {value}\n")
    rc, _ = cli("train", "--data", tiny_data.path, "--out", run, "--preset", "quick", "--config", config, "--quiet")
    line = _error_line(capsys, "train", rc)
    assert key in line, line
    assert not run.exists()


@pytest.mark.parametrize("flag,value", BAD_COLLECT_FLAGS, ids=[f"{f}={v}" for f, v in BAD_COLLECT_FLAGS])
def test_bad_collect_flag_refused(tmp_path, capsys, flag, value):
    out = tmp_path / "data"
    args = {"--n": "24", "--config": str(FAULTS_CONFIG), "--seed": "0", **{flag: value}}
    line = _argparse_refusal(capsys, ["collect", "--out", out, "--quiet", *[x for kv in args.items() for x in kv]])
    assert line.startswith("symlearn collect: error: argument") and flag in line and repr(value) in line, line
    assert not out.exists()  # so a later `--seed 0` in this folder is not blocked by a manifest of seed -1


@pytest.mark.parametrize("kw", [dict(epochs=0), dict(epochs=-1), dict(batch_size=0), dict(batch_size=-2),
                                dict(max_train_samples=0), dict(max_train_samples=-5), dict(lr=float("inf")),
                                dict(lr=float("nan")), dict(lr=0.0), dict(seed=-1), dict(weight_decay=float("nan")),
                                dict(lr_min_ratio=1.5), dict(epochs=True)], ids=str)
def test_train_config_refuses_bad_values(kw):
    from symlearn.learning.training import TrainConfig

    name = next(iter(kw))
    with pytest.raises(ValueError, match=f"train config: {name}="):
        TrainConfig.from_preset("quick", **kw)


@pytest.mark.parametrize("kw", [dict(seed=-1), dict(n=0), dict(shard_size=0), dict(shard_size=2.5), dict(seed=1.0)],
                         ids=str)
def test_collect_config_refuses_bad_values(kw):
    from symlearn.sim.collect import CollectConfig, CollectError

    with pytest.raises(CollectError, match=f"{next(iter(kw))}="):
        CollectConfig(**{"n": 24, "shard_size": 2, **kw})


@pytest.mark.parametrize("command", ["train", "collect"])
def test_manifest_not_an_object_is_one_line_error(data_copy, tmp_path, capsys, command):
    from conftest import TINY_DATA_ARGS

    (data_copy / "manifest.json").write_text("[1, 2]")
    if command == "train":
        rc, _ = cli("train", "--data", data_copy, "--out", tmp_path / "run", *RUN_ARGS)
    else:
        rc, _ = cli("collect", "--out", data_copy, *TINY_DATA_ARGS, "--quiet")
    line = _error_line(capsys, command, rc)
    assert "manifest.json" in line and str(data_copy) in line, line
    assert (data_copy / "manifest.json").read_text() == "[1, 2]" and not (tmp_path / "run").exists()


def test_diverging_training_is_refused_and_leaves_no_run_folder(tiny_data, tmp_path, capsys):
    run = tmp_path / "run"
    (tmp_path / "lr.toml").write_text("[train]\nbatch_size = 4\nmax_train_samples = 16\nbf16 = false\nlr = 1e30\n")
    rc, out = cli("train", "--data", tiny_data.path, "--out", run, "--preset", "quick", "--epochs", "1",
                  "--config", tmp_path / "lr.toml", "--quiet")
    line = _error_line(capsys, "train", rc)
    assert "loss became" in line and "lower the learning rate" in line, line
    assert out == "" and not run.exists()


# ----------------------------------------------------------------------------------------------
# 4. a run folder and a data set folder are never the same folder


@pytest.mark.parametrize("spelling", ["same", "dotted"])
def test_train_into_a_data_set_folder_refused(data_copy, capsys, spelling):
    out = data_copy if spelling == "same" else data_copy / ".." / data_copy.name
    before = {p.name: p.stat().st_mtime_ns for p in data_copy.iterdir()}
    rc, _ = cli("train", "--data", data_copy, "--out", out, *RUN_ARGS)
    line = _error_line(capsys, "train", rc)
    assert "data set" in line and str(out) in line, line
    assert {p.name: p.stat().st_mtime_ns for p in data_copy.iterdir()} == before


def test_train_into_another_data_set_folder_refused(data_copy, tiny_data, capsys):
    rc, _ = cli("train", "--data", tiny_data.path, "--out", data_copy, *RUN_ARGS)
    line = _error_line(capsys, "train", rc)
    assert f"holds a symlearn data set ({data_copy / 'manifest.json'})" in line, line
    assert not list(data_copy.glob("*.pt")) and not (data_copy / "config.json").exists()


def test_collect_into_a_run_folder_refused(effect_run, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(effect_run, run)
    before = {p.name: p.stat().st_mtime_ns for p in run.iterdir()}
    rc, _ = cli("collect", "--out", run, "--n", "24", "--config", FAULTS_CONFIG, "--quiet")
    line = _error_line(capsys, "collect", rc)
    assert f"{run} is a training run folder" in line, line
    assert {p.name: p.stat().st_mtime_ns for p in run.iterdir()} == before


# ----------------------------------------------------------------------------------------------
# 5. strict JSON only: no NaN or Infinity in what training writes or prints


def _strict(text: str):
    def refuse(name):
        raise ValueError(f"non-strict JSON constant {name}")

    return json.loads(text, parse_constant=refuse)


def test_training_writes_and_prints_strict_json(effect_run, tiny_data, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(effect_run, run)
    for name in ("config.json", "metrics.json"):
        _strict((run / name).read_text())
    best = _strict((run / "metrics.json").read_text())["best_val_loss"]
    assert isinstance(best, float) and 0 < best < 100
    rc, out = cli("train", "--data", tiny_data.path, "--out", run, *RUN_ARGS)  # resumed: no epoch left to run
    assert rc == 0 and _strict(out)["best_val_loss"] == pytest.approx(best)


def test_finite_or_none_and_checkpoints_refuse_nan():
    import math

    from symlearn.learning.checkpoint import save_checkpoint
    from symlearn.learning.models import AttentiveDeepSym, ModelConfig
    from symlearn.learning.training import finite_or_none

    assert finite_or_none(math.inf) is None and finite_or_none(math.nan) is None and finite_or_none(0.5) == 0.5
    model = AttentiveDeepSym(ModelConfig.from_preset("quick"))
    with pytest.raises(ValueError, match="Out of range float"):
        save_checkpoint(Path("/nonexistent/never.pt"), model=model, history=[{"val_loss": math.nan}])
