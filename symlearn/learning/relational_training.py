"""Training the relational effect model (symlearn.learning.relational) by effect prediction alone.

One or more data sets (symlearn collect) are read, padded to one object count, and every scene gets the
six location crops (symlearn.learning.entities). The loss is the mean squared error of the normalized
displacement of every real object, plus three terms that shape the symbols:

- grasp (`grasp_weight`): when the robot's suction tool held an object, that object's at(o, .) is pulled
  to the pick location (cross-entropy). The robot knows what it grasped and where; this ties the learned
  at(o, l) to a place, and the shared pair network carries it to every other object (without it, at(o, l)
  stayed at chance for 5 epochs on 1-5-object data and the effect error at 37 mm);
- code stability (`code_stability`): an object's unary code is the same before and after the action, so
  unary bits say what an object is, and relations say where it is and on what;
- relation sparsity (`relation_sparsity`): object-object relations stay off where they do not help.

Scenes where an object rides on the held one are drawn `rider_scene_repeat` times an epoch (3.6% of the
paper set's scenes hold a rider). Each epoch ends with a checkpoint (`relations_last.pt`: weights,
optimizer, epoch), so an interrupted run resumes where it stopped; the epoch with the lowest validation
error is kept as `relations.pt`.

    symlearn train-relations --data data/paper_a data/k15 --out RUN   # (docs/RELATIONS.md)
"""
from __future__ import annotations

import dataclasses
import io
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
import torch
import torch.nn.functional as F

from pddl_export.files import atomic_write_bytes, atomic_write_text, sha256_file
from symlearn.config_file import Bound, check_bounds, preset
from symlearn.data.dataset import InteractionData, data_fingerprint, load_manifest, load_split
from symlearn.data.model_input import model_inputs
from symlearn.data.statistics import rider_mask
from symlearn.learning.checkpoint import BlobKind, guarded_blob
from symlearn.learning.entities import entity_inputs, location_crops, location_windows
from symlearn.learning.models import code_stability_loss, masked_mse
from symlearn.learning.relational import RelationalConfig, RelationalDeepSym
from symlearn.provenance import versions
from symlearn.sim.camera import CameraConfig
from symlearn.world import N_LOCATIONS

CHECKPOINT, LAST = "relations.pt", "relations_last.pt"
STORED_CROP = 64  # the data sets' crop size
RELATIONS_KIND, RELATIONS_FORMAT = "symlearn-relational-model", 1


class RelationsError(ValueError):
    """A relational checkpoint that is missing, foreign, of another format or damaged."""


RELATIONAL_MODEL = BlobKind(RELATIONS_KIND, RELATIONS_FORMAT, "relational-model", "relational checkpoint",
                            "no relational model at {path}; run 'symlearn train-relations' first", RelationsError)


@dataclass(frozen=True)
class RelationalTrainConfig:
    """How the relational model is trained; the model's sizes are in `model`."""

    model: RelationalConfig = RelationalConfig()
    epochs: int = 30
    batch_size: int = 64
    lr: float = 1e-3
    lr_min_ratio: float = 0.05  # cosine schedule down to lr * this
    rider_scene_repeat: int = 3
    relation_sparsity: float = 0.05  # weight of the mean probability of the object-object relations
    code_stability: float = 0.0  # weight of the hinge that keeps an object's unary code across the action
    soft_at_epochs: int = 0  # the first epochs read at(o, l) as softmax weights (a warm-up), then a hard choice
    grasp_weight: float = 1.0  # weight of the cross-entropy that puts the grasped object at the pick location
    ride_weight: float = 0.0  # weight of the cross-entropy that makes r1(a, held) say whether a rode along
    support_weight: float = 0.0  # weight of support_loss (a model with a rests-on head: model.support)
    post_support_weight: float = 0.0  # weight of post_support_loss, read on the scene after the action
    support_exclusive: float = 0.0  # weight of the penalty on more than one object resting on the same one
    seed: int = 0

    def __post_init__(self) -> None:
        check_bounds(self, TRAIN_BOUNDS)
        if (self.support_weight or self.post_support_weight or self.support_exclusive) and not self.model.support:
            raise ValueError("support_weight, post_support_weight and support_exclusive need a model with a rests-on "
                             "head (model.support)")

    @staticmethod
    def from_preset(name: str, **overrides) -> "RelationalTrainConfig":
        """A named preset (TRAIN_PRESETS) with optional field overrides."""
        return preset(TRAIN_PRESETS, name, "relational training preset", **overrides)

    def to_json(self) -> dict:
        d = dataclasses.asdict(self)
        d["model"] = self.model.to_json()
        return d

    @staticmethod
    def from_json(d: dict) -> "RelationalTrainConfig":
        d = dict(d)
        return RelationalTrainConfig(model=RelationalConfig.from_json(d.pop("model")), **d)


