"""The symbolic transition network m(z): its config, the network itself and its loss.

As in the paper's "Planning with Discovered Symbols": each object's binary code is
concatenated with the 36-way one-hot action, passed through two dense layers, one
self-attention layer over the scene's objects (padding masked out) and two more dense
layers, giving per-object next-code logits; training minimizes binary cross-entropy per bit
over the real objects (transition_training.py). attention_rounds > 1 adds further rounds of
attention (docs/DESIGN.md); the presets keep the paper's one.

modes > 1 makes m(z) a mixture: M whole-scene outcomes, each with its own next-code logits for every
object and a weight read from the scene, trained on the mixture's likelihood. The paper's net (M = 1)
scores bits independently, so an action whose outcome is one of two arrangements (a stick that tips or
stays) gets bits mixed from both, and the second arrangement, which differs in many bits, is never
among its likely states; a mode names it whole (docs/DESIGN.md, "Outcome modes").
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

from pddl_export.location_codec import LOCATION_BITS
from symlearn.config_file import RECIPE, Bound, check_bounds, preset
from symlearn.learning.models import MAX_CODE_BITS
from symlearn.world import N_ACTIONS

# An 8-bit learned code and 9 location bits make 17; the rule searches hold (objects, 2**bits) tables, 8 MB at 20.
MAX_TRANSITION_BITS = 20
MAX_MODES = 16


@dataclass(frozen=True)
class TransitionConfig:
    """Architecture and training of m(z); `paper` follows the paper's layer counts, `quick` is small."""

    preset: str = "paper"
    code_bits: int = 8  # the effect model's code length; train_transition takes it from the effect model
    hidden: int = 128  # width of every dense layer and of the attention
    n_heads: int = 4  # attention heads (hidden must be divisible by it)
    epochs: int = 200  # the network is tiny: 200 epochs of 10,000 samples take about a minute on CPU
    batch_size: int = 128  # scenes per step
    lr: float = 1e-3
    weight_decay: float = 0.0
    encode_batch_size: int = 256  # scenes per encoder forward pass while building the data set
    copy_prior: float = 0.0  # added to each logit toward the input bit, so "no change" is the default
    attention_rounds: int = 1  # self-attention rounds over the scene; the paper has 1 (docs/DESIGN.md on more)
    location_bits: int = 0  # 0, or one of LOCATION_BITS: codes end with where each object stands (symbolic.locations)
    modes: int = 1  # whole-scene outcomes of the mixture; 1: the paper's independent bits

    def __post_init__(self) -> None:
        """Refuse what cannot be built or trained ([transition] in a settings file): sizes, a zero that divides."""
        check_bounds(self, TRANSITION_BOUNDS)
        if self.hidden % self.n_heads:
            raise ValueError(f"hidden {self.hidden} is not divisible by n_heads {self.n_heads}")
        if not (isinstance(self.code_bits, int) and 1 <= self.code_bits <= MAX_CODE_BITS):
            raise ValueError(f"code_bits={self.code_bits!r} must be an integer in 1..{MAX_CODE_BITS}")
        if self.epochs < 1 or self.batch_size < 1 or self.encode_batch_size < 1:
            raise ValueError("epochs, batch_size and encode_batch_size must be positive")
        if not self.lr > 0:
            raise ValueError(f"lr={self.lr} must be positive")
        if not (isinstance(self.modes, int) and 1 <= self.modes <= MAX_MODES):
            raise ValueError(f"modes={self.modes!r} must be an integer in 1..{MAX_MODES}")
        if not (isinstance(self.attention_rounds, int) and self.attention_rounds >= 1):
            raise ValueError(f"attention_rounds={self.attention_rounds!r} must be an integer >= 1")
        if self.location_bits not in (0, *LOCATION_BITS):
            raise ValueError(f"location_bits={self.location_bits!r} must be 0 or one of {LOCATION_BITS}")
        if self.bits > MAX_TRANSITION_BITS:
            raise ValueError(f"code_bits {self.code_bits} + location_bits {self.location_bits} make {self.bits} "
                             f"bits, more than {MAX_TRANSITION_BITS}")

    @property
    def bits(self) -> int:
        """The width of m(z)'s codes: the learned code, then the location bits."""
        return self.code_bits + self.location_bits

    @staticmethod
    def from_preset(name: str = RECIPE, **overrides) -> "TransitionConfig":
        """A named preset (TRANSITION_PRESETS; by default the recipe's, what `symlearn train-transition` and the
        recommended pipeline train) with optional field overrides."""
        return preset(TRANSITION_PRESETS, name, **overrides)

    def to_json(self) -> dict:
        """The config as plain JSON, as stored in the checkpoint and the metrics, with the total width `bits`."""
        return {**dataclasses.asdict(self), "bits": self.bits}

    @staticmethod
    def from_json(d: dict) -> "TransitionConfig":
        """The config back from to_json's form; unknown fields and a `bits` that is not the sum are refused.

        A file from before code_bits holds only the total `bits`; its code_bits is that less the location bits.
        """
        d = dict(d)
        names = {f.name for f in dataclasses.fields(TransitionConfig)}
        unknown = set(d) - names - {"bits"}
        if unknown:
            raise ValueError(f"unknown transition config fields {sorted(unknown)}")
        total = d.pop("bits", None)
        if "code_bits" not in d and total is not None:
            d["code_bits"] = int(total) - int(d.get("location_bits", 0))
        cfg = TransitionConfig(**d)  # a file from before copy_prior (attention_rounds, location_bits, modes): default
        if total is not None and total != cfg.bits:
            raise ValueError(f"bits={total!r} is not code_bits {cfg.code_bits} + location_bits {cfg.location_bits}")
        return cfg


