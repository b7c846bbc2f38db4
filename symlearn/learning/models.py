"""Attentive DeepSym and its baselines as torch modules.

The encoder f turns each object's 3-channel crop (depth, x, y) into a `bits`-bit code through a
Gumbel-sigmoid with a straight-through estimator (a deterministic threshold at evaluation);
the one-hot action is concatenated to every code; a stack of transformer encoder layers lets
the objects of a scene attend to each other (padding masked out); the decoder g predicts each
object's normalized displacement. Batch-norm layers only ever see real objects: padded slots
are removed before the encoder and decoder and scattered back after.

    >>> cfg = ModelConfig.from_preset("quick")
    >>> model = AttentiveDeepSym(cfg)
    >>> x = torch.zeros(2, 3, 3, cfg.crop, cfg.crop); mask = torch.tensor([[1, 1, 0], [1, 0, 0]]).bool()
    >>> out = model(x, mask, torch.tensor([0, 35]))
    >>> tuple(out.effect.shape), tuple(out.codes.shape)
    ((2, 3, 3), (2, 3, 8))
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import torch
import torch.nn as nn
import torch.nn.functional as F

from symlearn.config_file import Bound, check_bounds, preset
from symlearn.world import N_ACTIONS

MAX_CODE_BITS = 16  # the longest learned code


@dataclass(frozen=True)
class ModelConfig:
    """Architecture of the effect model; `paper` is the seed paper's, `quick` trains in minutes."""

    bits: int = 8  # code length: at most 256 symbols, as the paper
    crop: int = 64  # input crop size in pixels
    conv_channels: tuple[int, ...] = (64, 128, 256, 512)  # DCGAN-like: kernel 4, stride 2, padding 1
    d_model: int = 128  # transformer width; code+action (44) is projected to it
    n_heads: int = 8  # 16 dimensions per head
    n_layers: int = 4  # TransformerEncoderLayer stack
    ff_dim: int = 2048  # PyTorch's default dim_feedforward
    dropout: float = 0.1  # PyTorch's default
    decoder_hidden: tuple[int, ...] = (256, 256, 256)  # three hidden layers with batch-norm
    attention: bool = True  # False: the DeepSym baseline, each object decoded from its own code
    tau: float = 1.0  # Gumbel-sigmoid temperature
    depth_ref: float = 2.0  # input depth d becomes (depth_ref - d) / depth_scale on object pixels
    depth_scale: float = 0.5
    dynamics_head: bool = False  # a head predicting each object's next code, trained jointly (TrainConfig.dynamics_weight)
    # True: the action reaches only the held object's token (the authors' per-object action: the grasped object is
    # marked), so whatever rides on it must learn that it moves from the others, through attention. False: the
    # scene's action beside every object's code (the paper's text).
    action_per_object: bool = False

    def __post_init__(self) -> None:
        """Refuse an architecture that cannot be built ([train.model] in a settings file): sizes, a zero divisor."""
        check_bounds(self, MODEL_BOUNDS)
        if self.d_model % self.n_heads:
            raise ValueError(f"d_model {self.d_model} is not divisible by n_heads {self.n_heads}")
        if self.crop % (2 ** len(self.conv_channels)):
            raise ValueError(f"crop {self.crop} must be divisible by 2^{len(self.conv_channels)}")
        if not 1 <= self.bits <= MAX_CODE_BITS:
            raise ValueError(f"bits={self.bits} must lie in 1..{MAX_CODE_BITS}")

    @staticmethod
    def from_preset(name: str, **overrides) -> "ModelConfig":
        """A named preset (paper, quick, recommended) with optional field overrides."""
        return preset(PRESETS, name, **overrides)

    def to_json(self) -> dict:
        """The config as plain JSON, as stored in checkpoints."""
        return dataclasses.asdict(self)

    @staticmethod
    def from_json(d: dict) -> "ModelConfig":
        """The config back from to_json's form."""
        fields = {f.name for f in dataclasses.fields(ModelConfig)}
        unknown = set(d) - fields
        if unknown:
            raise ValueError(f"unknown model config fields {sorted(unknown)}")
        return ModelConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in d.items()})


_SIZE = Bound(1, 65_536, integer=True)
MODEL_BOUNDS = {"crop": Bound(1, 1024, integer=True), "conv_channels": _SIZE, "d_model": _SIZE,
                "n_heads": Bound(1, 1024, integer=True), "n_layers": Bound(1, 256, integer=True), "ff_dim": _SIZE,
                "dropout": Bound(0.0, 1.0, hi_open=True), "decoder_hidden": _SIZE,
                "tau": Bound(0.0, 1000.0, lo_open=True), "depth_ref": Bound(-100.0, 100.0),
                "depth_scale": Bound(0.0, 100.0, lo_open=True)}

