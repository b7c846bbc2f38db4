"""Training m(z) on the codes of a run's effect model; writes RUN/transition.pt and RUN/transition_metrics.json.

    >>> train_transition(Path("runs/paper"), Path("data/paper"), TransitionConfig.from_preset("paper"))  # doctest: +SKIP

The metrics file records the transition config, the seed, package versions, the data set's
fingerprint and the hash of the effect model (best.pt) the codes came from. Extra data sets (collected
apart, for instance with more objects) add their train and val splits to m(z)'s; their test splits are
reported apart, so the main test figures stay comparable with a model trained on the main set alone.
"""
from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Callable

import torch

from symlearn.data.dataset import (DataError, data_fingerprint, data_records, distinct_extra_data, load_manifest,
                                   load_split)
from symlearn.learning.checkpoint import analysis_device, effect_model_sha256, load_effect_model
from symlearn.learning.models import AttentiveDeepSym
from pddl_export.files import finite_or_null
from symlearn.provenance import atomic_write_json, versions
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, save_transition
from symlearn.sim.camera import CameraConfig
from symlearn.symbolic.transition_data import (SymbolReader, TransitionData, build_transition_data,
                                               concat_transition_data)
from symlearn.symbolic.transition_metrics import evaluate_transition
from symlearn.symbolic.transition_model import TransitionConfig, TransitionNet, transition_loss

METRICS_FILE = "transition_metrics.json"


def train_transition(run_dir: Path, data_dir: Path, cfg: TransitionConfig, seed: int = 0,
                     show_progress: bool = False, extra_data: tuple[Path, ...] = ()) -> dict:
    """Train m(z) on the codes of RUN's effect model; writes RUN/transition.pt and RUN/transition_metrics.json.

    extra_data: more data sets whose train and val splits join the main set's (their test splits are
    evaluated apart, under "extra_test").
    """
    run_dir, data_dir = Path(run_dir), Path(data_dir)
    extra_data = distinct_extra_data(data_dir, extra_data)
    t_start = time.perf_counter()
    encoder, ck = load_effect_model(run_dir, device=analysis_device())
    cfg = dataclasses.replace(cfg, code_bits=ck.config.bits)  # the codes m(z) learns are this effect model's
    fingerprint = data_fingerprint(data_dir)
    extra_fp = data_records(extra_data)
    camera = data_camera(data_dir, extra_data) if cfg.location_bits else None
    reader = SymbolReader(encoder, camera, cfg.location_bits)
    splits = encode_splits(reader, data_dir, cfg.encode_batch_size)
    extras = [encode_splits(reader, d, cfg.encode_batch_size) for d in extra_data]
    train = concat_transition_data([splits["train"], *(e["train"] for e in extras)])
    val = concat_transition_data([splits["val"], *(e["val"] for e in extras)])
    encode_s = time.perf_counter() - t_start
    net, best, history = fit_transition(cfg, train, val, seed, show_progress)
    meta = {"transition_config": cfg.to_json(), "seed": seed, "data": str(data_dir),
            "data_fingerprint": fingerprint, "extra_data": extra_fp, "effect_model": "best.pt",
            "effect_model_sha256": effect_model_sha256(run_dir), "effect_model_bits": ck.config.bits,
            "location_camera": None if camera is None else dataclasses.asdict(camera),
            "best_val_loss": best, "versions": versions()}
    save_transition(run_dir / TRANSITION_FILE, net, meta)
    metrics = {**meta, "history": history,
               "n_samples": {"train": len(train), "val": len(val), "test": len(splits["test"])},
               "test": evaluate_transition(net, splits["test"]), "val": evaluate_transition(net, splits["val"]),
               "extra_test": {str(d): evaluate_transition(net, e["test"]) for d, e in zip(extra_data, extras)},
               "encode_time_s": round(encode_s, 2), "wall_time_s": round(time.perf_counter() - t_start, 2)}
    metrics = finite_or_null(metrics)  # NaN metrics of empty selections become null
    atomic_write_json(run_dir / METRICS_FILE, metrics)
    return metrics