_SIZE = Bound(1, 65_536, integer=True)
TRANSITION_BOUNDS = {"hidden": _SIZE, "n_heads": Bound(1, 1024, integer=True),
                     "epochs": Bound(1, 1_000_000, integer=True), "batch_size": _SIZE, "encode_batch_size": _SIZE,
                     "lr": Bound(0.0, 10.0, lo_open=True), "weight_decay": Bound(0.0, 10.0),
                     "copy_prior": Bound(0.0, 100.0), "attention_rounds": Bound(1, 64, integer=True)}

TRANSITION_PRESETS = {
    # copy_prior 3: on paper24 it raised closed-loop A* success from 0.81 to 0.91 (an early paper24 run; git history of docs/BENCHMARKS.md).
    # attention_rounds stays 1: 3 rounds helped one effect model's rollouts and planning, not the other two
    # (docs/RESULTS.md, "More attention rounds in m(z)").
    "paper": TransitionConfig(preset="paper", copy_prior=3.0),
    "quick": TransitionConfig(preset="quick", hidden=64, n_heads=4, epochs=40, batch_size=64, lr=2e-3),
}
# the recipe that plans best (pretrained/recommended): quick, with the 9 location bits the lifted domain reads
# (which way and how far an object stands off its location, and its height; pddl_export/lifted_scene.py)
TRANSITION_PRESETS["recommended"] = dataclasses.replace(TRANSITION_PRESETS["quick"], preset="recommended",
                                                        location_bits=9)


class TransitionOutput(NamedTuple):
    logits: torch.Tensor  # (B, K, bits) next-code logits (of the likeliest mode), zero for padded slots
    codes: torch.Tensor  # (B, K, bits) thresholded next codes in {0, 1}, zero for padded slots
    mode_weights: torch.Tensor | None = None  # (B, M) log mixture weights; None for one mode
    mode_logits: torch.Tensor | None = None  # (B, M, K, bits) each mode's next-code logits; None for one mode