PRESETS = {
    "paper": ModelConfig(),
    # 32 px crops (the stored 64 px average-pooled) and narrow layers: about 20x less compute a crop.
    "quick": ModelConfig(crop=32, conv_channels=(32, 64, 64, 64), d_model=64, n_heads=4, n_layers=2, ff_dim=256,
                         decoder_hidden=(128, 128, 128)),
}
# the recipe that plans best (pretrained/recommended): the quick sizes, the action on the held object's token only
# (docs/RESULTS.md, "Riders and Table I")
PRESETS["recommended"] = dataclasses.replace(PRESETS["quick"], action_per_object=True)


class EffectOutput(NamedTuple):
    effect: torch.Tensor  # (B, K, 3) normalized displacement
    codes: torch.Tensor  # (B, K, bits) in {0, 1} (straight-through while training)
    logits: torch.Tensor  # (B, K, bits)
    next_logits: torch.Tensor | None = None  # (B, K, bits) the dynamics head's prediction of the post-state codes
    next_codes: torch.Tensor | None = None  # (B, K, bits) the encoder's codes of the post-state crops
    post_logits: torch.Tensor | None = None  # (B, K, bits) the encoder's logits of the post-state crops


def gumbel_sigmoid(logits: torch.Tensor, tau: float, training: bool,
                   generator: torch.Generator | None = None) -> torch.Tensor:
    """Binary codes: noisy hard sample with straight-through gradients in training, threshold at eval."""
    if not training:
        return (logits > 0).to(logits.dtype)
    u = torch.rand(logits.shape, generator=generator, device=logits.device, dtype=torch.float32)
    u = u.clamp(1e-6, 1 - 1e-6).to(logits.dtype)
    soft = torch.sigmoid((logits + torch.log(u) - torch.log1p(-u)) / tau)  # logistic = Gumbel difference
    hard = (soft > 0.5).to(logits.dtype)
    return hard + soft - soft.detach()


