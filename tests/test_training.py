import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from symlearn.learning.checkpoint import CheckpointError, load_checkpoint, load_effect_model, save_checkpoint
from symlearn.learning.models import AttentiveDeepSym, ModelConfig
from symlearn.learning.training import TrainConfig, TrainingError, train

TINY = dict(epochs=2, batch_size=8, bf16=False)


@pytest.fixture(scope="module")
def data(tiny_data):
    """The session's tiny data set (48 samples)."""
    return tiny_data.path


def _weights(run):
    model, _ = load_effect_model(run, "last")
    return torch.cat([p.flatten() for p in model.state_dict().values() if p.is_floating_point()])


def test_quick_training_writes_run_files(data, tmp_path):
    run = tmp_path / "run"
    out = train(data, run, TrainConfig.from_preset("quick", **TINY), show_progress=False)
    assert len(out["history"]) == 2
    m = json.loads((run / "metrics.json").read_text())
    assert set(m["history"][0]) >= {"train_loss", "val_loss", "val_mae_mm", "crops_per_s"}
    # best.pt holds the epoch of the lowest validation loss, last.pt the last epoch, both with that history
    val = [h["val_loss"] for h in m["history"]]
    best = load_checkpoint(run / "best.pt")
    assert best.epoch == int(np.argmin(val)) and best.best_val == pytest.approx(min(val), abs=1e-5)
    assert m["best_val_loss"] == out["best_val_loss"] == pytest.approx(min(val), abs=1e-5)
    assert [h["epoch"] for h in load_checkpoint(run / "last.pt").history] == [1, 2]
    cfg = json.loads((run / "config.json").read_text())
    assert cfg["train_config"]["preset"] == "quick" and "torch" in cfg["versions"] and cfg["data_fingerprint"]
    ck = load_checkpoint(run / "last.pt")
    assert ck.epoch == 1 and ck.effect_std.shape == (3,) and ck.effect_std.min() > 0


def test_resume_equals_uninterrupted(data, tmp_path):
    cfg2 = TrainConfig.from_preset("quick", **TINY)
    train(data, tmp_path / "a", cfg2, show_progress=False)
    train(data, tmp_path / "b", TrainConfig.from_preset("quick", **{**TINY, "epochs": 1}), show_progress=False)
    out = train(data, tmp_path / "b", cfg2, show_progress=False)  # resumes at epoch 2
    assert [h["epoch"] for h in out["history"]] == [1, 2]
    torch.testing.assert_close(_weights(tmp_path / "a"), _weights(tmp_path / "b"))


def test_resume_refuses_other_settings(data, tmp_path):
    train(data, tmp_path / "r", TrainConfig.from_preset("quick", **{**TINY, "epochs": 1}), show_progress=False)
    with pytest.raises((TrainingError, CheckpointError), match="other"):
        train(data, tmp_path / "r", TrainConfig.from_preset("quick", **{**TINY, "lr": 0.5}), show_progress=False)


def test_nan_loss_stops_with_step(data, tmp_path, monkeypatch):
    import symlearn.learning.training as tr

    monkeypatch.setattr(tr, "masked_mse", lambda *a: torch.tensor(float("nan")))
    with pytest.raises(TrainingError, match="epoch 1, step 1"):
        train(data, tmp_path / "nan", TrainConfig.from_preset("quick", **TINY), show_progress=False)


def test_checkpoint_round_trip_and_refusals(tmp_path):
    model = AttentiveDeepSym(ModelConfig.from_preset("quick"))
    save_checkpoint(tmp_path / "c.pt", model=model, epoch=3, effect_std=[1, 2, 3])
    ck = load_checkpoint(tmp_path / "c.pt")
    assert ck.epoch == 3 and ck.config == model.cfg and ck.effect_std.tolist() == [1, 2, 3]
    for k, v in model.state_dict().items():
        torch.testing.assert_close(ck.model_state[k], v)
    with pytest.raises(CheckpointError, match="another model config"):
        load_checkpoint(tmp_path / "c.pt", expect_config=ModelConfig.from_preset("paper"))
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint at all")
    with pytest.raises(CheckpointError, match="not a readable checkpoint"):
        load_checkpoint(tmp_path / "junk.pt")
    torch.save({"weights": torch.zeros(2)}, tmp_path / "foreign.pt")
    with pytest.raises(CheckpointError, match="not a symlearn"):
        load_checkpoint(tmp_path / "foreign.pt")
    blob = torch.load(tmp_path / "c.pt", weights_only=True)
    blob["format_version"] = 99
    torch.save(blob, tmp_path / "old.pt")
    with pytest.raises(CheckpointError, match="format 99"):
        load_checkpoint(tmp_path / "old.pt")
    with pytest.raises(CheckpointError, match="no checkpoint"):
        load_effect_model(tmp_path / "missing")


