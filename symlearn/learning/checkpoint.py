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

from pddl_export.bounded_json import JsonFileError, loads_bounded, open_regular_file
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
        "config": json.dumps(model.cfg.to_json(), allow_nan=False),
        "model": model.state_dict(),
        "optimizer": optimizer.state_dict() if optimizer is not None else {},
        "epoch": int(epoch), "best_val": float(best_val),
        "history": json.dumps(history or [], allow_nan=False), "meta": json.dumps(meta or {}, allow_nan=False),
        "rng_states": dict(rng_states or {}),
        "effect_mean": torch.as_tensor(np.asarray(effect_mean if effect_mean is not None else np.zeros(3), np.float32)),
        "effect_std": torch.as_tensor(np.asarray(effect_std if effect_std is not None else np.ones(3), np.float32)),
    }
    buf = io.BytesIO()
    torch.save(blob, buf)
    atomic_write_bytes(Path(path), buf.getvalue())


MAX_CHECKPOINT_BYTES = 4 << 30  # a checkpoint of any preset is megabytes; 4 GiB is far beyond one


@dataclass(frozen=True)
class BlobKind:
    """One kind of checkpoint file a run holds, as guarded_blob checks it and names it in its one-line refusals."""

    tag: str  # the file's "kind" field, e.g. "symlearn-effect-model"
    version: int  # the one "format_version" read
    noun: str  # what a foreign file is said not to be, e.g. "effect-model"
    format_name: str  # "checkpoint format 2, expected 1"
    missing: str  # the refusal of a missing file, with {path}
    error: type[ValueError]


EFFECT_MODEL = BlobKind(CHECKPOINT_KIND, CHECKPOINT_FORMAT, "effect-model", "checkpoint",
                        "no checkpoint at {path}; train a model first ('symlearn train')", CheckpointError)


def guarded_blob(path: Path, kind: BlobKind) -> dict:
    """The dict a run's checkpoint file holds (best.pt, last.pt, transition.pt), read with weights_only=True (no
    pickle) after the checks every such file gets: a missing file, one that is not a regular file (a FIFO would
    block torch.load), a foreign, truncated or other-format file are each refused with one line of kind.error.
    The one loader of them: each kind only reads its fields from the blob."""
    path = Path(path)
    if not path.exists():
        raise kind.error(kind.missing.format(path=path))
    try:  # the bounded reader's open-and-check: the file loaded is the one checked
        f = open_regular_file(path, MAX_CHECKPOINT_BYTES, "file")
    except JsonFileError as e:
        raise kind.error(str(e)) from None
    try:
        with f:
            blob = torch.load(f, map_location="cpu", weights_only=True)
    except Exception as e:  # torch raises several types for foreign, empty or truncated files
        raise kind.error(f"{path} is not a readable checkpoint ({_first_line(e)})") from None
    if not isinstance(blob, dict) or blob.get("kind") != kind.tag:
        raise kind.error(f"{path} is not a symlearn {kind.noun} checkpoint")
    if blob.get("format_version") != kind.version:
        raise kind.error(f"{path} has {kind.format_name} format {blob.get('format_version')!r}, "
                         f"expected {kind.version}")
    return blob


def load_checkpoint(path: Path, expect_config: ModelConfig | None = None) -> Checkpoint:
    """A checkpoint file's record; refuses missing, foreign, other-format, malformed or other-config files."""
    path = Path(path)
    blob = guarded_blob(path, EFFECT_MODEL)
    try:
        ck = _record(blob)
    except (KeyError, TypeError, ValueError, AttributeError, json.JSONDecodeError) as e:
        raise CheckpointError(f"{path} is a damaged checkpoint ({_first_line(e)})") from None
    if expect_config is not None and ck.config != expect_config:
        raise CheckpointError(f"{path} was trained with another model config; use a new run directory")
    return ck


_FIELDS = {"config": str, "model": dict, "optimizer": dict, "epoch": int, "best_val": float, "history": str,
           "meta": str, "rng_states": dict, "effect_mean": torch.Tensor, "effect_std": torch.Tensor}


def _record(blob: dict) -> Checkpoint:
    """The Checkpoint in a loaded blob; KeyError or TypeError names a missing or mistyped field."""
    for key, kind in _FIELDS.items():
        if key not in blob:
            raise KeyError(f"field {key!r} missing")
        if not isinstance(blob[key], kind):
            raise TypeError(f"field {key!r} is {type(blob[key]).__name__}, expected {kind.__name__}")
    cfg = ModelConfig.from_json(loads_bounded(blob["config"], "field 'config'"))
    return Checkpoint(cfg, blob["model"], blob["optimizer"] or None, blob["epoch"], blob["best_val"],
                      loads_bounded(blob["history"], "field 'history'"), blob["rng_states"],
                      blob["effect_mean"].numpy(), blob["effect_std"].numpy(),
                      loads_bounded(blob["meta"], "field 'meta'"))


def _first_line(e: BaseException) -> str:
    """'Type: first line of the message' (at most 120 characters), also for an empty message."""
    lines = str(e).strip().splitlines()
    return f"{type(e).__name__}: {lines[0][:120]}" if lines else type(e).__name__


def load_weights(model: torch.nn.Module, state: dict, path: Path) -> None:
    """Load `state` into `model`, or one line naming `path` and the first keys that do not fit."""
    own = model.state_dict()
    missing = [k for k in own if k not in state]
    unexpected = [k for k in state if k not in own]
    shapes = [k for k in own if k in state and getattr(state[k], "shape", None) != own[k].shape]
    if missing or unexpected or shapes:
        parts = [f"{what} {', '.join(keys[:3])}{' ...' if len(keys) > 3 else ''} ({len(keys)})"
                 for what, keys in (("missing", missing), ("unexpected", unexpected), ("shape differs", shapes)) if keys]
        raise CheckpointError(f"{path}: the weights do not fit the model config stored with them: {'; '.join(parts)}")
    model.load_state_dict(state)


def analysis_device() -> torch.device:
    """Where the analysis stages (evaluate, symbols, train-transition's encoding) run the effect model: a GPU if any."""
    return torch.device("cuda") if torch.cuda.is_available() else torch.device("cpu")


def load_effect_model(run_dir: Path, which: str = "best",
                      device: torch.device | str = "cpu") -> tuple[AttentiveDeepSym, Checkpoint]:
    """The trained model of a run, in eval mode on `device`, with its checkpoint record."""
    if which not in ("best", "last"):
        raise CheckpointError(f"unknown checkpoint {which!r}: expected best or last")
    path = Path(run_dir) / f"{which}.pt"
    ck = load_checkpoint(path)
    model = AttentiveDeepSym(ck.config)
    load_weights(model, ck.model_state, path)
    return model.to(device).eval(), ck


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
