"""The transition model's file, RUN/transition.pt: tensors plus JSON strings, loadable with weights_only.

A missing, foreign, other-format or damaged file is refused with a one-line TransitionError.
"""
from __future__ import annotations

import io
import json
from pathlib import Path

import torch

from pddl_export.bounded_json import loads_bounded
from symlearn.learning.checkpoint import BlobKind, guarded_blob
from symlearn.provenance import atomic_write_bytes
from symlearn.symbolic.transition_model import TransitionConfig, TransitionNet

TRANSITION_KIND = "symlearn-transition-model"
TRANSITION_FORMAT = 1
TRANSITION_FILE = "transition.pt"


class TransitionError(ValueError):
    """A transition checkpoint that is missing, foreign, of another format or another effect model."""


TRANSITION_MODEL = BlobKind(TRANSITION_KIND, TRANSITION_FORMAT, "transition-model", "transition",
                            "no transition model at {path}; run 'symlearn train-transition' first", TransitionError)


def save_transition(path: Path, net: TransitionNet, meta: dict) -> None:
    """Write the transition checkpoint atomically: tensors plus JSON strings (weights_only loadable)."""
    blob = {"kind": TRANSITION_KIND, "format_version": TRANSITION_FORMAT,
            "config": json.dumps(net.cfg.to_json()), "model": net.state_dict(), "meta": json.dumps(meta)}
    buf = io.BytesIO()
    torch.save(blob, buf)
    atomic_write_bytes(Path(path), buf.getvalue())


def load_transition(path: Path, expect_config: TransitionConfig | None = None) -> tuple[TransitionNet, dict]:
    """The transition network (eval mode) and its meta record; refuses foreign or mismatched files."""
    path = Path(path)
    blob = guarded_blob(path, TRANSITION_MODEL)
    try:
        cfg = TransitionConfig.from_json(loads_bounded(blob["config"], "field 'config'"))
        meta = loads_bounded(blob["meta"], "field 'meta'")
        net = TransitionNet(cfg)
        net.load_state_dict(blob["model"])
    except (KeyError, TypeError, ValueError, RuntimeError) as e:
        raise TransitionError(f"{path} is a damaged transition checkpoint ({str(e).splitlines()[0][:120]})") from None
    if expect_config is not None and cfg != expect_config:
        raise TransitionError(f"{path} was trained with another transition config")
    return net.eval(), meta
