"""Checkpoints: weights, optimizer, config and normalization in one file, read with weights_only=True.

Everything that is not a tensor is stored as a JSON string, so loading needs no pickle and a
foreign or older file is refused with a one-line reason.
"""
from __future__ import annotations

import io
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from symlearn.learning.models import AttentiveDeepSym, ModelConfig
from symlearn.provenance import atomic_write_bytes, sha256_file, versions

CHECKPOINT_FORMAT = 1
CHECKPOINT_KIND = "symlearn-effect-model"


class CheckpointError(ValueError):
    """A checkpoint that is missing, foreign, of another format version or another config."""


@dataclass(frozen=True)
class Checkpoint:
    config: ModelConfig
    model_state: dict
    optimizer_state: dict | None
    epoch: int
    best_val: float
    history: list
    rng_states: dict
    effect_mean: np.ndarray
    effect_std: np.ndarray
    meta: dict


def save_checkpoint(path: Path, *, model, optimizer=None, epoch: int = 0, best_val: float = float("inf"),
                    history: list | None = None, rng_states: dict | None = None,
                    effect_mean=None, effect_std=None, meta: dict | None = None) -> None:
    """Write atomically: a crash never leaves half a checkpoint behind."""
    blob = {
        "kind": CHECKPOINT_KIND, "format_version": CHECKPOINT_FORMAT,
        "config": json.dumps(model.cfg.to_json()),
        "model": model.state_dict(),
        "optimizer": optimizer.state_dict() if optimizer is not None else {},
        "epoch": int(epoch), "best_val": float(best_val),
        "history": json.dumps(history or []), "meta": json.dumps(meta or {}),
        "rng_states": dict(rng_states or {}),
        "effect_mean": torch.as_tensor(np.asarray(effect_mean if effect_mean is not None else np.zeros(3), np.float32)),
        "effect_std": torch.as_tensor(np.asarray(effect_std if effect_std is not None else np.ones(3), np.float32)),
    }
    buf = io.BytesIO()
    torch.save(blob, buf)
    atomic_write_bytes(Path(path), buf.getvalue())


def load_checkpoint(path: Path, expect_config: ModelConfig | None = None) -> Checkpoint:
    """A checkpoint file's record; refuses missing, foreign, other-format or other-config files."""
    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"no checkpoint at {path}; train a model first ('symlearn train')")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # torch raises several types for foreign or truncated files
        raise CheckpointError(f"{path} is not a readable checkpoint ({type(e).__name__}: {str(e).splitlines()[0][:120]})") from None
    if not isinstance(blob, dict) or blob.get("kind") != CHECKPOINT_KIND:
        raise CheckpointError(f"{path} is not a symlearn effect-model checkpoint")
    if blob.get("format_version") != CHECKPOINT_FORMAT:
        raise CheckpointError(f"{path} has checkpoint format {blob.get('format_version')!r}, expected {CHECKPOINT_FORMAT}")
    cfg = ModelConfig.from_json(json.loads(blob["config"]))
    if expect_config is not None and cfg != expect_config:
        raise CheckpointError(f"{path} was trained with another model config; use a new run directory")
    return Checkpoint(cfg, blob["model"], blob["optimizer"] or None, blob["epoch"], blob["best_val"],
                      json.loads(blob["history"]), blob["rng_states"],
                      blob["effect_mean"].numpy(), blob["effect_std"].numpy(), json.loads(blob["meta"]))


def load_effect_model(run_dir: Path, which: str = "best") -> tuple[AttentiveDeepSym, Checkpoint]:
    """The trained model of a run, in eval mode, with its checkpoint record."""
    if which not in ("best", "last"):
        raise CheckpointError(f"unknown checkpoint {which!r}: expected best or last")
    ck = load_checkpoint(Path(run_dir) / f"{which}.pt")
    model = AttentiveDeepSym(ck.config)
    model.load_state_dict(ck.model_state)
    return model.eval(), ck


def effect_model_sha256(run_dir: Path, which: str = "best") -> str:
    """First 16 hex digits of RUN/best.pt's SHA-256: names the exact effect model an output derives from."""
    return sha256_file(Path(run_dir) / f"{which}.pt")[:16]


def stage_record(run_dir: Path, ck: Checkpoint, config: dict) -> dict:
    """What a stage reading RUN's effect model writes beside its results: config, seed, versions, model hash.

    These stages draw no random numbers (eval mode, deterministic physics), so the seed recorded
    is the one the effect model was trained with: it and the model hash fix every number.
    """
    return {"config": config, "seed": ck.meta.get("train_config", {}).get("seed"), "versions": versions(),
            "effect_model_sha256": effect_model_sha256(run_dir)}