TRAIN_BOUNDS = {"epochs": Bound(1, 100_000, integer=True), "batch_size": Bound(1, 65_536, integer=True),
                "lr": Bound(0.0, 10.0, lo_open=True), "lr_min_ratio": Bound(0.0, 1.0),
                "rider_scene_repeat": Bound(1, 100, integer=True),
                "relation_sparsity": Bound(0.0, 100.0), "code_stability": Bound(0.0, 100.0),
                "soft_at_epochs": Bound(0, 100_000, integer=True), "grasp_weight": Bound(0.0, 100.0),
                "ride_weight": Bound(0.0, 100.0), "support_weight": Bound(0.0, 100.0),
                "post_support_weight": Bound(0.0, 100.0), "support_exclusive": Bound(0.0, 100.0),
                "seed": Bound(0, 2**63 - 1, integer=True)}
TRAIN_PRESETS = {
    # three free object-object heads (binarized attention), none told what to mean
    "attention": RelationalTrainConfig(),
    # one rests-on head, a hard attention over the other objects and the table, shaped by what the grasp showed
    "support": RelationalTrainConfig(model=RelationalConfig.from_preset("support"), support_weight=1.0),
    # and the rests-on head read on the scene after the action: where the held object landed, what kept its support
    "support-post": RelationalTrainConfig(model=RelationalConfig.from_preset("support"), support_weight=1.0,
                                          post_support_weight=1.0),
    # and at most one object on each: the top of a three-object stack rests on the middle one, not the bottom
    "support-exclusive": RelationalTrainConfig(model=RelationalConfig.from_preset("support"), support_weight=1.0,
                                               post_support_weight=1.0, support_exclusive=1.0),
}


@dataclass
class EntitySplit:
    """A split's scenes as tensors: object crops and origins, location crops, actions, normalized effects."""

    depth: torch.Tensor  # (N, K, 64, 64) float16
    origin: torch.Tensor  # (N, K, 2) float32
    mask: torch.Tensor  # (N, K) bool
    loc_depth: torch.Tensor  # (N, L, 64, 64) float16
    action: torch.Tensor  # (N,) int64
    effect: torch.Tensor  # (N, K, 3) float32, normalized
    rider: torch.Tensor  # (N, K) bool
    post_depth: torch.Tensor  # (N, K, 64, 64) float16, the objects after the action
    post_origin: torch.Tensor  # (N, K, 2) float32
    held: torch.Tensor  # (N,) int64: the object the suction tool held, -1 for none
    post_loc_depth: torch.Tensor | None = None  # (N, L, 64, 64) float16, the locations after the action (if asked)

    def __len__(self) -> int:
        return int(self.action.shape[0])

    def inputs(self, idx: torch.Tensor, windows: torch.Tensor):
        """Model inputs for rows idx: object crops, mask, location crops, actions."""
        obj, loc = entity_inputs(self.depth[idx], self.origin[idx], self.loc_depth[idx], windows)
        return obj, self.mask[idx], loc, self.action[idx]

    def post_inputs(self, idx: torch.Tensor, windows: torch.Tensor):
        """The scene after the action, rows idx: object crops, mask, location crops."""
        obj, loc = entity_inputs(self.post_depth[idx], self.post_origin[idx], self.post_loc_depth[idx], windows)
        return obj, self.mask[idx], loc


