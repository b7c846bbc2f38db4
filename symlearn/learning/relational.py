"""A relational effect model: unary bits per entity, relational bits per ordered pair, both learned.

The entities of a scene are its objects and the six table locations (symlearn.learning.entities: a fixed
window of the depth image over each table cell). Two convolutional trunks read the crops:

- an object's unary code z_o (`bits` bits, Gumbel-sigmoid: straight-through while training, a threshold at
  evaluation) comes from a trunk that sees only the crop's depth relative to its nearest pixel: what the
  object looks like, never where it is or how high it stands;
- a location's code and every relation come from a trunk that sees depth and image position;
- relation head 0, at(o, l): each object relates to exactly one location, a pair network's score of the object
  and each location through a hard Gumbel-softmax (the follow-up's softmax variant); with `cover`, to every
  location whose pick would lift it, a Gumbel-sigmoid per pair: a stick in the far row spans two or three
  cells and is lifted from any, so one location cannot say where it lies, while the set of cells it covers can;
- relation heads 1..n_relations, between objects: r_k(a, b) is the scaled dot product of a query of a with a
  key of b, minus a learned per-head bias, through a Gumbel-sigmoid (the authors' follow-up, arXiv
  2401.01123: binarized attention instead of a softmax). A pair holds two real, distinct objects.

The effect of an action is then predicted from the symbols alone. Each entity's token is made from its
code and kind; the action marks its two arguments, the pick and the release location. `rounds` times,
every entity adds, per head, the sum of the tokens of the entities it relates to (at(o, l) both ways: an
object hears its location, a location the objects at it), so a rider learns it moves from the stick it
rests on, the stick from the location it is at. A decoder maps each object's final token, beside the
tokens of the action's two locations, to its normalized displacement. An object learns that it is picked
only through the location it relates to, which makes at(o, l) link it to where it stands; no label says what
any relation means.

    >>> cfg = RelationalConfig.from_preset("quick")
    >>> model = RelationalDeepSym(cfg).eval()
    >>> obj = torch.zeros(2, 3, 3, 64, 64); loc = torch.zeros(2, 6, 3, 64, 64)
    >>> out = model(obj, torch.tensor([[1, 1, 0], [1, 0, 0]]).bool(), loc, torch.tensor([0, 35]))
    >>> tuple(out.effect.shape), tuple(out.relations.shape)
    ((2, 3, 3), (2, 4, 9, 9))
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import torch
import torch.nn as nn
import torch.nn.functional as F

from symlearn.config_file import Bound, check_bounds, preset
from symlearn.learning.models import gumbel_sigmoid, mlp
from symlearn.world import N_LOCATIONS

OBJECT, LOCATION = 0, 1  # the two kinds of entity


@dataclass(frozen=True)
class RelationalConfig:
    """Architecture of the relational effect model; `quick` trains on two CPU cores in minutes an epoch."""

    bits: int = 8  # unary bits of an object
    location_bits: int = 4  # unary bits of a location (6 locations need 3 to be told apart)
    n_relations: int = 3  # object-object relation heads r_k(a, b), besides the one object-location head
    crop: int = 32  # model crop; the stored 64 px crops are average-pooled to it
    conv_channels: tuple[int, ...] = (32, 64, 64, 64)
    feature_dim: int = 64  # the trunk's feature vector, read by the unary and relation heads
    key_dim: int = 16  # query and key width of a relation head
    hidden: int = 128  # token width of the effect predictor
    rounds: int = 2  # message-passing rounds over the relations
    decoder_hidden: tuple[int, ...] = (128, 128)
    tau: float = 1.0  # Gumbel-sigmoid temperature
    depth_ref: float = 2.0  # as ModelConfig: input depth d becomes (depth_ref - d) / depth_scale on seen pixels
    depth_scale: float = 0.5
    support: bool = False  # head 1 is rests-on: each object rests on one other object or on the table
    cover: bool = False  # head 0 is at(o, l) for every location whose pick would lift o, not one choice per object


    def __post_init__(self) -> None:
        check_bounds(self, RELATIONAL_BOUNDS)
        if self.crop % (2 ** len(self.conv_channels)):
            raise ValueError(f"crop {self.crop} must be divisible by 2^{len(self.conv_channels)}")

    @staticmethod
    def from_preset(name: str, **overrides) -> "RelationalConfig":
        """A named preset with optional field overrides."""
        return preset(RELATIONAL_PRESETS, name, "relational preset", **overrides)

    def to_json(self) -> dict:
        return dataclasses.asdict(self)

    @staticmethod
    def from_json(d: dict) -> "RelationalConfig":
        fields = {f.name for f in dataclasses.fields(RelationalConfig)}
        unknown = set(d) - fields
        if unknown:
            raise ValueError(f"unknown relational model config fields {sorted(unknown)}")
        return RelationalConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in d.items()})


_SIZE = Bound(1, 65_536, integer=True)
RELATIONAL_BOUNDS = {"bits": Bound(1, 16, integer=True), "location_bits": Bound(1, 16, integer=True),
                     "n_relations": Bound(1, 32, integer=True), "crop": Bound(1, 1024, integer=True),
                     "conv_channels": _SIZE, "feature_dim": _SIZE, "key_dim": _SIZE, "hidden": _SIZE,
                     "rounds": Bound(1, 8, integer=True), "decoder_hidden": _SIZE,
                     "tau": Bound(0.0, 1000.0, lo_open=True), "depth_ref": Bound(-100.0, 100.0),
                     "depth_scale": Bound(0.0, 100.0, lo_open=True)}
RELATIONAL_PRESETS = {"quick": RelationalConfig(),
                      # one object-object head, rests-on, as a hard attention over the other objects and the table
                      "support": RelationalConfig(n_relations=1, rounds=3, support=True),
                      # and at(o, l) holds for every cell a pick at which lifts o (a far-row stick: two or three)
                      "cover": RelationalConfig(n_relations=1, rounds=3, support=True, cover=True)}


def hard_softmax(logits: torch.Tensor, tau: float, training: bool,
                 generator: torch.Generator | None = None) -> torch.Tensor:
    """One-hot choice over the last axis: a Gumbel-softmax sample with straight-through gradients in training,
    the argmax at evaluation."""
    if training:
        u = torch.rand(logits.shape, generator=generator, device=logits.device).clamp(1e-6, 1 - 1e-6)
        soft = torch.softmax((logits - torch.log(-torch.log(u))) / tau, -1)
    else:
        soft = torch.softmax(logits, -1)
    hard = F.one_hot(soft.argmax(-1), logits.shape[-1]).to(logits.dtype)
    return hard + soft - soft.detach() if training else hard


class RelationalOutput(NamedTuple):
    effect: torch.Tensor  # (B, K, 3) normalized displacement of each object
    codes: torch.Tensor  # (B, K, bits) object unary bits
    location_codes: torch.Tensor  # (B, L, location_bits)
    relations: torch.Tensor  # (B, R, E, E) relational bits, entities = K objects then L locations
    relation_logits: torch.Tensor  # (B, R, E, E)


class Trunk(nn.Module):
    """Crop (3, S, S) -> feature vector; the seed model's encoder without its code layer.

    With shape_only, the trunk sees one channel: the crop's depth relative to its nearest visible pixel, no
    image position and no distance to the camera. An object's unary code is read from such a trunk, so it can
    say what the object looks like (its shape, how it lies) but not where it is: where an object is, and what
    it stands on, can only reach the effect predictor through relations.
    """

    def __init__(self, cfg: RelationalConfig, shape_only: bool = False) -> None:
        super().__init__()
        self.shape_only = shape_only
        layers, c_in = [], 1 if shape_only else 3
        for c in cfg.conv_channels:
            layers += [nn.Conv2d(c_in, c, 4, 2, 1, bias=False), nn.BatchNorm2d(c), nn.ReLU(inplace=True)]
            c_in = c
        self.conv = nn.Sequential(*layers)
        self.proj = nn.Linear(c_in, cfg.feature_dim)
        self.cfg = cfg

    def forward(self, crops: torch.Tensor) -> torch.Tensor:
        if crops.shape[-1] % self.cfg.crop:
            raise ValueError(f"crops of {crops.shape[-1]} px cannot be pooled to {self.cfg.crop} px")
        if self.shape_only:  # relative depth on the stored pixels, then pooled
            d = crops[:, :1]
            seen = d > 0
            nearest = torch.where(seen, d, torch.full_like(d, float("inf"))).amin(dim=(2, 3), keepdim=True)
            x = torch.where(seen, 1.0 - (d - nearest) / 0.1, torch.zeros_like(d))  # 1 at the nearest pixel
        else:
            x = crops
        if x.shape[-1] != self.cfg.crop:
            x = F.avg_pool2d(x, x.shape[-1] // self.cfg.crop)
        if not self.shape_only:
            d = x[:, :1]
            depth = torch.where(d > 0, (self.cfg.depth_ref - d) / self.cfg.depth_scale, torch.zeros_like(d))
            x = torch.cat([depth, x[:, 1:]], dim=1)
        return self.proj(self.conv(x).mean(dim=(2, 3)))


class RelationalDeepSym(nn.Module):
    """Entity crops -> unary and relational bits -> message passing over the bits -> object effects."""

    def __init__(self, cfg: RelationalConfig) -> None:
        super().__init__()
        self.cfg = cfg
        f, r, dk, h = cfg.feature_dim, cfg.n_relations, cfg.key_dim, cfg.hidden
        self.trunk = Trunk(cfg)  # where and what: read by the relation heads and the location codes
        self.shape_trunk = Trunk(cfg, shape_only=True)  # what alone: read by the object codes
        self.kind = nn.Embedding(2, f)
        self.object_code = nn.Linear(f, cfg.bits)
        self.location_code = nn.Linear(f, cfg.location_bits)
        # at(o, l) scores a pair by a small network over both entities' features (a dot product of projections
        # learned the alignment of objects and cells several times slower)
        self.at_pair = nn.Sequential(nn.Linear(2 * f, h), nn.ReLU(), nn.Linear(h, 1))
        self.soft_at = False  # training only: at(o, l) as softmax weights, not a hard choice (a warm-up)
        self.query = nn.Linear(f, r * dk)
        self.key = nn.Linear(f, r * dk)
        self.bias = nn.Parameter(torch.zeros(r))
        if cfg.support:  # the score of "rests on the table", the support head's choice beside the other objects
            self.table = nn.Linear(f, 1)
        width = max(cfg.bits, cfg.location_bits)
        self.token = nn.Linear(width + 4, h)  # code, kind (2), is the pick location, is the release location
        self.heads = heads = r + 1 + int(cfg.support)  # message heads: rests-on carries messages both ways, as two
        self.values = nn.ModuleList(nn.Linear(h, heads * h) for _ in range(cfg.rounds))
        self.updates = nn.ModuleList(nn.Sequential(nn.Linear(heads * h + h, h), nn.ReLU(), nn.Linear(h, h))
                                     for _ in range(cfg.rounds))
        self.norms = nn.ModuleList(nn.LayerNorm(h) for _ in range(cfg.rounds))
        self.decoder = mlp([3 * h, *cfg.decoder_hidden, 3], batch_norm=False)

    def features(self, obj_crops: torch.Tensor, mask: torch.Tensor, loc_crops: torch.Tensor) -> torch.Tensor:
        """(B, E, feature_dim) features of the K objects then the L locations; padded objects are zero."""
        b, k = mask.shape
        n_loc = loc_crops.shape[1]
        real = self.trunk(torch.cat([obj_crops[mask], loc_crops.flatten(0, 1)]))
        n_obj = int(mask.sum())
        feats = real.new_zeros(b, k + n_loc, real.shape[-1])
        feats[:, :k][mask] = real[:n_obj]
        feats[:, k:] = real[n_obj:].view(b, n_loc, -1)
        kinds = torch.cat([torch.full((k,), OBJECT), torch.full((n_loc,), LOCATION)]).to(mask.device)
        return feats + self.kind(kinds)[None]

    def object_logits(self, obj_crops: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """(B, K, bits) logits of the objects' unary codes (zero for padding)."""
        b, k = mask.shape
        logits = obj_crops.new_zeros(b, k, self.cfg.bits)
        logits[mask] = self.object_code(self.shape_trunk(obj_crops[mask]))
        return logits

    def symbols(self, obj_crops: torch.Tensor, mask: torch.Tensor, loc_crops: torch.Tensor,
                generator: torch.Generator | None = None):
        """Unary codes (B, K, bits), location codes (B, L, location_bits), relations and their logits
        (B, R, E, E), and the entity mask (B, E)."""
        b, k = mask.shape
        n_loc = loc_crops.shape[1]
        feats = self.features(obj_crops, mask, loc_crops)
        training, tau = self.training, self.cfg.tau
        codes = gumbel_sigmoid(self.object_logits(obj_crops, mask), tau, training, generator) * mask[..., None]
        loc_codes = gumbel_sigmoid(self.location_code(feats[:, k:]), tau, training, generator)
        r, dk = self.cfg.n_relations, self.cfg.key_dim
        e = k + n_loc
        ent = torch.cat([mask, torch.ones(b, n_loc, dtype=torch.bool, device=mask.device)], dim=1)
        logits = feats.new_zeros(b, r + 1, e, e)
        rel = feats.new_zeros(b, r + 1, e, e)
        # head 0, at(o, l): each object is at exactly one location (a hard Gumbel-softmax over the locations)
        pair = torch.cat([feats[:, :k, None].expand(b, k, n_loc, -1), feats[:, None, k:].expand(b, k, n_loc, -1)], -1)
        at_logits = self.at_pair(pair).squeeze(-1)  # (B, K, L)
        logits[:, 0, :k, k:] = at_logits
        if self.cfg.cover:  # every location whose pick lifts o: one binary choice per pair
            at = gumbel_sigmoid(at_logits, tau, training, generator)
        elif training and self.soft_at:
            at = torch.softmax(at_logits, -1)
        else:
            at = hard_softmax(at_logits, tau, training, generator)
        rel[:, 0, :k, k:] = at * mask[..., None]
        # heads 1..r, between objects: free binary relations (Gumbel-sigmoid)
        obj = feats[:, :k]
        q = self.query(obj).view(b, k, r, dk).transpose(1, 2)  # (B, r, K, dk)
        key = self.key(obj).view(b, k, r, dk).transpose(1, 2)
        oo = q @ key.transpose(-1, -2) / dk ** 0.5 - self.bias[None, :, None, None]
        pairs = mask[:, :, None] & mask[:, None, :] & ~torch.eye(k, dtype=torch.bool, device=mask.device)[None]
        logits[:, 1:, :k, :k] = oo
        rel[:, 1:, :k, :k] = gumbel_sigmoid(oo, tau, training, generator) * pairs[:, None].to(oo.dtype)
        if self.cfg.support:  # head 1, rests-on(a, b): one choice per object among the others and the table
            eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
            table = self.table(obj).squeeze(-1)  # (B, K), written on the diagonal: "rests on itself" = the table
            sup = torch.where(eye, table[:, :, None], oo[:, 0])
            sup = sup.masked_fill(~(pairs | eye), -1e4)
            logits[:, 1, :k, :k] = sup
            choice = hard_softmax(sup, tau, training, generator)
            rel[:, 1, :k, :k] = choice * pairs.to(choice.dtype)
        return codes, loc_codes, rel, logits, ent

    def effect_parameters(self) -> list[nn.Parameter]:
        """The weights of the effect predictor that reads the symbols (decode): the tokens, the message passing
        and the decoder; no weight that computes a symbol."""
        parts = (self.token, self.values, self.updates, self.norms, self.decoder)
        return [p for part in parts for p in part.parameters()]

    def decode(self, codes: torch.Tensor, loc_codes: torch.Tensor, rel: torch.Tensor, ent: torch.Tensor,
               actions: torch.Tensor) -> torch.Tensor:
        """Effects (B, K, 3) from the symbols and the action ids (B,) alone."""
        b, k, _ = codes.shape
        n_loc = loc_codes.shape[1]
        width = self.token.in_features - 4
        z = torch.cat([F.pad(codes, (0, width - codes.shape[-1])), F.pad(loc_codes, (0, width - loc_codes.shape[-1]))], 1)
        kinds = torch.cat([torch.full((k,), OBJECT), torch.full((n_loc,), LOCATION)]).to(codes.device)
        kind = F.one_hot(kinds, 2).to(z.dtype)[None].expand(b, -1, -1)
        # the action marks its two arguments, the pick and the release location; an object learns whether it is
        # picked only through the location it relates to, so at(o, l) must link it to the location it stands at
        pick, release = actions.long() // N_LOCATIONS, actions.long() % N_LOCATIONS
        flags = z.new_zeros(b, k + n_loc, 2)
        rows = torch.arange(b, device=codes.device)
        flags[rows, k + pick, 0] = 1.0
        flags[rows, k + release, 1] = 1.0
        tok = self.token(torch.cat([z, kind, flags], -1)) * ent[..., None]
        heads, h = self.heads, self.cfg.hidden
        # at(o, l) carries messages both ways: an object hears its location, a location the objects at it
        links = torch.cat([rel[:, :1] + rel[:, :1].transpose(-1, -2), rel[:, 1:]], 1)
        if self.cfg.support:  # a support hears what rests on it: the object under the held one is not picked
            links = torch.cat([links, rel[:, 1:2].transpose(-1, -2)], 1)
        for values, update, norm in zip(self.values, self.updates, self.norms):
            v = values(tok).view(b, -1, heads, h).transpose(1, 2)  # (B, heads, E, H)
            msg = (links @ v).transpose(1, 2).reshape(b, -1, heads * h)  # sum over related entities, per head
            tok = norm(tok + update(torch.cat([tok, msg], -1))) * ent[..., None]
        # the action's two arguments, its pick and release location, are read by every object's decoder
        args = torch.cat([tok[rows, k + pick], tok[rows, k + release]], -1)[:, None].expand(b, k, 2 * h)
        return self.decoder(torch.cat([tok[:, :k], args], -1)) * ent[:, :k, None]

    def forward(self, obj_crops: torch.Tensor, mask: torch.Tensor, loc_crops: torch.Tensor, actions: torch.Tensor,
                generator: torch.Generator | None = None) -> RelationalOutput:
        if obj_crops.dim() != 5 or obj_crops.shape[:2] != mask.shape or loc_crops.dim() != 5:
            raise ValueError(f"crops must be (B, K, 3, S, S) matching mask (B, K) and (B, L, 3, S, S); got "
                             f"{tuple(obj_crops.shape)}, {tuple(mask.shape)}, {tuple(loc_crops.shape)}")
        if loc_crops.shape[1] != N_LOCATIONS:
            raise ValueError(f"expected {N_LOCATIONS} location crops, got {loc_crops.shape[1]}")
        if actions.shape != mask.shape[:1]:
            raise ValueError(f"actions must be (B,), got {tuple(actions.shape)}")
        codes, loc_codes, rel, logits, ent = self.symbols(obj_crops, mask, loc_crops, generator)
        return RelationalOutput(self.decode(codes, loc_codes, rel, ent, actions), codes, loc_codes, rel, logits)