class TransitionNet(nn.Module):
    """m(z): (code, action) per object -> 2 dense -> self-attention -> 2 dense -> next-code logits.

    With attention_rounds > 1, each further round is a residual dense layer and a residual self-attention
    layer: an object's next code can then depend on what another object's context says (what lies under
    the place a held object is released on), which one round of attention cannot compose.
    """

    def __init__(self, cfg: TransitionConfig) -> None:
        super().__init__()
        self.cfg = cfg
        h = cfg.hidden
        self.pre = nn.Sequential(nn.Linear(cfg.bits + N_ACTIONS, h), nn.ReLU(), nn.Linear(h, h), nn.ReLU())
        self.attn = nn.MultiheadAttention(h, cfg.n_heads, batch_first=True)
        self.rounds = nn.ModuleList(_AttentionRound(h, cfg.n_heads) for _ in range(cfg.attention_rounds - 1))
        self.post = nn.Sequential(nn.Linear(h, h), nn.ReLU(), nn.Linear(h, cfg.bits * cfg.modes))
        if cfg.modes > 1:  # the weights, from the scene's mean feature
            self.weight_head = nn.Sequential(nn.Linear(h, h), nn.ReLU(), nn.Linear(h, cfg.modes))

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
        for r in self.rounds:
            h = r(h, pad)
        m = self.cfg.modes
        logits = self.post(h).view(b, k, m, self.cfg.bits).transpose(1, 2)  # (B, M, K, bits)
        if self.cfg.copy_prior:  # most (object, action) pairs leave the code as it is
            logits = logits + self.cfg.copy_prior * (2 * codes[:, None] - 1)
        logits = logits * mask[:, None, :, None]
        if m == 1:
            return TransitionOutput(logits[:, 0], (logits[:, 0] > 0).to(codes.dtype) * mask[..., None])
        real = mask[..., None].to(h.dtype)
        pooled = (h * real).sum(1) / real.sum(1).clamp_min(1.0)  # (B, H)
        weights = F.log_softmax(self.weight_head(pooled), dim=-1)  # (B, M)
        # each mode's likeliest state, scored by its own weight and bits; the best one answers as the net's
        score = weights - F.softplus(-logits.abs()).sum((2, 3))
        best = logits[torch.arange(b), score.argmax(1)]  # (B, K, bits)
        return TransitionOutput(best, (best > 0).to(codes.dtype) * mask[..., None], weights, logits)


class _AttentionRound(nn.Module):
    """A further round of m(z): residual dense layer, then residual self-attention over the scene."""

    def __init__(self, hidden: int, n_heads: int) -> None:
        super().__init__()
        self.dense = nn.Sequential(nn.Linear(hidden, hidden), nn.ReLU())
        self.attn = nn.MultiheadAttention(hidden, n_heads, batch_first=True)

    def forward(self, h: torch.Tensor, pad: torch.Tensor) -> torch.Tensor:
        h = h + self.dense(h)
        att, _ = self.attn(h, h, h, key_padding_mask=pad, need_weights=False)
        return h + att