def pad_objects(data: InteractionData, k: int) -> dict[str, np.ndarray]:
    """A split's object arrays padded with empty slots to k objects."""
    extra = k - data.effect.shape[1]
    def pad(a: np.ndarray) -> np.ndarray:
        return np.pad(a, [(0, 0), (0, extra)] + [(0, 0)] * (a.ndim - 2)) if extra else a
    return {"depth": pad(data.pre_depth), "origin": pad(data.pre_origin), "mask": pad(data.mask),
            "post_depth": pad(data.post_depth), "post_origin": pad(data.post_origin),
            "effect": pad(data.effect), "rider": pad(rider_mask(data))}


def camera_of(root: Path) -> CameraConfig:
    """The camera a data set was rendered with (its manifest's settings)."""
    return CameraConfig.from_json(load_manifest(root)["settings"]["sim"]["camera"])


def entity_split(datas: Sequence[InteractionData], windows: np.ndarray, k: int,
                 mean: np.ndarray | None = None, std: np.ndarray | None = None,
                 post: bool = False) -> tuple[EntitySplit, np.ndarray, np.ndarray]:
    """One split of several data sets (load_split), padded to k objects, with location crops (also after the
    action, with `post`); effects normalized by (mean, std), computed from this split when not given."""
    parts = [pad_objects(d, k) | {"n": d.n_objects, "action": d.action, "held": d.grasped} for d in datas]
    cat = {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}
    if mean is None:
        eff = cat["effect"][cat["mask"]].astype(np.float64)
        mean, std = eff.mean(0).astype(np.float32), np.maximum(eff.std(0), 1e-6).astype(np.float32)
    loc = location_crops(cat["depth"], cat["origin"], cat["n"], windows)
    mask = torch.from_numpy(cat["mask"])
    eff = torch.from_numpy(((cat["effect"] - mean) / std).astype(np.float32)) * mask[..., None]
    return EntitySplit(torch.from_numpy(cat["depth"]), torch.from_numpy(cat["origin"].astype(np.float32)), mask,
                       torch.from_numpy(loc), torch.from_numpy(cat["action"].astype(np.int64)), eff,
                       torch.from_numpy(cat["rider"]), torch.from_numpy(cat["post_depth"]),
                       torch.from_numpy(cat["post_origin"].astype(np.float32)),
                       torch.from_numpy(cat["held"].astype(np.int64)),
                       torch.from_numpy(location_crops(cat["post_depth"], cat["post_origin"], cat["n"], windows))
                       if post else None), mean, std