def data_camera(data_dir: Path, extra_data: tuple[Path, ...] = ()) -> CameraConfig:
    """The camera the data sets' crops were rendered with (location bits back-project through it); one for all sets."""
    cams = {}
    for d in (data_dir, *extra_data):
        settings = load_manifest(Path(d)).get("settings", {})
        cam = settings.get("sim", {}).get("camera")
        if not isinstance(cam, dict):
            raise DataError(f"{Path(d) / 'manifest.json'} records no camera (settings.sim.camera): "
                            "location bits cannot be read from its crops")
        cams[str(d)] = CameraConfig.from_json(cam)
    if len(set(cams.values())) > 1:
        raise DataError(f"the data sets were rendered with different cameras ({', '.join(cams)}): "
                        "location bits need one")
    return next(iter(cams.values()))


def encode_splits(encoder: AttentiveDeepSym | SymbolReader, data_dir: Path,
                  batch_size: int) -> dict[str, TransitionData]:
    """The train, val and test splits encoded by the effect model: m(z)'s training, selection and test pairs."""
    return {s: build_transition_data(encoder, load_split(data_dir, s), batch_size) for s in ("train", "val", "test")}


# one training epoch: (net, optimizer, shuffling generator, epoch index) -> mean training loss
EpochFn = Callable[[TransitionNet, torch.optim.Optimizer, torch.Generator, int], float]


def fit_transition(cfg: TransitionConfig, tr: TransitionData, va: TransitionData, seed: int,
                   show_progress: bool = False,
                   train_epoch: EpochFn | None = None) -> tuple[TransitionNet, float, list[dict]]:
    """Adam on masked BCE (with modes, the mixture's likelihood) for cfg.epochs; returns the net with its
    best-validation weights, that loss and the history.

    train_epoch replaces the epoch over (before, action, after) pairs (for instance one over multi-step chains);
    validation and keeping the best weights stay the same.
    """
    with torch.random.fork_rng(devices=[]):  # seeded init without touching the caller's global RNG
        torch.manual_seed(seed)
        net = TransitionNet(cfg)
    opt = torch.optim.Adam(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    gen = torch.Generator().manual_seed(seed)
    train_t = _tensors(tr)
    x_va, m_va, a_va, y_va = _tensors(va)
    best, best_state, history = math.inf, None, []
    for epoch in range(cfg.epochs):
        train_loss = (train_epoch(net, opt, gen, epoch) if train_epoch is not None
                      else _train_epoch(net, opt, gen, train_t, cfg, epoch))
        net.eval()
        with torch.no_grad():
            val_loss = float(transition_loss(net(x_va, m_va, a_va), y_va, m_va))
        history.append({"epoch": epoch + 1, "train_loss": round(train_loss, 5), "val_loss": round(val_loss, 5)})
        if val_loss < best:
            best = val_loss
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
        if show_progress:
            print(f"transition epoch {epoch + 1}/{cfg.epochs}: train {train_loss:.4f} val {val_loss:.4f}", flush=True)
    net.load_state_dict(best_state)
    net.eval()
    return net, best, history


def _tensors(data: TransitionData) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """A split's codes before, mask, actions and codes after, as tensors sharing the arrays' memory."""
    return (torch.from_numpy(data.before), torch.from_numpy(data.mask),
            torch.from_numpy(data.action), torch.from_numpy(data.after))


def _train_epoch(net: TransitionNet, opt: torch.optim.Optimizer, gen: torch.Generator,
                 train_t: tuple[torch.Tensor, ...], cfg: TransitionConfig, epoch: int) -> float:
    """One shuffled pass over the training pairs; returns the mean batch loss."""
    x_tr, m_tr, a_tr, y_tr = train_t
    net.train()
    perm = torch.randperm(len(a_tr), generator=gen)
    n_batches = max(1, math.ceil(len(a_tr) / cfg.batch_size))
    total = 0.0
    for b in range(n_batches):
        idx = perm[b * cfg.batch_size:(b + 1) * cfg.batch_size]
        out = net(x_tr[idx], m_tr[idx], a_tr[idx])
        loss = transition_loss(out, y_tr[idx], m_tr[idx])
        if not torch.isfinite(loss):
            raise RuntimeError(f"transition loss became {loss.item()} at epoch {epoch + 1}; lower the learning rate")
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        total += float(loss.detach())
    return total / n_batches