def masked_bce(logits: torch.Tensor, target: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Binary cross-entropy per bit, averaged over the bits of real objects only."""
    per_bit = F.binary_cross_entropy_with_logits(logits, target, reduction="none")  # (B, K, bits)
    m = mask[..., None].to(per_bit.dtype)
    return (per_bit * m).sum() / (m.sum() * logits.shape[-1]).clamp_min(1.0)


def mode_log_likelihoods(out: TransitionOutput, target: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """(B, M) log P(target, mode m) = log weight + each real bit's log-likelihood under mode m."""
    t = target[:, None].expand_as(out.mode_logits)
    per_bit = F.binary_cross_entropy_with_logits(out.mode_logits, t, reduction="none")  # (B, M, K, bits)
    return out.mode_weights - (per_bit * mask[:, None, :, None].to(per_bit.dtype)).sum((2, 3))


def transition_loss(out: TransitionOutput, target: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """The loss m(z) is trained on: masked BCE, or with modes the mixture's negative log-likelihood, per real bit."""
    if out.mode_logits is None:
        return masked_bce(out.logits, target, mask)
    nll = -torch.logsumexp(mode_log_likelihoods(out, target, mask), dim=1)  # (B,)
    return nll.sum() / (mask.sum() * target.shape[-1]).clamp_min(1)


@torch.no_grad()
def predict_bits(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray,
                 batch_size: int = 4096) -> np.ndarray:
    """(N, K, bits) codes, (N, K) mask, (N,) actions -> (N, K, bits) float32 thresholded next codes."""
    return predict_scored(net, before, mask, action, batch_size)[0]


def _batched_outputs(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray, batch_size: int):
    """Yield (mask, network output) per batch of rows, in eval mode (the caller holds no_grad)."""
    net.eval()
    for i in range(0, before.shape[0], batch_size):
        m = torch.from_numpy(np.asarray(mask[i:i + batch_size], bool))
        yield m, net(torch.from_numpy(np.asarray(before[i:i + batch_size], np.float32)), m,
                     torch.from_numpy(np.asarray(action[i:i + batch_size], np.int64)))


def _likeliest_nll(o: TransitionOutput, mask: torch.Tensor) -> torch.Tensor:
    """(B,) -log P(o.codes): one mode sums softplus(-|logit|) over the real bits; a mixture sums over its modes."""
    if o.mode_logits is None:
        return (F.softplus(-o.logits.abs()) * mask[..., None]).sum((1, 2))
    return -torch.logsumexp(mode_log_likelihoods(o, o.codes, mask), 1)


@torch.no_grad()
def predict_scored(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray,
                   batch_size: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Thresholded next codes (N, K, bits) and each row's -log P(those codes), (N,) float64.

    With one mode the bits are independent Bernoullis given the input, so the thresholded codes are the
    most likely next state and -log P sums softplus(-|logit|) over the real objects' bits. With modes
    they are the likeliest mode's likeliest state, scored under the whole mixture.
    """
    codes, nll = [], []
    for m, o in _batched_outputs(net, before, mask, action, batch_size):
        codes.append(o.codes.numpy())
        nll.append(_likeliest_nll(o, m).double().numpy())
    if not codes:
        return np.zeros_like(before, np.float32), np.zeros(before.shape[0])
    return np.concatenate(codes), np.concatenate(nll)


@torch.no_grad()
def predict_probabilities(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray,
                          batch_size: int = 4096) -> np.ndarray:
    """(N, K, bits) float64 P(each next bit is 1), 0 in padded slots: every outcome's probability, not just the likeliest.

    With modes, the mixture's marginal of each bit.
    """
    out = []
    for m, o in _batched_outputs(net, before, mask, action, batch_size):
        if o.mode_logits is None:
            p = torch.sigmoid(o.logits.double())
        else:
            p = (o.mode_weights.double().exp()[..., None, None] * torch.sigmoid(o.mode_logits.double())).sum(1)
        out.append((p * m[..., None]).numpy())
    return np.concatenate(out) if out else np.zeros(before.shape, np.float64)


@torch.no_grad()
def predict_modes(net: TransitionNet, before: np.ndarray, mask: np.ndarray, action: np.ndarray,
                  batch_size: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Each mode's likeliest next state, (N, M, K, bits) float32 0/1, and its -log P under the mixture, (N, M).

    One mode: the thresholded codes and their -log P, as predict_scored.
    """
    states, nll = [], []
    for m, o in _batched_outputs(net, before, mask, action, batch_size):
        if o.mode_logits is None:
            states.append(o.codes[:, None].numpy())
            nll.append(_likeliest_nll(o, m)[:, None].double().numpy())
            continue
        mode_codes = (o.mode_logits > 0).to(o.codes.dtype) * m[:, None, :, None]  # (B, M, K, bits)
        b, n_modes = o.mode_weights.shape
        flat = mode_codes.reshape(b * n_modes, *mode_codes.shape[2:])
        rep = TransitionOutput(o.logits, o.codes, o.mode_weights.repeat_interleave(n_modes, 0),
                               o.mode_logits.repeat_interleave(n_modes, 0))  # row i * M + j: state j under row i
        ll = mode_log_likelihoods(rep, flat, m.repeat_interleave(n_modes, 0))  # (B * M, M)
        states.append(mode_codes.numpy())
        nll.append((-torch.logsumexp(ll, 1)).view(b, n_modes).double().numpy())
    if not states:
        return np.zeros((0, net.cfg.modes, *before.shape[1:]), np.float32), np.zeros((0, net.cfg.modes))
    return np.concatenate(states), np.concatenate(nll)