def grasp_loss(logits: torch.Tensor, held: torch.Tensor, actions: torch.Tensor, k: int) -> torch.Tensor:
    """Cross-entropy of at(o, .) for the object the robot grasped, against the action's pick location.

    The robot knows what it did: when its suction tool held an object, that object stood at the pick location.
    This is the one signal that ties the learned at(o, l) to a place; every other object's at(o, l) comes from
    the same pair network, never from a label."""
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    at_logits = logits[rows, 0, held[rows], k:]  # (n, L)
    return F.cross_entropy(at_logits, actions[rows] // N_LOCATIONS)


def ride_loss(logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor, mask: torch.Tensor,
              at: torch.Tensor | None = None, actions: torch.Tensor | None = None) -> torch.Tensor:
    """Binary cross-entropy that makes r1(a, b) say "a rests on b", from what the robot saw its grasp do.

    - r1(a, held): whether object a rode along with the held object (an effect the robot saw; a stack beside
      the stick that did not move is a negative example);
    - r1(held, b) = 1 for every object b that stayed at the pick location, as the model's own at(o, l) places
      them (`at`, (B, K+L, K+L) relation 0, detached; `actions` give the pick location): a pick lifts the top
      object, so whatever stays where it was picked lay under it.
    """
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    k = mask.shape[1]
    h = held[rows]
    row_logits = logits[rows, 1, :k, h]  # (n, K): r1(a, held) for every a of the scene
    others = mask[rows] & (torch.arange(k, device=mask.device)[None] != h[:, None])
    loss = F.binary_cross_entropy_with_logits(row_logits[others], rider[rows][others].to(logits.dtype))
    if at is None or actions is None:
        return loss
    pick = actions[rows] // N_LOCATIONS
    at_pick = at[rows, :k, k:][torch.arange(len(rows)), :, pick] > 0.5  # (n, K): placed at the pick location
    under = others & at_pick & ~rider[rows]
    if under.any():
        col_logits = logits[rows, 1, h, :k]  # (n, K): r1(held, b)
        loss = loss + F.binary_cross_entropy_with_logits(col_logits[under], torch.ones_like(col_logits[under]))
    return loss


def log_prob_of(logp: torch.Tensor, members: torch.Tensor) -> torch.Tensor:
    """log P(the choice is one of `members`) from log-probabilities over the last axis and a same-shape bool mask."""
    return torch.logsumexp(logp.masked_fill(~members, -1e4), -1)


def support_loss(logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor, mask: torch.Tensor,
                 at: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
    """Cross-entropy of the rests-on head (relation 1 of a model.support model) from what the robot saw its grasp do.

    Head 1 picks, for each object a, one support: another object b (logits[.., 1, a, b]) or the table (the
    diagonal). In a scene where the suction tool held object h (picked at location p):
    - h rests on one of the objects that stayed at p (the model's own at, detached), or on the table if none did:
      a pick lifts the top object, so what stays where it was picked lay under it;
    - an object that rode along rests on h or on another rider;
    - an object that did not ride rests on neither h nor a rider.
    Each is a set-valued target (the log of the probability summed over the set), so a three-object stack does
    not have to say which of the two below it h touches; the network learns that from two-object stacks."""
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    k = mask.shape[1]
    n = len(rows)
    ar = torch.arange(n, device=mask.device)
    h, m, rid = held[rows], mask[rows], rider[rows]
    logp = torch.log_softmax(logits[rows, 1, :k, :k], -1)  # (n, K, K); the diagonal is "on the table"
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    is_h = F.one_hot(h, k).bool()
    pick = actions[rows] // N_LOCATIONS
    stayed = m & ~is_h & ~rid & (at[rows, :k, k:][ar, :, pick] > 0.5)  # (n, K)
    target_h = torch.where(stayed.any(1, keepdim=True), stayed, is_h)  # h's candidates (or itself: the table)
    loss_h = -log_prob_of(logp[ar, h], target_h)
    carried = is_h | rid  # (n, K): h and its riders
    loss = loss_h.mean()
    sets = carried[:, None, :] & ~eye  # (n, K, K): for object a, the carried objects other than itself
    lse = log_prob_of(logp, sets)  # (n, K): log P(a rests on a carried object)
    riders = rid & m
    if riders.any():
        loss = loss - lse[riders].mean()
    still = m & ~carried
    if still.any():
        loss = loss - torch.log1p(-lse[still].exp().clamp(max=1 - 1e-6)).mean()
    return loss


def post_support_loss(pre_logits: torch.Tensor, post_logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor,
                      mask: torch.Tensor, post_at: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
    """The rests-on head read on the scene after the action (model.support), from what the robot did:
    - where it released the held object h (location r), h now rests on one of the objects at r that it did not
      carry there (the model's own at on the scene after, detached), or on the table if there is none;
    - every other object rests on what it rested on before (a pick-and-place moves only h and its riders, which
      keep their supports): the cross-entropy of its support after against its support before, both ways.
    Scenes where nothing was held (a pick at an empty location) change nothing: every object keeps its support."""
    k = mask.shape[1]
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    pre = torch.log_softmax(pre_logits[:, 1, :k, :k], -1)
    post = torch.log_softmax(post_logits[:, 1, :k, :k], -1)
    is_h = F.one_hot(held.clamp_min(0), k).bool() & (held >= 0)[:, None]
    keep = mask & ~is_h  # (B, K)
    loss = pre.new_zeros(())
    if keep.any():  # symmetric cross-entropy of the two supports (each side detached in turn)
        ce = -(pre.exp().detach() * post).sum(-1) - (post.exp().detach() * pre).sum(-1)
        loss = loss + ce[keep].mean() / 2
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if len(rows):
        ar = torch.arange(len(rows), device=mask.device)
        h = held[rows]
        release = actions[rows] % N_LOCATIONS
        carried = is_h[rows] | rider[rows]
        below = mask[rows] & ~carried & (post_at[rows, :k, k:][ar, :, release] > 0.5)
        target = torch.where(below.any(1, keepdim=True), below, is_h[rows])
        loss = loss - log_prob_of(post[rows][ar, h], target).mean()
    return loss


def support_exclusion(logits: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean squared excess over one of the objects resting on each object (rests-on probabilities summed per
    support): in a three-object stack the top rests on the middle one, not also on the bottom one, which the
    grasp alone cannot tell (both stayed where the top was picked). A stick with a cube on each end is the
    exception the penalty pays for; it is rare in the data."""
    k = mask.shape[1]
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    p = torch.softmax(logits[:, 1, :k, :k], -1).masked_fill(eye, 0.0) * mask[:, :, None]
    excess = F.relu(p.sum(1) - 1.0) * mask
    return (excess ** 2).sum() / mask.sum().clamp_min(1)


def relation_density(logits: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean probability of the object-object relations (heads 1.. of (B, R, E, E) logits) over the real pairs: a
    penalty that keeps a relation off where it does not help predict effects."""
    k = mask.shape[1]
    pairs = (mask[:, :, None] & mask[:, None, :] & ~torch.eye(k, dtype=torch.bool, device=mask.device)[None])
    p = torch.sigmoid(logits[:, 1:, :k, :k]) * pairs[:, None]
    return p.sum() / (pairs.sum() * (logits.shape[1] - 1)).clamp_min(1)


@torch.no_grad()
def evaluate(model: RelationalDeepSym, split: EntitySplit, windows: torch.Tensor, std: np.ndarray,
             batch_size: int = 256) -> dict:
    """Validation loss and mean absolute error in mm: all objects, and riders alone."""
    model.eval()
    err, n, loss, rider_err, n_rider = torch.zeros(3), 0, 0.0, torch.zeros(3), 0
    s = torch.from_numpy(std)
    for a in range(0, len(split), batch_size):
        idx = torch.arange(a, min(a + batch_size, len(split)))
        obj, mask, loc, act = split.inputs(idx, windows)
        pred = model(obj, mask, loc, act).effect
        tgt = split.effect[idx]
        loss += float(masked_mse(pred, tgt, mask)) * len(idx)
        e = (pred - tgt).abs() * s * 1000
        err += e[mask].sum(0)
        n += int(mask.sum())
        r = split.rider[idx]
        rider_err += e[r].sum(0)
        n_rider += int(r.sum())
    return {"loss": loss / max(len(split), 1), "mae_mm": float((err / max(n, 1)).mean()),
            "rider_mae_mm": float((rider_err / max(n_rider, 1)).mean()) if n_rider else None, "riders": n_rider}


def epoch_order(split: EntitySplit, repeat: int, gen: torch.Generator) -> torch.Tensor:
    """A shuffled epoch of row indices, each scene with a rider present `repeat` times."""
    rows = torch.arange(len(split))
    with_rider = rows[split.rider.any(1)]
    rows = torch.cat([rows] + [with_rider] * (repeat - 1))
    return rows[torch.randperm(len(rows), generator=gen)]


def batch_loss(model: RelationalDeepSym, cfg: RelationalTrainConfig, tr: EntitySplit, idx: torch.Tensor,
               windows: torch.Tensor, gen: torch.Generator) -> torch.Tensor:
    """One training batch's loss: the effect error plus each term of cfg whose weight is not zero."""
    obj, mask, loc, act = tr.inputs(idx, windows)
    out = model(obj, mask, loc, act, generator=gen)
    loss = masked_mse(out.effect, tr.effect[idx], mask)
    if cfg.code_stability:  # unary codes say what an object is: the same before and after the action
        post = model_inputs(tr.post_depth[idx].float(), tr.post_origin[idx])
        loss = loss + cfg.code_stability * code_stability_loss(
            model.object_logits(obj, mask), model.object_logits(post, mask), mask)
    if cfg.grasp_weight:
        loss = loss + cfg.grasp_weight * grasp_loss(out.relation_logits, tr.held[idx], act, mask.shape[1])
    if cfg.ride_weight:
        loss = loss + cfg.ride_weight * ride_loss(out.relation_logits, tr.held[idx], tr.rider[idx], mask,
                                                  out.relations[:, 0].detach(), act)
    if cfg.support_weight:
        loss = loss + cfg.support_weight * support_loss(out.relation_logits, tr.held[idx], tr.rider[idx],
                                                        mask, out.relations[:, 0].detach(), act)
    if cfg.support_exclusive:
        loss = loss + cfg.support_exclusive * support_exclusion(out.relation_logits, mask)
    if cfg.post_support_weight:
        p_obj, _, p_loc = tr.post_inputs(idx, windows)
        _, _, p_rel, p_logits, _ = model.symbols(p_obj, mask, p_loc, generator=gen)
        loss = loss + cfg.post_support_weight * post_support_loss(
            out.relation_logits, p_logits, tr.held[idx], tr.rider[idx], mask, p_rel[:, 0].detach(), act)
    if cfg.relation_sparsity:  # the free heads only: a rests-on head makes one choice per object anyway
        free = out.relation_logits[:, 1 + int(cfg.model.support):]
        if free.shape[1]:
            loss = loss + cfg.relation_sparsity * relation_density(
                torch.cat([out.relation_logits[:, :1], free], 1), mask)
    return loss


def train_relations(roots: Sequence[Path], run_dir: Path, cfg: RelationalTrainConfig, show: bool = True,
                    init: Path | None = None) -> dict:
    """Train (or resume) the relational model on the data sets `roots`; returns the final metrics. With `init`, a
    new run starts from the weights of that run's relations.pt (same architecture), recorded in the inputs."""
    roots = [Path(r) for r in roots]
    cams = {json.dumps(camera_of(r).__dict__, sort_keys=True, default=list) for r in roots}
    if len(cams) != 1:
        raise ValueError(f"the data sets {', '.join(map(str, roots))} were rendered with different cameras")
    cam = camera_of(roots[0])
    windows_np = location_windows(cam, STORED_CROP)
    train_data, val_data = ([load_split(r, s) for r in roots] for s in ("train", "val"))
    k = max(d.effect.shape[1] for d in val_data)
    inputs = [{"data": str(r), "data_fingerprint": data_fingerprint(r)} for r in roots]
    if init is not None:
        init_blob = guarded_blob(Path(init) / CHECKPOINT, RELATIONAL_MODEL)
        if RelationalConfig.from_json(init_blob["config"]["model"]) != cfg.model:
            raise ValueError(f"{Path(init) / CHECKPOINT} holds another architecture than --preset asks for")
        inputs.append({"init": str(Path(init) / CHECKPOINT), "sha256": sha256_file(Path(init) / CHECKPOINT)})
    run_dir.mkdir(parents=True, exist_ok=True)
    last = run_dir / LAST
    torch.manual_seed(cfg.seed)
    model = RelationalDeepSym(cfg.model)
    opt = torch.optim.AdamW(model.parameters(), lr=cfg.lr, weight_decay=0.0)
    start, best, history = 0, math.inf, []
    if last.exists():
        blob = guarded_blob(last, RELATIONAL_MODEL)
        same = {**blob["config"], "epochs": cfg.epochs} == cfg.to_json()  # more epochs extend a run
        if not same or blob["inputs"] != inputs:
            raise ValueError(f"{last} was trained with other settings or data; use another --out")
        model.load_state_dict(blob["model"])
        opt.load_state_dict(blob["optimizer"])
        start, best, history = blob["epoch"], blob["best_val"], json.loads(blob["history"])
    elif init is not None:
        model.load_state_dict(init_blob["model"])
    tr, mean, std = entity_split(train_data, windows_np, k, post=bool(cfg.post_support_weight))
    va, _, _ = entity_split(val_data, windows_np, k, mean, std)
    del train_data, val_data  # the padded tensors hold what training reads
    windows = torch.from_numpy(windows_np.astype(np.float32))
    for epoch in range(start, cfg.epochs):
        gen = torch.Generator().manual_seed(cfg.seed * 100_003 + epoch)
        lr = cfg.lr * (cfg.lr_min_ratio + (1 - cfg.lr_min_ratio) * 0.5 * (1 + math.cos(math.pi * epoch / cfg.epochs)))
        for g in opt.param_groups:
            g["lr"] = lr
        model.train()
        model.soft_at = epoch < cfg.soft_at_epochs
        t0, total, seen = time.time(), 0.0, 0
        order = epoch_order(tr, cfg.rider_scene_repeat, gen)
        for a in range(0, len(order), cfg.batch_size):
            idx = order[a:a + cfg.batch_size]
            loss = batch_loss(model, cfg, tr, idx, windows, gen)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(idx)
            seen += len(idx)
        row = {"epoch": epoch + 1, "train_loss": total / max(seen, 1), "lr": lr} | evaluate(model, va, windows, std)
        history.append(row)
        if show:
            print(f"epoch {epoch + 1}/{cfg.epochs} train {row['train_loss']:.4f} val {row['loss']:.4f} "
                  f"mae {row['mae_mm']:.1f} mm riders {row['rider_mae_mm']} mm ({time.time() - t0:.0f} s)", flush=True)
        blob = {"kind": RELATIONS_KIND, "format_version": RELATIONS_FORMAT, "config": cfg.to_json(), "inputs": inputs, "model": model.state_dict(), "mean": torch.from_numpy(mean),
                "std": torch.from_numpy(std), "windows": torch.from_numpy(windows_np.astype(np.int64)),
                "camera": json.dumps(dataclasses.asdict(cam)), "max_objects": k, "epoch": epoch + 1,
                "history": json.dumps(history), "versions": json.dumps(versions())}
        if row["loss"] < best:
            best = row["loss"]
            _save(blob | {"best_val": best}, run_dir / CHECKPOINT)
        _save(blob | {"best_val": best, "optimizer": opt.state_dict()}, last)
    metrics = {"config": cfg.to_json(), "inputs": inputs, "history": history, "best_val": best,
               "versions": versions()}
    atomic_write_text(run_dir / "relations_metrics.json", json.dumps(metrics, indent=1))
    return metrics


def _save(blob: dict, path: Path) -> None:
    """Write a checkpoint atomically (weights_only loadable: tensors, plain data and JSON strings)."""
    buf = io.BytesIO()
    torch.save(blob, buf)
    atomic_write_bytes(path, buf.getvalue())


def load_relational(run_dir: Path) -> tuple[RelationalDeepSym, dict]:
    """The best relational model of a run (eval mode) and its checkpoint record (mean, std, windows, camera); a
    missing, foreign or damaged file is refused in one line (RelationsError) by the runs' one guarded loader."""
    path = Path(run_dir) / CHECKPOINT
    blob = guarded_blob(path, RELATIONAL_MODEL)
    try:
        model = RelationalDeepSym(RelationalTrainConfig.from_json(blob["config"]).model)
        model.load_state_dict(blob["model"])
    except (KeyError, TypeError, ValueError, RuntimeError) as e:
        raise RelationsError(f"{path} is a damaged relational checkpoint ({str(e).splitlines()[0][:120]})") from None
    return model.eval(), blob
