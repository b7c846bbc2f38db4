"""Training the effect model: whole split in memory, Adam, validation each epoch, resumable.

The data set's depth crops stay as float16 tensors in memory and each batch's 3-channel input
(depth, x, y) is built with tensor ops, so the loop does no per-sample Python work. Effects
are normalized per axis with statistics of the real (unpadded) training objects; they travel
in the checkpoint. Runs under `torchrun` with DistributedDataParallel (gloo on CPU, nccl on a
GPU): every rank takes its share of each shuffled epoch and rank 0 writes the files.

    >>> train(Path("data/paper"), Path("runs/paper"), TrainConfig.from_preset("quick"))  # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import torch
import torch.distributed as dist

from pddl_export.bounded_json import read_json_file
from symlearn.config_file import RECIPE
from symlearn.learning.checkpoint import load_checkpoint, load_weights, save_checkpoint
from symlearn.data.dataset import InteractionData, data_fingerprint, load_split
from symlearn.data.model_input import model_inputs
from symlearn.data.statistics import rider_mask, still_mask
from symlearn.learning.models import (AttentiveDeepSym, ModelConfig, code_distinct_loss, code_prediction_loss,
                                      code_stability_loss, masked_mse)
from symlearn.provenance import atomic_write_json, versions


class TrainingError(RuntimeError):
    """Training cannot go on (NaN loss, mismatched run directory)."""


# Each preset's optimisation settings; the model preset of the same name (models.PRESETS) gives its sizes.
TRAIN_PRESETS = {
    "paper": dict(epochs=60, batch_size=128, lr=5e-4),
    "quick": dict(epochs=40, batch_size=64, lr=1e-3),
    # the recipe that plans best (pretrained/recommended): quick, with the stability loss that keeps the codes of
    # objects an action left in place unchanged (docs/RESULTS.md, "Levers for symbols that plan"), and each scene
    # with a rider drawn three times an epoch, so that riders learn through attention (docs/RESULTS.md, "Riders");
    # in float32, as the pipeline trains on a CPU: the setting whose three seeds met every target of Table I
    "recommended": dict(epochs=40, batch_size=64, lr=1e-3, stability_weight=0.1, rider_scene_repeat=3, bf16=False),
}


@dataclass(frozen=True)
class TrainConfig:
    """Optimization settings; `paper` and `quick` pair with the model presets of the same name."""

    model: ModelConfig = field(default_factory=ModelConfig)
    preset: str = "paper"
    epochs: int = 60
    batch_size: int = 128  # scenes per step
    lr: float = 5e-4
    weight_decay: float = 0.0
    cosine_lr: bool = True  # decay the learning rate to lr_min_ratio * lr over the epochs (cosine)
    lr_min_ratio: float = 0.05
    seed: int = 0
    bf16: bool = True  # bfloat16 autocast on CPU (AMX) or GPU; weights stay float32
    compile: bool = False  # torch.compile the model
    max_train_samples: int | None = None  # a subset, for quick runs and tests
    rider_weight: float = 1.0  # loss weight of riders (objects carried by the held one; 1.5% of objects)
    # each training scene with a rider is drawn this many times an epoch (1: once, as every scene): rider-rich
    # sampling, the data-side alternative to rider_weight
    rider_scene_repeat: int = 1
    dynamics_weight: float = 0.0  # weight of the joint next-code loss (needs model.dynamics_head)
    stability_weight: float = 0.0  # weight of the hinge keeping still objects' codes unchanged by an action
    stability_margin: float = 1.0  # logit distance from 0 the hinge asks of every bit of a still object
    distinct_weight: float = 0.0  # weight of the hinge giving every two objects of a scene a differing code bit
    distinct_margin: float = 1.0  # logit distance from 0, on opposite sides, the hinge asks of that bit

    @property
    def uses_post_crops(self) -> bool:
        """Whether training also encodes the post-state crops (for the next-code or the stability loss)."""
        return self.dynamics_weight > 0 or self.stability_weight > 0

    def __post_init__(self) -> None:
        """Refuse settings that would train nothing, on a wrong subset, or into NaN."""
        problem = _config_problem(self)
        if problem:
            raise ValueError(f"train config: {problem}")

    @staticmethod
    def from_preset(name: str = RECIPE, **overrides) -> "TrainConfig":
        """A named preset (TRAIN_PRESETS; by default the recipe's, what `symlearn train` and the recommended
        pipeline train); model fields among the overrides go to the model config.

        A positive dynamics_weight switches the model's dynamics head on.
        """
        model_over = {k: overrides.pop(k) for k in list(overrides) if k in ModelConfig.__dataclass_fields__}
        if overrides.get("dynamics_weight", 0) > 0:
            model_over.setdefault("dynamics_head", True)
        if name not in TRAIN_PRESETS:
            raise ValueError(f"unknown preset {name!r}; known: {', '.join(TRAIN_PRESETS)}")
        base = TRAIN_PRESETS[name]
        return TrainConfig(model=ModelConfig.from_preset(name, **model_over), preset=name, **{**base, **overrides})

    def to_json(self) -> dict:
        """The config as plain JSON, as stored in checkpoints and config.json."""
        d = dataclasses.asdict(self)
        d["model"] = self.model.to_json()
        return json.loads(json.dumps(d, allow_nan=False))  # tuples as lists, as read back from disk

    @staticmethod
    def from_json(d: dict) -> "TrainConfig":
        """The config back from to_json's form."""
        d = dict(d)
        d["model"] = ModelConfig.from_json(d["model"])
        return TrainConfig(**d)


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_real(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _config_problem(c: TrainConfig) -> str | None:
    """What is wrong with a TrainConfig's values, or None."""
    checks = [
        (_is_int(c.epochs) and c.epochs >= 1, f"epochs={c.epochs!r} must be a positive integer"),
        (_is_int(c.batch_size) and c.batch_size >= 1, f"batch_size={c.batch_size!r} must be a positive integer"),
        (_is_real(c.lr) and c.lr > 0, f"lr={c.lr!r} must be a positive finite number"),
        (_is_real(c.weight_decay) and c.weight_decay >= 0, f"weight_decay={c.weight_decay!r} must be finite and >= 0"),
        (_is_real(c.lr_min_ratio) and 0 <= c.lr_min_ratio <= 1, f"lr_min_ratio={c.lr_min_ratio!r} must be in [0, 1]"),
        (_is_int(c.seed) and c.seed >= 0, f"seed={c.seed!r} must be a non-negative integer"),
        (_is_real(c.rider_weight) and c.rider_weight > 0, f"rider_weight={c.rider_weight!r} must be finite and > 0"),
        (_is_int(c.rider_scene_repeat) and c.rider_scene_repeat >= 1,
         f"rider_scene_repeat={c.rider_scene_repeat!r} must be an integer >= 1"),
        (_is_real(c.dynamics_weight) and c.dynamics_weight >= 0,
         f"dynamics_weight={c.dynamics_weight!r} must be finite and >= 0"),
        (_is_real(c.stability_weight) and c.stability_weight >= 0,
         f"stability_weight={c.stability_weight!r} must be finite and >= 0"),
        (_is_real(c.stability_margin) and c.stability_margin > 0,
         f"stability_margin={c.stability_margin!r} must be finite and > 0"),
        (_is_real(c.distinct_weight) and c.distinct_weight >= 0,
         f"distinct_weight={c.distinct_weight!r} must be finite and >= 0"),
        (_is_real(c.distinct_margin) and c.distinct_margin > 0,
         f"distinct_margin={c.distinct_margin!r} must be finite and > 0"),
        (c.dynamics_weight == 0 or c.model.dynamics_head,
         f"dynamics_weight={c.dynamics_weight!r} needs a model with dynamics_head=True"),
        (c.max_train_samples is None or (_is_int(c.max_train_samples) and c.max_train_samples >= 1),
         f"max_train_samples={c.max_train_samples!r} must be a positive integer (or None: all)"),
    ]
    return next((msg for ok, msg in checks if not ok), None)


@dataclass(frozen=True)
class SplitTensors:
    """One split as tensors: float16 depth, crop origins, mask, actions, normalized effects.

    With with_post=True in to_tensors the post-state crops and the still-object mask come along (for
    the next-code and stability losses); `weight` holds each object's loss weight when not all are 1.
    """

    depth: torch.Tensor  # (N, K, S, S) float16
    origin: torch.Tensor  # (N, K, 2) float32
    mask: torch.Tensor  # (N, K) bool
    action: torch.Tensor  # (N,) int64
    effect: torch.Tensor  # (N, K, 3) float32, normalized
    n_objects: torch.Tensor  # (N,) int64
    held: torch.Tensor  # (N,) int64, the object the suction tool held (-1: none), for the action per object
    weight: torch.Tensor | None = None  # (N, K) float32 loss weight per object
    post_depth: torch.Tensor | None = None  # (N, K, S, S) float16, the same objects after the action
    post_origin: torch.Tensor | None = None  # (N, K, 2) float32
    still: torch.Tensor | None = None  # (N, K) bool, objects the action left in place (with the post crops)

    def __len__(self) -> int:
        return int(self.action.shape[0])

    def to(self, device: torch.device) -> "SplitTensors":
        """The split on a device (a GPU holds a paper-size split many times over; batches are then built there)."""
        return SplitTensors(**{f.name: None if getattr(self, f.name) is None else getattr(self, f.name).to(device)
                               for f in dataclasses.fields(self)})

    def batch(self, idx: torch.Tensor, image_size: int = 256):
        """Model inputs for rows idx: crops (B, K, 3, S, S) float32, mask, actions, effects."""
        idx = idx.to(self.depth.device)
        d = self.depth[idx].float()  # (B, K, S, S)
        crops = model_inputs(d, self.origin[idx], image_size)
        return crops, self.mask[idx], self.action[idx], self.effect[idx]

    def post_crops(self, idx: torch.Tensor, image_size: int = 256) -> torch.Tensor:
        """Model inputs of the post-state crops for rows idx (B, K, 3, S, S)."""
        if self.post_depth is None:
            raise ValueError("this split was built without post-state crops (to_tensors(..., with_post=True))")
        idx = idx.to(self.post_depth.device)
        return model_inputs(self.post_depth[idx].float(), self.post_origin[idx], image_size)

    def held_of(self, idx: torch.Tensor) -> torch.Tensor:
        """The held object's index of rows idx (for models that take the action per object)."""
        return self.held[idx.to(self.held.device)]

    def weights(self, idx: torch.Tensor) -> torch.Tensor | None:
        """Loss weights of rows idx, or None when every object weighs 1."""
        return None if self.weight is None else self.weight[idx.to(self.weight.device)]


def effect_normalization(data: InteractionData) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis mean and std of the real objects' effects (padding excluded)."""
    eff = data.effect[data.mask].astype(np.float64)
    return eff.mean(0).astype(np.float32), np.maximum(eff.std(0), 1e-6).astype(np.float32)


def to_tensors(data: InteractionData, mean: np.ndarray, std: np.ndarray, post: bool = False,
               with_post: bool = False, rider_weight: float = 1.0) -> SplitTensors:
    """A split's pre-state (or, with post, post-state) crops and its normalized effects as tensors.

    with_post adds the post-state crops beside the pre-state ones; rider_weight != 1 adds per-object
    loss weights, riders (symlearn.data.statistics.rider_mask) weighing rider_weight.
    """
    mask = torch.from_numpy(data.mask)
    eff = torch.from_numpy((data.effect - mean) / std) * mask[..., None]
    weight = None
    if rider_weight != 1.0:
        weight = torch.from_numpy(np.where(rider_mask(data), rider_weight, 1.0).astype(np.float32))
    return SplitTensors(
        depth=torch.from_numpy(data.post_depth if post else data.pre_depth),
        origin=torch.from_numpy((data.post_origin if post else data.pre_origin).astype(np.float32)),
        mask=mask, action=torch.from_numpy(data.action.astype(np.int64)), effect=eff.float(),
        n_objects=torch.from_numpy(data.n_objects.astype(np.int64)), weight=weight,
        post_depth=torch.from_numpy(data.post_depth) if with_post else None,
        post_origin=torch.from_numpy(data.post_origin.astype(np.float32)) if with_post else None,
        still=torch.from_numpy(still_mask(data)) if with_post else None,
        held=torch.from_numpy(data.grasped.astype(np.int64)))


def _dist_info() -> tuple[int, int]:
    if dist.is_available() and dist.is_initialized():
        return dist.get_rank(), dist.get_world_size()
    return 0, 1


def _autocast(cfg: TrainConfig, device: torch.device):
    return torch.autocast(device.type, dtype=torch.bfloat16, enabled=cfg.bf16)


@torch.no_grad()
def predict_effects(model: AttentiveDeepSym, split: SplitTensors, batch_size: int = 256,
                    bf16: bool = False) -> torch.Tensor:
    """Normalized effect predictions (N, K, 3) in eval mode (deterministic codes)."""
    model.eval()
    device = next(model.parameters()).device
    outs = []
    for i in range(0, len(split), batch_size):
        idx = torch.arange(i, min(i + batch_size, len(split)))
        crops, mask, act, _ = split.batch(idx)
        with torch.autocast(device.type, dtype=torch.bfloat16, enabled=bf16):
            outs.append(model(crops.to(device), mask.to(device), act.to(device),
                              held=split.held_of(idx).to(device)).effect.float().cpu())
    return torch.cat(outs)


def mae_mm(pred: torch.Tensor, split: SplitTensors, std: np.ndarray) -> dict[str, float]:
    """Mean absolute error per axis in millimetres over real objects."""
    err = (pred - split.effect)[split.mask].abs() * torch.from_numpy(std) * 1000
    return dict(zip("xyz", [round(float(v), 2) for v in err.mean(0)]))


@dataclass(frozen=True)
class _Loop:
    """What every epoch of one training run shares: the model, its optimizer, generators and this rank's place."""

    cfg: TrainConfig
    run_dir: Path
    model: AttentiveDeepSym
    step_fn: Callable  # the model, wrapped in DistributedDataParallel and/or compiled
    opt: torch.optim.Optimizer
    gen: torch.Generator  # shuffling of the training split
    noise_gen: torch.Generator  # the encoder's code noise during training
    device: torch.device
    rank: int
    world: int
    mean: np.ndarray  # effect normalization, saved in every checkpoint
    std: np.ndarray
    meta: dict
    show_progress: bool
    order: torch.Tensor  # the training split's sample indices an epoch draws from (rider scenes repeated)


def train(data_dir: Path, run_dir: Path, cfg: TrainConfig, resume: bool = True, show_progress: bool = True) -> dict:
    """Train (or resume training) an effect model; returns the metrics written to RUN/metrics.json."""
    rank, world = _dist_info()
    run_dir = Path(run_dir)
    check_run_dir(run_dir, Path(data_dir))
    device = torch.device("cuda", rank % torch.cuda.device_count()) if torch.cuda.is_available() else torch.device("cpu")
    fingerprint = data_fingerprint(data_dir)
    tr, va, mean, std, order = _load_training_splits(data_dir, cfg)
    if device.type == "cuda":  # training batches are then built on the GPU: no per-step host work or copies
        tr = tr.to(device)
    torch.manual_seed(cfg.seed)
    model = AttentiveDeepSym(cfg.model).to(device)
    opt = torch.optim.Adam(model.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    gen = torch.Generator().manual_seed(cfg.seed)
    noise_gen = torch.Generator(device=device).manual_seed(cfg.seed + 1 + rank)
    start_epoch, best, history = 0, math.inf, []
    meta = {"train_config": cfg.to_json(), "data": str(data_dir), "data_fingerprint": fingerprint}
    if resume and (run_dir / "last.pt").exists():
        start_epoch, best, history = _resume(run_dir, cfg, fingerprint, model, opt, gen, noise_gen)
    created = not run_dir.exists()
    if rank == 0:
        run_dir.mkdir(parents=True, exist_ok=True)
        atomic_write_json(run_dir / "config.json", {**meta, "seed": cfg.seed, "versions": versions(),
                                                    "world_size": world})
    net = model
    if world > 1:
        net = torch.nn.parallel.DistributedDataParallel(model, device_ids=[device.index] if device.type == "cuda" else None)
    loop = _Loop(cfg, run_dir, model, torch.compile(net) if cfg.compile else net, opt, gen, noise_gen, device,
                 rank, world, mean, std, meta, show_progress, order)
    try:
        best = _run_epochs(loop, tr, va, start_epoch, best, history)
    except BaseException:
        if rank == 0 and created:
            _remove_unstarted_run(run_dir)
        raise
    return _finish(loop, history, best)


def _run_epochs(loop: _Loop, tr: SplitTensors, va: SplitTensors, start_epoch: int, best: float,
                history: list) -> float:
    """Epochs start_epoch.. of the run (rank 0 saves each); appends to history, returns the best val loss."""
    for epoch in range(start_epoch, loop.cfg.epochs):
        train_loss, seen, train_time = _train_epoch(loop, tr, epoch)
        row, val_loss = _validate(loop, va, epoch, train_loss, seen, train_time)
        history.append(row)
        if loop.rank == 0:
            best = _save_epoch(loop, epoch, row, val_loss, best, history)
    return best


def _remove_unstarted_run(run_dir: Path) -> None:
    """A run folder this call created, failed before its first checkpoint: remove its config.json and the folder."""
    if (run_dir / "last.pt").exists():
        return
    (run_dir / "config.json").unlink(missing_ok=True)
    try:
        run_dir.rmdir()  # only when nothing else is in it
    except OSError:
        pass


def check_run_dir(run_dir: Path, data_dir: Path) -> None:
    """Refuse a run folder that is the data set, or any data set folder: checkpoints would mix into it."""
    from symlearn.data.dataset import DATA_KIND

    if run_dir.resolve() == data_dir.resolve():
        raise TrainingError(f"--out {run_dir} is the data set folder itself; choose a separate run folder")
    manifest = run_dir / "manifest.json"
    if manifest.exists():
        try:
            kind = read_json_file(manifest, what="manifest").get("kind")
        except (ValueError, AttributeError):  # JsonFileError is a ValueError
            kind = None
        what = "a symlearn data set" if kind == DATA_KIND else "a folder with a manifest.json"
        raise TrainingError(f"--out {run_dir} holds {what} ({manifest}); choose a separate run folder")


def _load_training_splits(data_dir: Path, cfg: TrainConfig
                          ) -> tuple[SplitTensors, SplitTensors, np.ndarray, np.ndarray, torch.Tensor]:
    """The train and val splits as tensors, effects normalized with the training split's statistics, and the
    training samples an epoch draws from: each once, a scene with a rider cfg.rider_scene_repeat times."""
    train_data = load_split(data_dir, "train")
    val_data = load_split(data_dir, "val")
    if cfg.max_train_samples:
        train_data = InteractionData(**{f.name: getattr(train_data, f.name)[: cfg.max_train_samples]
                                        for f in dataclasses.fields(InteractionData)})
    if train_data.pre_depth.shape[-1] % cfg.model.crop:
        raise TrainingError(f"data crops of {train_data.pre_depth.shape[-1]} px do not pool to the model's {cfg.model.crop} px")
    mean, std = effect_normalization(train_data)
    tr = to_tensors(train_data, mean, std, with_post=cfg.uses_post_crops, rider_weight=cfg.rider_weight)
    repeats = np.where(rider_mask(train_data).any(1), cfg.rider_scene_repeat, 1)
    order = torch.from_numpy(np.repeat(np.arange(len(repeats)), repeats))
    return tr, to_tensors(val_data, mean, std), mean, std, order


def _resume(run_dir: Path, cfg: TrainConfig, fingerprint: str, model: AttentiveDeepSym, opt: torch.optim.Optimizer,
            gen: torch.Generator, noise_gen: torch.Generator) -> tuple[int, float, list]:
    """Load RUN/last.pt into model, optimizer and generators; returns the next epoch, best val loss and history."""
    ck = load_checkpoint(run_dir / "last.pt", expect_config=cfg.model)
    if (_resumable(ck.meta.get("train_config", {})) != _resumable(cfg.to_json())
            or ck.meta.get("data_fingerprint") != fingerprint):
        raise TrainingError(f"{run_dir} holds a run with other settings or data; use a new --out or --no-resume")
    problem = _schedule_problem(ck.meta["train_config"].get("epochs"), cfg, ck.epoch + 1)
    if problem:
        raise TrainingError(f"{run_dir} holds a run whose {problem}: resumed, it would not be the model these "
                            "settings train; use a new --out or --no-resume")
    load_weights(model, ck.model_state, run_dir / "last.pt")
    opt.load_state_dict(ck.optimizer_state)
    gen.set_state(ck.rng_states["shuffle"])
    noise_gen.set_state(ck.rng_states["noise"])
    torch.set_rng_state(ck.rng_states["torch"])  # dropout
    return ck.epoch + 1, ck.best_val, _timed(ck.history, run_dir / "metrics.json")


# fields of a history row that record wall times: in metrics.json, not in the checkpoints
WALL_TIME_FIELDS = ("crops_per_s", "epoch_time_s")


def _untimed(row: dict) -> dict:
    """A history row without its wall times, as the checkpoints hold it."""
    return {k: v for k, v in row.items() if k not in WALL_TIME_FIELDS}


def _timed(history: list, metrics: Path) -> list:
    """A resumed checkpoint's history with the wall times RUN/metrics.json recorded for its epochs (where it has
    them: it is written after the checkpoints, so a killed run's last epoch may have none)."""
    try:
        rows = read_json_file(metrics, what="training metrics").get("history") or []
        times = {r["epoch"]: {k: r[k] for k in WALL_TIME_FIELDS if k in r} for r in rows}
    except (ValueError, AttributeError, TypeError, KeyError):  # missing or damaged: the rows stay without them
        times = {}
    return [{**row, **times.get(row.get("epoch"), {})} for row in history]


def _train_epoch(loop: _Loop, tr: SplitTensors, epoch: int) -> tuple[float, int, float]:
    """One shuffled pass over this rank's share of the training split: mean loss, real crops seen, seconds."""
    from tqdm import tqdm

    cfg, world = loop.cfg, loop.world
    for group in loop.opt.param_groups:
        group["lr"] = epoch_lr(cfg, epoch)
    loop.model.train()
    perm = loop.order[torch.randperm(len(loop.order), generator=loop.gen)]
    per_rank = len(perm) // world
    perm = perm[loop.rank * per_rank:(loop.rank + 1) * per_rank]
    n_batches = max(1, len(perm) // cfg.batch_size)
    t0, seen, total = time.perf_counter(), 0, 0.0
    bar = tqdm(range(n_batches), desc=f"epoch {epoch + 1}/{cfg.epochs}",
               disable=not loop.show_progress or loop.rank != 0, leave=False)
    for b in bar:
        idx = perm[b * cfg.batch_size:(b + 1) * cfg.batch_size]
        crops, mask, act, eff = (t.to(loop.device) for t in tr.batch(idx))
        post = tr.post_crops(idx).to(loop.device) if cfg.uses_post_crops else None
        weight = tr.weights(idx)
        with _autocast(cfg, loop.device):
            out = loop.step_fn(crops, mask, act, generator=loop.noise_gen, post_crops=post,
                               held=tr.held_of(idx).to(loop.device))
        loss = masked_mse(out.effect.float(), eff, mask, None if weight is None else weight.to(loop.device))
        if cfg.dynamics_weight > 0:
            loss = loss + cfg.dynamics_weight * code_prediction_loss(out.next_logits.float(), out.next_codes.float(), mask)
        if cfg.stability_weight > 0:
            still = tr.still[idx.to(tr.still.device)].to(loop.device) & mask
            loss = loss + cfg.stability_weight * code_stability_loss(out.logits.float(), out.post_logits.float(), still,
                                                                     cfg.stability_margin)
        if cfg.distinct_weight > 0:
            loss = loss + cfg.distinct_weight * code_distinct_loss(out.logits.float(), mask, cfg.distinct_margin)
        if not torch.isfinite(loss):
            raise TrainingError(f"loss became {loss.item()} at epoch {epoch + 1}, step {b + 1}; "
                                "lower the learning rate or check the data")
        loop.opt.zero_grad(set_to_none=True)
        loss.backward()
        loop.opt.step()
        seen += int(mask.sum())
        total += float(loss.detach())
        bar.set_postfix(loss=f"{total / (b + 1):.4f}", crops_s=f"{seen * world / (time.perf_counter() - t0):.0f}")
    return total / n_batches, seen, time.perf_counter() - t0


def _validate(loop: _Loop, va: SplitTensors, epoch: int, train_loss: float, seen: int,
              train_time: float) -> tuple[dict, float]:
    """The epoch's history row (losses, val MAE, lr, throughput) and its unrounded validation loss."""
    cfg = loop.cfg
    pred = predict_effects(loop.model, va, bf16=cfg.bf16)
    val_loss = float(masked_mse(pred, va.effect, va.mask))
    if not math.isfinite(val_loss):
        raise TrainingError(f"validation loss became {val_loss} at epoch {epoch + 1}; "
                            "lower the learning rate or check the data")
    row = {"epoch": epoch + 1, "train_loss": round(train_loss, 5), "val_loss": round(val_loss, 5),
           "val_mae_mm": mae_mm(pred, va, loop.std), "lr": round(epoch_lr(cfg, epoch), 7),
           "crops_per_s": round(seen * loop.world / train_time, 1), "epoch_time_s": round(train_time, 1)}
    return row, val_loss


def _save_epoch(loop: _Loop, epoch: int, row: dict, val_loss: float, best: float, history: list) -> float:
    """Rank 0 after an epoch: write last.pt, best.pt when improved and metrics.json; returns the new best."""
    improved = val_loss < best
    best = min(best, val_loss)
    # the checkpoints' history leaves out the wall times, so that a checkpoint is byte for byte the same file
    # in every run of the same settings (its hash is recorded downstream: m(z), the export, the report)
    state = dict(model=loop.model, optimizer=loop.opt, epoch=epoch, best_val=best,
                 history=[_untimed(r) for r in history],
                 rng_states={"shuffle": loop.gen.get_state(), "noise": loop.noise_gen.get_state(),
                             "torch": torch.get_rng_state()},
                 effect_mean=loop.mean, effect_std=loop.std, meta=loop.meta)
    save_checkpoint(loop.run_dir / "last.pt", **state)
    if improved:
        save_checkpoint(loop.run_dir / "best.pt", **state)
    atomic_write_json(loop.run_dir / "metrics.json", {"history": history, "best_val_loss": finite_or_none(best),
                                                      "data_fingerprint": loop.meta["data_fingerprint"]})
    if loop.show_progress:
        print(f"epoch {epoch + 1}: train {row['train_loss']:.4f} val {val_loss:.4f} "
              f"mae mm {row['val_mae_mm']} {row['crops_per_s']:.0f} crops/s", flush=True)
    return best


def _finish(loop: _Loop, history: list, best: float) -> dict:
    """The run's result; with several ranks, also whether they ended with identical weights."""
    result = {"history": history, "best_val_loss": finite_or_none(best)}
    if loop.world > 1:
        result["ranks_identical"] = _ranks_identical(loop.model)
        if loop.rank == 0:
            atomic_write_json(loop.run_dir / "metrics.json", {**result, "data_fingerprint": loop.meta["data_fingerprint"],
                                                              "world_size": loop.world})
    return result


def finite_or_none(x: float) -> float | None:
    """x, or None (JSON null) when it is NaN or infinite: strict JSON has no such numbers."""
    return float(x) if math.isfinite(x) else None


def epoch_lr(cfg: TrainConfig, epoch: int) -> float:
    """Learning rate of an epoch: constant, or cosine from lr down to lr * lr_min_ratio."""
    if not cfg.cosine_lr or cfg.epochs <= 1:
        return cfg.lr
    w = 0.5 * (1 + math.cos(math.pi * epoch / (cfg.epochs - 1)))
    return cfg.lr * (cfg.lr_min_ratio + (1 - cfg.lr_min_ratio) * w)


def _resumable(train_config: dict) -> dict:
    """The settings a resumed run must share with the original: all but the number of epochs.

    A config written before a field existed reads as that field's default.
    """
    try:
        train_config = TrainConfig.from_json(train_config).to_json()
    except (TypeError, ValueError, KeyError):
        pass  # unreadable: compared as written, so it cannot match
    return {k: v for k, v in train_config.items() if k != "epochs"}


def _schedule_problem(trained_for: object, cfg: TrainConfig, trained: int) -> str | None:
    """Why the first `trained` epochs of a run of `trained_for` epochs (otherwise cfg's settings) are not those of a
    run of cfg: more epochs than cfg has, or other learning rates (the cosine schedule spans all the epochs);
    None when resuming it trains, bit for bit, what cfg trains from scratch."""
    if trained > cfg.epochs:
        return f"{trained} epochs are more than the {cfg.epochs} asked"
    if not _is_int(trained_for) or trained_for < 1:
        return f"number of epochs {trained_for!r} cannot be read"
    before = dataclasses.replace(cfg, epochs=trained_for)
    if any(epoch_lr(before, e) != epoch_lr(cfg, e) for e in range(trained)):
        return f"{trained} epochs followed the learning rates of {trained_for} epochs, not of {cfg.epochs}"
    return None


def _ranks_identical(model: torch.nn.Module) -> bool:
    """Whether every rank ends with bit-identical weights (DDP keeps them in step)."""
    flat = torch.cat([p.detach().float().flatten() for p in model.parameters()])
    gathered = [torch.empty_like(flat) for _ in range(dist.get_world_size())]
    dist.all_gather(gathered, flat)
    return all(torch.equal(gathered[0], g) for g in gathered[1:])
