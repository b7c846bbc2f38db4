"""The symbolic transition model m(z): next per-object codes from current codes and an action.

As in the paper's "Planning with Discovered Symbols": each object's binary code is
concatenated with the 36-way one-hot action, passed through two dense layers, one
self-attention layer over the scene's objects (padding masked out) and two more dense
layers, giving per-object next-code logits; training minimizes binary cross-entropy per bit
over the real objects. The training pairs are the trained effect model's own codes of the
before- and after-crops of every data sample (encoder in eval mode: deterministic threshold).

    >>> train_transition(Path("runs/paper"), Path("data/paper"), TransitionConfig.from_preset("paper"))  # doctest: +SKIP
    >>> m = LearnedTransition.from_run(Path("runs/paper"))                                          # doctest: +SKIP
    >>> m(np.array([[3, 17]]), np.array([action_id(3, 4)]))   # (B, K) codes, (B,) actions      # doctest: +SKIP
    array([[ 3, 19]])

`LearnedTransition` implements pddl_export.symbolic.TransitionFn; A* and the PDDL export call it.
"""
from __future__ import annotations

import dataclasses
import io
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

from pddl_export.symbolic import bits_from_codes, codes_from_bits
from symlearn.learning.checkpoint import load_effect_model
from symlearn.data.dataset import InteractionData, load_split
from symlearn.learning.models import N_ACTIONS, AttentiveDeepSym
from symlearn.provenance import atomic_write_bytes, atomic_write_json, sha256_bytes, sha256_file, versions
from symlearn.learning.training import crops_from_depth, data_fingerprint

TRANSITION_KIND = "symlearn-transition-model"
TRANSITION_FORMAT = 1
TRANSITION_FILE = "transition.pt"
METRICS_FILE = "transition_metrics.json"
ROLLOUT_STEPS = 5  # multi-step accuracy is reported for 1..ROLLOUT_STEPS actions


class TransitionError(ValueError):
    """A transition checkpoint that is missing, foreign, of another format or another effect model."""


@dataclass(frozen=True)
class TransitionConfig:
    """Architecture and training of m(z); `paper` follows the paper's layer counts, `quick` is small."""

    preset: str = "paper"
    bits: int = 8  # code length; always taken from the effect model the codes come from
    hidden: int = 128  # width of every dense layer and of the attention
    n_heads: int = 4  # attention heads (hidden must be divisible by it)
    epochs: int = 200  # the network is tiny: 200 epochs of 10,000 samples take about a minute on CPU
    batch_size: int = 128  # scenes per step
    lr: float = 1e-3
    weight_decay: float = 0.0
    encode_batch_size: int = 256  # scenes per encoder forward pass while building the data set
    copy_prior: float = 0.0  # added to each logit toward the input bit, so "no change" is the default

    def __post_init__(self) -> None:
        if self.hidden % self.n_heads:
            raise ValueError(f"hidden {self.hidden} is not divisible by n_heads {self.n_heads}")
        if not 1 <= self.bits <= 16:
            raise ValueError(f"bits={self.bits} must lie in 1..16")
        if self.epochs < 1 or self.batch_size < 1 or self.encode_batch_size < 1:
            raise ValueError("epochs, batch_size and encode_batch_size must be positive")
        if not self.lr > 0:
            raise ValueError(f"lr={self.lr} must be positive")

    @staticmethod
    def from_preset(name: str, **overrides) -> "TransitionConfig":
        """A named preset with optional field overrides."""
        if name not in TRANSITION_PRESETS:
            raise ValueError(f"unknown preset {name!r}; known: {', '.join(TRANSITION_PRESETS)}")
        return dataclasses.replace(TRANSITION_PRESETS[name], **overrides)

    def to_json(self) -> dict:
        return dataclasses.asdict(self)

    @staticmethod
    def from_json(d: dict) -> "TransitionConfig":
        names = {f.name for f in dataclasses.fields(TransitionConfig)}
        unknown = set(d) - names
        if unknown:
            raise ValueError(f"unknown transition config fields {sorted(unknown)}")
        return TransitionConfig(**d)  # a file from before copy_prior gets its default, 0