def _batch4(tmp_path: Path) -> Path:
    """A settings file: batches of 4 scenes in float32."""
    path = tmp_path / "batch4.toml"
    path.write_text("[train]\nbatch_size = 4\nbf16 = false\n")
    return path


def test_two_process_ddp_ends_with_identical_weights(data, tmp_path):
    run, logs = tmp_path / "ddp", tmp_path / "rank_logs"
    # each rank's stderr goes to a file of its own (--redirects 2), so that a rank that dies says why in the
    # failure message; the launcher's stderr alone had only the other rank's SIGTERM
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node=2", "--log-dir", str(logs),
           "--redirects", "2", "-m", "symlearn.cli.main", "train", "--data", str(data), "--out", str(run),
           "--preset", "quick", "--epochs", "1", "--config", str(_batch4(tmp_path)), "--quiet"]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    ranks = "".join(f"\n--- {f.relative_to(logs)} ---\n{f.read_text()[-3000:]}"
                    for f in sorted(logs.rglob("stderr.log")))
    assert r.returncode == 0, r.stderr[-2000:] + ranks
    m = json.loads((run / "metrics.json").read_text())
    assert m["world_size"] == 2 and m["ranks_identical"] is True


def _two_node_launch(data, tmp_path: Path, attempt: int) -> tuple[bool, list[str], Path]:
    """One try of docs/SCALING.md's two-node command on this machine: (every launcher that ended by itself
    succeeded and one did, the launchers' last log lines, the run folder)."""
    import os
    import socket

    with socket.socket() as s:  # a free port for the rendezvous
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    run = tmp_path / f"two_nodes_{attempt}"
    cmd = [sys.executable, "-m", "torch.distributed.run", "--nnodes", "2", "--nproc-per-node", "1",
           "--rdzv-backend", "c10d", "--rdzv-endpoint", f"127.0.0.1:{port}", "--rdzv-id", f"test-two-nodes-{attempt}",
           "-m", "symlearn.cli", "train", "--data", str(data), "--out", str(run), "--preset", "quick",
           "--epochs", "1", "--config", str(_batch4(tmp_path)), "--quiet"]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    # the first launcher hosts the rendezvous store: the second starts once it listens (both started at once on
    # one machine, both may try to host it, and the loser can hang in the rendezvous)
    logs = [tmp_path / f"node{i}_{attempt}.log" for i in range(2)]  # files, not pipes: nothing blocks on a full pipe
    nodes = [subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=logs[0].open("w"), env=env)]
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and nodes[0].poll() is None:
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                break
        time.sleep(0.2)
    nodes.append(subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=logs[1].open("w"), env=env))
    # A launcher that hosts the rendezvous store was once seen waiting at exit, after training had finished, for a
    # peer that had already left (torch's elastic agent, both "nodes" on one loaded machine). Once one launcher has
    # ended cleanly and the run's metrics are written, the other gets 60 s before it is ended; every launcher that
    # ended by itself must have succeeded.
    deadline, grace = time.monotonic() + 150, None  # alone it takes 12 s
    try:
        while any(n.poll() is None for n in nodes) and time.monotonic() < deadline:
            if grace is None and any(n.poll() == 0 for n in nodes) and (run / "metrics.json").is_file():
                grace = time.monotonic() + 60
            if grace is not None and time.monotonic() > grace:
                break
            time.sleep(0.2)
        ended = [n.poll() is not None for n in nodes]
    finally:
        for n in nodes:
            if n.poll() is None:
                n.kill()
                n.wait()
    ok = any(ended) and all(n.returncode == 0 for n, e in zip(nodes, ended) if e)
    return ok, [log.read_text()[-2000:] for log in logs], run


def test_two_nodes_by_rendezvous_train_one_run(data, tmp_path):
    """docs/SCALING.md's two-node command, both "nodes" on this machine: one torchrun launcher per node,
    joined by a c10d rendezvous, one process each, writing one shared run. torch's elastic agent, both nodes on
    one loaded 2-core machine, once aborted a worker (SIGABRT) in a fresh-clone run that passes alone in 12 s:
    the command gets a second try, and the second must succeed."""
    ok, errs, run = _two_node_launch(data, tmp_path, 0)
    if not ok:
        ok, errs_again, run = _two_node_launch(data, tmp_path, 1)
        errs = errs + errs_again
    assert ok, errs
    m = json.loads((run / "metrics.json").read_text())
    assert m["world_size"] == 2 and m["ranks_identical"] is True


