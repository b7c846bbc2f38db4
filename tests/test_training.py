import json
import subprocess
import sys

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


def test_two_process_ddp_ends_with_identical_weights(data, tmp_path):
    run = tmp_path / "ddp"
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node=2", "-m", "symlearn.cli.main",
           "train", "--data", str(data), "--out", str(run), "--preset", "quick", "--epochs", "1", "--batch-size", "4",
           "--no-bf16", "--quiet"]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    m = json.loads((run / "metrics.json").read_text())
    assert m["world_size"] == 2 and m["ranks_identical"] is True