TRANSITION_PRESETS = {
    # copy_prior 3: on paper24 it raised closed-loop A* success from 0.81 to 0.91 (docs/BENCHMARKS.md)
    "paper": TransitionConfig(preset="paper", copy_prior=3.0),
    "quick": TransitionConfig(preset="quick", hidden=64, n_heads=4, epochs=40, batch_size=64, lr=2e-3),
}


class TransitionOutput(NamedTuple):
    logits: torch.Tensor  # (B, K, bits) next-code logits, zero for padded slots
    codes: torch.Tensor  # (B, K, bits) thresholded next codes in {0, 1}, zero for padded slots


class TransitionNet(nn.Module):
    """m(z): (code, action) per object -> 2 dense -> self-attention -> 2 dense -> next-code logits."""

    def __init__(self, cfg: TransitionConfig) -> None:
        super().__init__()
        self.cfg = cfg
        h = cfg.hidden
        self.pre = nn.Sequential(nn.Linear(cfg.bits + N_ACTIONS, h), nn.ReLU(), nn.Linear(h, h), nn.ReLU())
        self.attn = nn.MultiheadAttention(h, cfg.n_heads, batch_first=True)
        self.post = nn.Sequential(nn.Linear(h, h), nn.ReLU(), nn.Linear(h, cfg.bits))

    def forward(self, codes: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor) -> TransitionOutput:
        """Codes (B, K, bits) in {0, 1}, mask (B, K) bool, action ids (B,) -> next-code logits."""
        if codes.dim() != 3 or codes.shape[:2] != mask.shape or codes.shape[2] != self.cfg.bits:
            raise ValueError(f"codes must be (B, K, {self.cfg.bits}) matching mask (B, K); got "
                             f"{tuple(codes.shape)} and {tuple(mask.shape)}")
        if actions.shape != mask.shape[:1]:
            raise ValueError(f"actions must be (B,), got {tuple(actions.shape)}")
        b, k = mask.shape
        a = F.one_hot(actions.long(), N_ACTIONS).to(codes.dtype)  # (B, 36)
        x = torch.cat([codes, a[:, None].expand(b, k, N_ACTIONS)], dim=-1)  # (B, K, bits + 36)
        h = self.pre(x)  # (B, K, H)
        # A scene without real objects would attend to nothing (NaN): let its first slot attend to itself.
        pad = ~mask
        pad[:, 0] &= mask.any(dim=1)
        att, _ = self.attn(h, h, h, key_padding_mask=pad, need_weights=False)  # (B, K, H)
        h = h + att  # residual: an object keeps its own code's features beside the scene context
        logits = self.post(h)
        if self.cfg.copy_prior:  # most (object, action) pairs leave the code as it is
            logits = logits + self.cfg.copy_prior * (2 * codes - 1)
        logits = logits * mask[..., None]  # (B, K, bits)
        return TransitionOutput(logits, (logits > 0).to(codes.dtype) * mask[..., None])