def test_rider_weights_mark_exactly_the_riders(tiny_data):
    import dataclasses

    from symlearn.data.dataset import load_split
    from symlearn.data.statistics import rider_mask
    from symlearn.learning.training import effect_normalization, to_tensors

    d = load_split(data_path := tiny_data.path, "train")
    # make object 1 of every two-object scene a rider: object 0 held, object 1 carried 10 cm along y
    two = np.flatnonzero(d.n_objects >= 2)
    grasped, effect = d.grasped.copy(), d.effect.copy()
    grasped[two] = 0
    effect[two, 1] = [0.0, 0.1, 0.0]
    d = dataclasses.replace(d, grasped=grasped, effect=effect)
    riders = rider_mask(d)
    assert len(two) > 0 and riders[two, 1].all() and not riders[:, 0].any(), data_path
    mean, std = effect_normalization(d)
    t = to_tensors(d, mean, std, rider_weight=5.0, with_post=True)
    assert np.array_equal(t.weight.numpy(), np.where(riders, 5.0, 1.0))
    assert to_tensors(d, mean, std).weight is None and to_tensors(d, mean, std).post_depth is None
    from symlearn.data.statistics import still_mask
    assert np.array_equal(t.still.numpy(), still_mask(d)) and not (t.still.numpy() & riders).any()
    assert t.post_crops(torch.arange(3)).shape == t.batch(torch.arange(3))[0].shape


def test_rider_scenes_are_drawn_as_often_as_asked(data, monkeypatch):
    """rider_scene_repeat = 3: a scene holding a rider is drawn three times an epoch, every other scene once; with 1
    the epoch's order is the plain index, so runs without the lever shuffle as they always did."""
    import symlearn.learning.training as training

    marked = lambda d: np.arange(len(d.mask))[:, None] % 5 == 0  # noqa: E731  (every fifth scene "has a rider")
    monkeypatch.setattr(training, "rider_mask", marked)
    cfg = TrainConfig.from_preset("quick", **TINY, rider_scene_repeat=3)
    tr, _, _, _, order = training._load_training_splits(data, cfg)
    counts = np.bincount(order.numpy(), minlength=len(tr))
    assert np.array_equal(counts, np.where(np.arange(len(tr)) % 5 == 0, 3, 1))
    plain = training._load_training_splits(data, TrainConfig.from_preset("quick", **TINY))[4]
    assert np.array_equal(plain.numpy(), np.arange(len(tr)))
    with pytest.raises(ValueError, match="rider_scene_repeat"):
        TrainConfig.from_preset("quick", rider_scene_repeat=0)


def test_levers_train_and_are_recorded(data, tmp_path):
    cfg = TrainConfig.from_preset("quick", **TINY, rider_weight=4.0, dynamics_weight=0.5, stability_weight=1.0,
                                  distinct_weight=0.5)
    assert cfg.model.dynamics_head  # a positive dynamics weight switches the head on
    out = train(data, tmp_path / "lev", cfg, show_progress=False)
    assert len(out["history"]) == 2 and np.isfinite(out["history"][-1]["train_loss"])
    saved = json.loads((tmp_path / "lev" / "config.json").read_text())["train_config"]
    assert saved["rider_weight"] == 4.0 and saved["dynamics_weight"] == 0.5 and saved["model"]["dynamics_head"]
    assert saved["stability_weight"] == 1.0 and saved["distinct_weight"] == 0.5
    model, _ = load_effect_model(tmp_path / "lev")
    assert model.dynamics is not None


def test_lever_settings_refused():
    with pytest.raises(ValueError, match="rider_weight"):
        TrainConfig.from_preset("quick", rider_weight=0.0)
    with pytest.raises(ValueError, match="dynamics_weight"):
        TrainConfig.from_preset("quick", dynamics_weight=-1.0)
    with pytest.raises(ValueError, match="dynamics_head"):
        TrainConfig(dynamics_weight=1.0)
    with pytest.raises(ValueError, match="stability_margin"):
        TrainConfig.from_preset("quick", stability_weight=1.0, stability_margin=0.0)
    with pytest.raises(ValueError, match="distinct_weight"):
        TrainConfig.from_preset("quick", distinct_weight=float("nan"))
    with pytest.raises(ValueError, match="distinct_margin"):
        TrainConfig.from_preset("quick", distinct_weight=1.0, distinct_margin=-1.0)


def test_config_from_before_the_levers_still_resumes():
    from symlearn.learning.training import _resumable

    cfg = TrainConfig.from_preset("quick", **TINY)
    old = cfg.to_json()
    for key in ("rider_weight", "dynamics_weight", "stability_weight", "stability_margin", "distinct_weight",
                "distinct_margin"):
        del old[key]
    del old["model"]["dynamics_head"]
    assert _resumable(old) == _resumable(cfg.to_json())
    assert _resumable({**old, "lr": 0.5}) != _resumable(cfg.to_json())