class Encoder(nn.Module):
    """Crop (3, S, S) -> code logits (bits,)."""

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        layers, c_in = [], 3
        for c in cfg.conv_channels:
            layers += [nn.Conv2d(c_in, c, 4, 2, 1, bias=False), nn.BatchNorm2d(c), nn.ReLU(inplace=True)]
            c_in = c
        self.conv = nn.Sequential(*layers)
        self.proj = nn.Linear(c_in, cfg.bits)
        self.cfg = cfg
        self.channels_last = True  # oneDNN's convolutions run faster on NHWC, with bf16 most of all

    def forward(self, crops: torch.Tensor) -> torch.Tensor:
        if crops.shape[-1] != self.cfg.crop:  # a smaller model crop: average-pool the stored 64 px crops
            if crops.shape[-1] % self.cfg.crop:
                raise ValueError(f"crops of {crops.shape[-1]} px cannot be pooled to {self.cfg.crop} px")
            crops = F.avg_pool2d(crops, crops.shape[-1] // self.cfg.crop)
        d = crops[:, :1]
        depth = torch.where(d > 0, (self.cfg.depth_ref - d) / self.cfg.depth_scale, torch.zeros_like(d))
        x = torch.cat([depth, crops[:, 1:]], dim=1)  # (N, 3, S, S)
        if self.channels_last:
            x = x.contiguous(memory_format=torch.channels_last)
        h = self.conv(x).mean(dim=(2, 3))  # (N, C)
        return self.proj(h)  # (N, bits)


def mlp(sizes: list[int], batch_norm: bool = True) -> nn.Sequential:
    """Dense layers of the given sizes with ReLU (and optional batch norm) between them."""
    layers: list[nn.Module] = []
    for a, b in zip(sizes[:-2], sizes[1:-1]):
        layers += [nn.Linear(a, b), *( [nn.BatchNorm1d(b)] if batch_norm else []), nn.ReLU(inplace=True)]
    layers.append(nn.Linear(sizes[-2], sizes[-1]))
    return nn.Sequential(*layers)


class CodeDynamics(nn.Module):
    """(code, action) per object -> dense -> one attention layer over the scene -> next-code logits.

    Trained with the effect model, its loss reaches the encoder on both sides, so codes are pushed
    to carry what decides their own next values and to be predictable: symbols that plan.
    """

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        h = cfg.d_model
        self.inp = nn.Sequential(nn.Linear(cfg.bits + N_ACTIONS, h), nn.ReLU())
        self.attn = nn.TransformerEncoderLayer(h, cfg.n_heads, 2 * h, 0.0, batch_first=True)
        self.out = nn.Linear(h, cfg.bits)

    def forward(self, codes: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
        b, k = mask.shape
        a = F.one_hot(actions.long(), N_ACTIONS).to(codes.dtype)
        h = self.inp(torch.cat([codes, a[:, None].expand(b, k, N_ACTIONS)], dim=-1))  # (B, K, D)
        h = self.attn(h, src_key_padding_mask=~mask)
        return self.out(h) * mask[..., None]  # (B, K, bits)


class AttentiveDeepSym(nn.Module):
    """Encoder -> (code, action) tokens -> transformer (or none) -> decoder, per object."""

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        self.cfg = cfg
        self.encoder = Encoder(cfg)
        self.inp = nn.Linear(cfg.bits + N_ACTIONS, cfg.d_model)
        if cfg.attention:
            layer = nn.TransformerEncoderLayer(cfg.d_model, cfg.n_heads, cfg.ff_dim, cfg.dropout, batch_first=True)
            self.attn = nn.TransformerEncoder(layer, cfg.n_layers, enable_nested_tensor=False)
        else:
            self.attn = None
        self.decoder = mlp([cfg.d_model, *cfg.decoder_hidden, 3])
        self.dynamics = CodeDynamics(cfg) if cfg.dynamics_head else None

    def encode(self, crops: torch.Tensor, mask: torch.Tensor,
               generator: torch.Generator | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, K, 3, S, S) crops -> codes (B, K, bits) and logits; padded slots are zero."""
        b, k = mask.shape
        logits_real = self.encoder(crops[mask])  # (N, bits)
        logits = logits_real.new_zeros(b, k, self.cfg.bits)
        logits[mask] = logits_real
        codes = gumbel_sigmoid(logits, self.cfg.tau, self.training, generator) * mask[..., None]
        return codes, logits

    def _tokens(self, codes: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor,
                held: torch.Tensor | None = None) -> torch.Tensor:
        """Each object's token (B, K, D): its code next to the scene's action; with action_per_object only the held
        object's token carries the action (held (B,): its index, -1 when nothing was grasped)."""
        b, k = mask.shape
        a = F.one_hot(actions.long(), N_ACTIONS).to(codes.dtype)[:, None].expand(b, k, N_ACTIONS)  # (B, K, 36)
        if self.cfg.action_per_object:
            if held is None or held.shape != actions.shape:
                raise ValueError("this model takes the action per object: give held, the index of the held object "
                                 "per scene (-1 for none), shaped like actions")
            a = a * (torch.arange(k, device=codes.device)[None] == held.long()[:, None])[..., None].to(codes.dtype)
        return self.inp(torch.cat([codes, a], dim=-1))

    @torch.no_grad()
    def attention_maps(self, codes: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor,
                       held: torch.Tensor | None = None) -> torch.Tensor | None:
        """How much each object attends to each other, per layer, averaged over heads: (layers, B, K, K), row i
        the weights object i's token puts on every object's (rows sum to 1 over real objects); None without
        attention. The same computation as decode's transformer, layer by layer (eval mode: no dropout)."""
        if self.attn is None:
            return None
        tok, maps = self._tokens(codes, mask, actions, held), []
        for layer in self.attn.layers:
            x = layer.norm1(tok) if layer.norm_first else tok
            maps.append(layer.self_attn(x, x, x, key_padding_mask=~mask, need_weights=True,
                                        average_attn_weights=True)[1])
            tok = layer(tok, src_key_padding_mask=~mask)
        return torch.stack(maps)

    def decode(self, codes: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor,
               held: torch.Tensor | None = None) -> torch.Tensor:
        """Codes (B, K, bits), mask (B, K), action ids (B,) [, held object per scene (B,)] -> normalized effects
        (B, K, 3)."""
        b, k = mask.shape
        tok = self._tokens(codes, mask, actions, held)
        if self.attn is not None:
            tok = self.attn(tok, src_key_padding_mask=~mask)  # (B, K, D)
        eff_real = self.decoder(tok[mask])  # (N, 3)
        eff = eff_real.new_zeros(b, k, 3)
        eff[mask] = eff_real
        return eff

    def forward(self, crops: torch.Tensor, mask: torch.Tensor, actions: torch.Tensor,
                generator: torch.Generator | None = None, post_crops: torch.Tensor | None = None,
                held: torch.Tensor | None = None) -> EffectOutput:
        """Effects and codes; with post_crops (the same objects after the action) also the post-state codes
        and logits, and with a dynamics head its prediction of those codes."""
        if crops.dim() != 5 or crops.shape[:2] != mask.shape or crops.shape[2] != 3 or crops.shape[-1] != crops.shape[-2]:
            raise ValueError(f"crops must be (B, K, 3, S, S) matching mask (B, K); got {tuple(crops.shape)} "
                             f"and {tuple(mask.shape)}")
        if actions.shape != mask.shape[:1]:
            raise ValueError(f"actions must be (B,), got {tuple(actions.shape)}")
        if actions.numel() and (int(actions.min()) < 0 or int(actions.max()) >= N_ACTIONS):
            raise ValueError(f"unknown action id: expected 0..{N_ACTIONS - 1}")
        codes, logits = self.encode(crops, mask, generator)
        effect = self.decode(codes, mask, actions, held)
        if post_crops is None:
            return EffectOutput(effect, codes, logits)
        if post_crops.shape != crops.shape:
            raise ValueError(f"post_crops {tuple(post_crops.shape)} must match crops {tuple(crops.shape)}")
        next_codes, post_logits = self.encode(post_crops, mask, generator)
        next_logits = None if self.dynamics is None else self.dynamics(codes, mask, actions)
        return EffectOutput(effect, codes, logits, next_logits, next_codes, post_logits)


def masked_mse(pred: torch.Tensor, target: torch.Tensor, mask: torch.Tensor,
               weight: torch.Tensor | None = None) -> torch.Tensor:
    """Mean squared error over real objects only; padded slots contribute nothing.

    weight (B, K) scales each object's error (e.g. riders up-weighted); the mean stays over real objects.
    """
    m = mask[..., None].to(pred.dtype)
    w = m if weight is None else m * weight[..., None].to(pred.dtype)
    return ((pred - target) ** 2 * w).sum() / (m.sum() * pred.shape[-1]).clamp_min(1.0)


def code_prediction_loss(next_logits: torch.Tensor, next_codes: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Binary cross-entropy of predicted next-code logits against the post-state codes, per bit of real objects.

    The target codes are detached: a gradient through them would make codes predictable by making them
    constant (tried: 3 distinct codes after 10 epochs, effect error doubled).
    """
    return F.binary_cross_entropy_with_logits(next_logits, next_codes.detach(), weight=mask[..., None].to(next_logits.dtype),
                                              reduction="sum") / (mask.sum() * next_logits.shape[-1]).clamp_min(1.0)


def code_stability_loss(pre_logits: torch.Tensor, post_logits: torch.Tensor, still: torch.Tensor,
                        margin: float = 1.0) -> torch.Tensor:
    """Hinge that makes a still object's code bits agree before and after the action, each at least `margin` from 0.

    Each bit's side is the sign of the two logits' sum, so neither crop is taken as the truth. Mean over
    the bits of all still objects ((B, K) bool).
    """
    side = torch.sign(pre_logits + post_logits).detach()
    side = torch.where(side == 0, torch.ones_like(side), side)
    per_bit = F.relu(margin - side * pre_logits) + F.relu(margin - side * post_logits)  # (B, K, bits)
    m = still[..., None].to(per_bit.dtype)
    return (per_bit * m).sum() / (m.sum() * pre_logits.shape[-1]).clamp_min(1.0)


def code_distinct_loss(logits: torch.Tensor, mask: torch.Tensor, margin: float = 1.0) -> torch.Tensor:
    """Hinge that gives every two real objects of a scene a bit on which their codes differ by a margin.

    Objects holding one code are moved alike by the rules and by the object-symmetric transition
    network, so no plan parts them again. For a pair (i, j) and bit b, the separation is how far
    both logits sit on opposite sides of 0 (min(s * l_ib, -s * l_jb), s the sign of l_ib - l_jb);
    the pair's best bit must reach `margin`. Mean over the pairs of real objects ((B, K) mask).
    """
    li, lj = logits[:, :, None, :], logits[:, None, :, :]  # (B, K, 1, bits), (B, 1, K, bits)
    side = torch.sign(li - lj).detach()
    side = torch.where(side == 0, torch.ones_like(side), side)
    separation = torch.minimum(side * li, -side * lj).amax(-1)  # (B, K, K): the pair's best-separated bit
    k = mask.shape[1]
    pairs = mask[:, :, None] & mask[:, None, :] & torch.triu(torch.ones(k, k, dtype=torch.bool, device=mask.device), 1)
    per_pair = F.relu(margin - separation) * pairs.to(separation.dtype)
    return per_pair.sum() / pairs.sum().clamp_min(1)