def masked_bce(logits: torch.Tensor, target: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Binary cross-entropy per bit, averaged over the bits of real objects only."""
    per_bit = F.binary_cross_entropy_with_logits(logits, target, reduction="none")  # (B, K, bits)
    m = mask[..., None].to(per_bit.dtype)
    return (per_bit * m).sum() / (m.sum() * logits.shape[-1]).clamp_min(1.0)


# ------------------------------------------------------------------------------- data set


@dataclass(frozen=True)
class TransitionData:
    """Encoded samples of one split: codes before and after each action, as 0/1 bit arrays."""

    before: np.ndarray  # (N, K, bits) float32 0/1, padded slots zero
    action: np.ndarray  # (N,) int64 action ids
    after: np.ndarray  # (N, K, bits) float32 0/1
    mask: np.ndarray  # (N, K) bool, real objects
    episode: np.ndarray  # (N,) int32 episode ids (unique within the split)
    step: np.ndarray  # (N,) int step index within the episode

    def __post_init__(self) -> None:
        n = self.action.shape[0]
        for f in dataclasses.fields(self):
            if getattr(self, f.name).shape[0] != n:
                raise ValueError(f"{f.name} has {getattr(self, f.name).shape[0]} rows, expected {n}")

    def __len__(self) -> int:
        return int(self.action.shape[0])


@torch.no_grad()
def encode_crops(model: AttentiveDeepSym, depth: np.ndarray, origin: np.ndarray, mask: np.ndarray,
                 batch_size: int = 256, image_size: int = 256) -> np.ndarray:
    """(N, K, S, S) depth crops, (N, K, 2) origins, (N, K) mask -> (N, K, bits) float32 codes (eval mode)."""
    model.eval()
    device = next(model.parameters()).device
    out = []
    for i in range(0, depth.shape[0], batch_size):
        d = torch.from_numpy(np.asarray(depth[i:i + batch_size], np.float32))  # (B, K, S, S)
        o = torch.from_numpy(np.asarray(origin[i:i + batch_size], np.float32))  # (B, K, 2)
        m = torch.from_numpy(np.asarray(mask[i:i + batch_size], bool))  # (B, K)
        crops = crops_from_depth(d, o, image_size)  # (B, K, 3, S, S)
        codes, _ = model.encode(crops.to(device), m.to(device))  # (B, K, bits)
        out.append(codes.float().cpu().numpy())
    bits = model.cfg.bits
    return np.concatenate(out) if out else np.zeros((0, depth.shape[1], bits), np.float32)


def build_transition_data(model: AttentiveDeepSym, data: InteractionData,
                          batch_size: int = 256) -> TransitionData:
    """Encode a split's before- and after-crops with the effect model's encoder."""
    mask = data.mask
    before = encode_crops(model, data.pre_depth, data.pre_origin, mask, batch_size)
    after = encode_crops(model, data.post_depth, data.post_origin, mask, batch_size)
    return TransitionData(before, data.action.astype(np.int64), after, mask,
                          data.episode.astype(np.int32), data.step.astype(np.int64))


def encode_observation(model: AttentiveDeepSym, obs) -> np.ndarray:
    """A live simulator Observation -> (k,) int64 codes, one per object, MSB first.

    Crops go through float16 first, as they are stored in the data set the encoder was trained on,
    so a live scene and its recorded twin get the same codes.
    """
    crops = np.asarray(obs.crops, np.float16).astype(np.float32)[None]  # (1, k, S, S)
    origins = np.asarray(obs.origins, np.float32)[None]  # (1, k, 2)
    if crops.shape[1] == 0:
        return np.zeros(0, np.int64)
    mask = np.ones(crops.shape[:2], bool)
    bits = encode_crops(model, crops, origins, mask, image_size=int(obs.depth.shape[0]))  # (1, k, bits)
    return codes_from_bits(bits[0])


# ------------------------------------------------------------------------------- metrics


@torch.no_grad()
def predict_bits(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray,
                 batch_size: int = 4096) -> np.ndarray:
    """(N, K, bits) codes, (N, K) mask, (N,) actions -> (N, K, bits) float32 thresholded next codes."""
    net.eval()
    out = []
    for i in range(0, before.shape[0], batch_size):
        o = net(torch.from_numpy(np.asarray(before[i:i + batch_size], np.float32)),
                torch.from_numpy(np.asarray(mask[i:i + batch_size], bool)),
                torch.from_numpy(np.asarray(action[i:i + batch_size], np.int64)))
        out.append(o.codes.numpy())
    return np.concatenate(out) if out else np.zeros_like(before, np.float32)


def _accuracies(pred: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> dict[str, float | int]:
    """Bit, per-object code and whole-scene accuracy over real objects."""
    if mask.sum() == 0:
        return {"bit_accuracy": math.nan, "object_accuracy": math.nan, "scene_accuracy": math.nan, "n": 0}
    bit_ok = pred == truth  # (N, K, bits)
    obj_ok = bit_ok.all(-1)  # (N, K)
    scene_ok = (obj_ok | ~mask).all(-1)  # (N,)
    return {"bit_accuracy": round(float(bit_ok[mask].mean()), 5),
            "object_accuracy": round(float(obj_ok[mask].mean()), 5),
            "scene_accuracy": round(float(scene_ok.mean()), 5), "n": int(mask.shape[0])}


def rollout_chains(data: TransitionData, n: int) -> np.ndarray:
    """(M, n) sample indices of every run of n consecutive steps of one episode."""
    index = {(int(e), int(s)): i for i, (e, s) in enumerate(zip(data.episode, data.step))}
    chains = []
    for i, (e, s) in enumerate(zip(data.episode.tolist(), data.step.tolist())):
        row = [i]
        for j in range(1, n):
            nxt = index.get((e, s + j))
            if nxt is None:
                break
            row.append(nxt)
        if len(row) == n:
            chains.append(row)
    return np.asarray(chains, np.int64).reshape(-1, n)


def rollout_accuracy(net: TransitionNet, data: TransitionData, n: int) -> dict[str, float | int]:
    """Roll m(z) n actions forward from the encoder's codes at t; compare with the codes of the real state at t+n."""
    chains = rollout_chains(data, n)
    if len(chains) == 0:
        return {"object_accuracy": math.nan, "scene_accuracy": math.nan, "bit_accuracy": math.nan, "n": 0}
    mask = data.mask[chains[:, 0]]
    state = data.before[chains[:, 0]]
    for j in range(n):
        state = predict_bits(net, state, mask, data.action[chains[:, j]])
    return _accuracies(state, data.after[chains[:, -1]], mask)


def evaluate_transition(net: TransitionNet, data: TransitionData) -> dict:
    """One-step accuracies, the copy baseline (no code changes) and 1..ROLLOUT_STEPS rollout accuracies."""
    pred = predict_bits(net, data.before, data.mask, data.action)
    return {**_accuracies(pred, data.after, data.mask),
            "copy_baseline": _accuracies(data.before, data.after, data.mask),
            "rollout": {str(n): rollout_accuracy(net, data, n) for n in range(1, ROLLOUT_STEPS + 1)}}


# ------------------------------------------------------------------------------- checkpoint


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
    if not path.exists():
        raise TransitionError(f"no transition model at {path}; run 'symlearn train-transition' first")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # torch raises several types for foreign or truncated files
        raise TransitionError(f"{path} is not a readable checkpoint "
                              f"({type(e).__name__}: {str(e).splitlines()[0][:120] if str(e) else ''})") from None
    if not isinstance(blob, dict) or blob.get("kind") != TRANSITION_KIND:
        raise TransitionError(f"{path} is not a symlearn transition-model checkpoint")
    if blob.get("format_version") != TRANSITION_FORMAT:
        raise TransitionError(f"{path} has transition format {blob.get('format_version')!r}, "
                              f"expected {TRANSITION_FORMAT}")
    try:
        cfg = TransitionConfig.from_json(json.loads(blob["config"]))
        meta = json.loads(blob["meta"])
        net = TransitionNet(cfg)
        net.load_state_dict(blob["model"])
    except (KeyError, TypeError, ValueError, RuntimeError) as e:
        raise TransitionError(f"{path} is a damaged transition checkpoint ({str(e).splitlines()[0][:120]})") from None
    if expect_config is not None and cfg != expect_config:
        raise TransitionError(f"{path} was trained with another transition config")
    return net.eval(), meta


# ------------------------------------------------------------------------------- training


def train_transition(run_dir: Path, data_dir: Path, cfg: TransitionConfig, seed: int = 0,
                     show_progress: bool = False) -> dict:
    """Train m(z) on the codes of RUN's effect model; writes RUN/transition.pt and RUN/transition_metrics.json."""
    run_dir, data_dir = Path(run_dir), Path(data_dir)
    t_start = time.perf_counter()
    encoder, ck = load_effect_model(run_dir)
    cfg = dataclasses.replace(cfg, bits=ck.config.bits)
    fingerprint = data_fingerprint(data_dir)
    splits = {s: build_transition_data(encoder, load_split(data_dir, s), cfg.encode_batch_size)
              for s in ("train", "val", "test")}
    tr, va = splits["train"], splits["val"]
    encode_s = time.perf_counter() - t_start

    with torch.random.fork_rng(devices=[]):  # seeded init without touching the caller's global RNG
        torch.manual_seed(seed)
        net = TransitionNet(cfg)
    opt = torch.optim.Adam(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    gen = torch.Generator().manual_seed(seed)
    x_tr, m_tr = torch.from_numpy(tr.before), torch.from_numpy(tr.mask)
    a_tr, y_tr = torch.from_numpy(tr.action), torch.from_numpy(tr.after)
    x_va, m_va = torch.from_numpy(va.before), torch.from_numpy(va.mask)
    a_va, y_va = torch.from_numpy(va.action), torch.from_numpy(va.after)
    best, best_state, history = math.inf, None, []
    for epoch in range(cfg.epochs):
        net.train()
        perm = torch.randperm(len(tr), generator=gen)
        n_batches = max(1, math.ceil(len(tr) / cfg.batch_size))
        total = 0.0
        for b in range(n_batches):
            idx = perm[b * cfg.batch_size:(b + 1) * cfg.batch_size]
            out = net(x_tr[idx], m_tr[idx], a_tr[idx])
            loss = masked_bce(out.logits, y_tr[idx], m_tr[idx])
            if not torch.isfinite(loss):
                raise RuntimeError(f"transition loss became {loss.item()} at epoch {epoch + 1}; lower the learning rate")
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            total += float(loss.detach())
        net.eval()
        with torch.no_grad():
            val_loss = float(masked_bce(net(x_va, m_va, a_va).logits, y_va, m_va))
        history.append({"epoch": epoch + 1, "train_loss": round(total / n_batches, 5), "val_loss": round(val_loss, 5)})
        if val_loss < best:
            best = val_loss
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
        if show_progress:
            print(f"transition epoch {epoch + 1}/{cfg.epochs}: train {total / n_batches:.4f} val {val_loss:.4f}", flush=True)
    net.load_state_dict(best_state)
    net.eval()
    meta = {"transition_config": cfg.to_json(), "seed": seed, "data": str(data_dir),
            "data_fingerprint": fingerprint, "effect_model": "best.pt",
            "effect_model_sha256": sha256_file(run_dir / "best.pt")[:16], "effect_model_bits": ck.config.bits,
            "best_val_loss": best, "versions": versions()}
    save_transition(run_dir / TRANSITION_FILE, net, meta)
    metrics = {**meta, "history": history, "n_samples": {s: len(d) for s, d in splits.items()},
               "test": evaluate_transition(net, splits["test"]), "val": evaluate_transition(net, va),
               "encode_time_s": round(encode_s, 2), "wall_time_s": round(time.perf_counter() - t_start, 2)}
    metrics = _json_safe(metrics)
    atomic_write_json(run_dir / METRICS_FILE, metrics)
    return metrics


def _json_safe(obj):
    """NaN (metrics of empty selections) becomes null so the file stays strict JSON."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_json_safe(v) for v in obj]
    return obj


# ------------------------------------------------------------------------------- planning interface


class LearnedTransition:
    """m(z) as a pddl_export.symbolic.TransitionFn: integer codes in, thresholded integer codes out."""

    def __init__(self, net: TransitionNet, batch_size: int = 4096) -> None:
        self.net = net.eval()
        self.bits = int(net.cfg.bits)
        self.batch_size = batch_size

    @classmethod
    def from_run(cls, run_dir: Path, check_encoder: bool = True) -> "LearnedTransition":
        """Load RUN/transition.pt; refuses one trained on another effect model than RUN/best.pt."""
        run_dir = Path(run_dir)
        net, meta = load_transition(run_dir / TRANSITION_FILE)
        if check_encoder:
            best = run_dir / "best.pt"
            if best.exists() and meta.get("effect_model_sha256") != sha256_file(best)[:16]:
                raise TransitionError(f"{run_dir / TRANSITION_FILE} was trained on another effect model than "
                                      f"{best}; re-run 'symlearn train-transition'")
        return cls(net)

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """(B, K) int codes and (B,) action ids -> (B, K) int64 next codes."""
        codes = np.asarray(codes)
        actions = np.asarray(actions)
        if codes.ndim != 2 or actions.shape != codes.shape[:1]:
            raise ValueError(f"codes must be (B, K) and actions (B,); got {codes.shape} and {actions.shape}")
        if not (np.issubdtype(codes.dtype, np.integer) and np.issubdtype(actions.dtype, np.integer)):
            raise ValueError(f"codes and actions must be integers, got {codes.dtype} and {actions.dtype}")
        if codes.size and (codes.min() < 0 or codes.max() >= 1 << self.bits):
            raise ValueError(f"codes must lie in 0..{(1 << self.bits) - 1}")
        if actions.size and (actions.min() < 0 or actions.max() >= N_ACTIONS):
            raise ValueError(f"action ids must lie in 0..{N_ACTIONS - 1}")
        if codes.size == 0:
            return codes.astype(np.int64)
        bits = bits_from_codes(codes, self.bits)  # (B, K, bits)
        mask = np.ones(codes.shape, bool)
        nxt = predict_bits(self.net, bits, mask, actions.astype(np.int64), self.batch_size)
        return codes_from_bits(nxt)
