"""Interaction data collection: random exploration episodes in the simulator, written in shards.

Each shard is an independent run of whole episodes from its own seed `(seed, shard index)` in
a fresh simulator, so the arrays do not depend on how many worker processes ran. Shards are
written atomically (temp file, then rename); `manifest.json` records the settings, each
finished shard's checksum, and the train / val / test split by shards. Re-running with the same
settings resumes: finished shards whose checksum matches are skipped. The format is described
in docs/DATA_FORMAT.md and read back by `symlearn.data.dataset`.

    >>> cfg = CollectConfig(n=40, seed=1)          # doctest: +SKIP
    >>> collect(Path("data/tiny"), cfg, workers=2)  # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import json
import math
import multiprocessing as mp
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from symlearn.sim.exploration import ExplorationConfig, sample_action, sample_scene_spec
from symlearn.data.dataset import DATA_KIND, FORMAT_VERSION, SPLITS
from symlearn.provenance import atomic_write_json, sha256_file, versions
from symlearn.sim.simulator import SimConfig, TabletopSimulator

MAX_FAILED_EPISODES = 1000  # consecutive episodes without a sample before collect_shard gives up


class CollectError(RuntimeError):
    """A collection request that cannot be honoured (bad settings, foreign or mismatched DIR)."""


@dataclass(frozen=True)
class CollectConfig:
    """What to collect; the paper's set is the default (12,000 samples, 10,000/1,000/1,000)."""

    n: int = 12000  # samples (actions) in all
    seed: int = 0
    shard_size: int = 250  # samples per shard: 48 shards for the paper set, split 40/4/4
    exploration: ExplorationConfig = field(default_factory=ExplorationConfig)
    sim: SimConfig = field(default_factory=SimConfig)

    def __post_init__(self) -> None:
        if not isinstance(self.n, int) or self.n < 3:
            raise CollectError(f"n={self.n!r}: need at least 3 samples (one shard per split)")
        if self.shard_size < 1:
            raise CollectError(f"shard_size={self.shard_size} must be positive")

    @property
    def max_objects(self) -> int:
        return max(self.exploration.k_values)

    def shard_sizes(self) -> list[int]:
        """Even shard sizes; at least 12 shards when n allows, so splits follow 10:1:1."""
        n_shards = max(min(12, self.n), math.ceil(self.n / self.shard_size))
        base, extra = divmod(self.n, n_shards)
        return [base + (i < extra) for i in range(n_shards)]

    def shard_splits(self) -> list[str]:
        """Split of each shard: the last twelfth is test, the one before it val (at least one each)."""
        n_shards = len(self.shard_sizes())
        n_hold = max(1, round(n_shards / 12))
        return ["train"] * (n_shards - 2 * n_hold) + ["val"] * n_hold + ["test"] * n_hold

    def to_json(self) -> dict:
        return json.loads(json.dumps(dataclasses.asdict(self)))


def _empty_arrays(size: int, k: int, s: int) -> dict[str, np.ndarray]:
    """Preallocated shard arrays for `size` samples of up to `k` objects with s x s crops (padding: zeros, type -1)."""
    return {
        "pre_depth": np.zeros((size, k, s, s), np.float16),
        "post_depth": np.zeros((size, k, s, s), np.float16),
        "pre_origin": np.zeros((size, k, 2), np.int16),
        "post_origin": np.zeros((size, k, 2), np.int16),
        "pre_pixels": np.zeros((size, k), np.int32),
        "post_pixels": np.zeros((size, k), np.int32),
        "action": np.zeros(size, np.int8),
        "effect": np.zeros((size, k, 3), np.float32),
        "n_objects": np.zeros(size, np.int8),
        "obj_type": np.full((size, k), -1, np.int8),
        "pre_pose": np.zeros((size, k, 7), np.float32),
        "post_pose": np.zeros((size, k, 7), np.float32),
        "grasped": np.zeros(size, np.int8),
        "episode": np.zeros(size, np.int32),
        "step": np.zeros(size, np.int16),
    }


def _record(a: dict[str, np.ndarray], i: int, pre, post, action, res, episode: int, step: int) -> None:
    """Fill row i of the shard arrays from one step: observations before/after, the step result, its place."""
    k = len(res.before.objects)
    a["pre_depth"][i, :k] = pre.crops
    a["post_depth"][i, :k] = post.crops
    a["pre_origin"][i, :k] = pre.origins
    a["post_origin"][i, :k] = post.origins
    a["pre_pixels"][i, :k] = pre.pixels
    a["post_pixels"][i, :k] = post.pixels
    a["action"][i] = action.id
    a["effect"][i, :k] = res.effect
    a["n_objects"][i] = k
    a["obj_type"][i, :k] = [int(o.type) for o in res.before.objects]
    a["pre_pose"][i, :k] = [o.position + o.orientation for o in res.before.objects]
    a["post_pose"][i, :k] = [o.position + o.orientation for o in res.after.objects]
    a["grasped"][i] = res.grasped
    a["episode"][i] = episode
    a["step"][i] = step


def collect_shard(cfg: CollectConfig, index: int, size: int,
                  progress: Callable[[int], None] | None = None,
                  max_failed_episodes: int = MAX_FAILED_EPISODES) -> dict[str, np.ndarray]:
    """Run episodes until `size` samples are recorded; arrays padded to cfg.max_objects objects.

    An episode that records no sample (its first action drops an object off the table) is retried
    with a fresh scene, at most `max_failed_episodes` times in a row; then a CollectError says so.
    """
    rng = np.random.default_rng([cfg.seed, index])
    a = _empty_arrays(size, cfg.max_objects, cfg.sim.crop)
    dropped = episode = failed_in_a_row = i = 0
    with TabletopSimulator(cfg.sim) as sim:
        while i < size:
            recorded_before = i
            spec = sample_scene_spec(rng, cfg.exploration)
            sim.build(spec)
            pre = sim.observe()
            for t in range(cfg.exploration.episode_length(len(spec))):
                if i == size:
                    break
                action = sample_action(rng, sim.occupied(), cfg.exploration)
                res = sim.step(action)
                post = sim.observe()
                if res.off_table:  # an object left the table: its crop and effect mean nothing
                    dropped += 1
                    break
                _record(a, i, pre, post, action, res, episode, t)
                i += 1
                pre = post
                if progress:
                    progress(1)
            episode += 1
            failed_in_a_row = failed_in_a_row + 1 if i == recorded_before else 0
            if failed_in_a_row >= max_failed_episodes:
                raise CollectError(f"shard {index}: {failed_in_a_row} episodes in a row recorded no sample "
                                   f"(each first action dropped an object off the table, or episodes are empty); "
                                   f"check the scene and exploration settings")
    a["dropped"] = np.array(dropped, np.int32)
    return a


def shard_name(index: int) -> str:
    return f"shard_{index:05d}.npz"


def _write_shard(out: Path, index: int, arrays: dict[str, np.ndarray]) -> dict:
    final = out / shard_name(index)
    tmp = out / f".{final.stem}.tmp{os.getpid()}.npz"
    np.savez_compressed(tmp, **arrays)
    os.replace(tmp, final)
    return {"name": final.name, "index": index, "n_samples": int(arrays["action"].shape[0]),
            "episodes": int(arrays["episode"].max()) + 1 if arrays["episode"].size else 0,
            "dropped_samples": int(arrays["dropped"]), "sha256": sha256_file(final)}


def _worker(args) -> dict:
    cfg, out, index, size, q = args
    arrays = collect_shard(cfg, index, size, progress=(lambda n: q.put(n)) if q is not None else None)
    return _write_shard(Path(out), index, arrays)


def _manifest(cfg: CollectConfig, done: dict[int, dict]) -> dict:
    splits = cfg.shard_splits()
    shards = [dict(done[i], split=splits[i]) for i in sorted(done)]
    counts = {s: sum(d["n_samples"] for d in shards if d["split"] == s) for s in SPLITS}
    return {"kind": DATA_KIND, "format_version": FORMAT_VERSION, "settings": cfg.to_json(),
            "seed": cfg.seed, "n_shards": len(splits), "complete": len(done) == len(splits),
            "counts": counts, "shards": shards, "versions": versions(),
            "updated": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


def _resume_state(out: Path, cfg: CollectConfig) -> dict[int, dict]:
    """Finished shards of an earlier run with the same settings; refuses a foreign or different DIR."""
    mpath = out / "manifest.json"
    if not mpath.exists():
        if out.exists() and any(p for p in out.iterdir() if not p.name.startswith(".")):
            raise CollectError(f"{out} exists and is not a symlearn data set (no manifest.json); "
                               "choose an empty or new --out")
        return {}
    try:
        old = json.loads(mpath.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise CollectError(f"{mpath} is not valid JSON ({e}); remove it or choose another --out")
    if old.get("kind") != DATA_KIND or old.get("format_version") != FORMAT_VERSION:
        raise CollectError(f"{out} holds a foreign data set or format version "
                           f"{old.get('format_version')!r} (expected {FORMAT_VERSION})")
    if old.get("settings") != cfg.to_json():
        diff = _first_difference(old.get("settings"), cfg.to_json())
        raise CollectError(f"{out} was collected with different settings ({diff}); "
                           "use the same arguments to resume or choose another --out")
    done = {}
    for d in old.get("shards", []):
        p = out / d["name"]
        if p.exists() and sha256_file(p) == d["sha256"]:
            done[int(d["index"])] = {k: v for k, v in d.items() if k != "split"}
    return done


def _first_difference(a, b, path: str = "") -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if a.get(key) != b.get(key):
                return _first_difference(a.get(key), b.get(key), f"{path}.{key}" if path else key)
    return f"{path}: {a!r} there, {b!r} now"


def collect(out: Path, cfg: CollectConfig, workers: int = 1, show_progress: bool = True) -> dict:
    """Collect (or finish collecting) a data set into `out`; returns the final manifest."""
    out = Path(out)
    if workers < 1:
        raise CollectError(f"workers={workers} must be at least 1")
    done = _resume_state(out, cfg)
    out.mkdir(parents=True, exist_ok=True)
    for stale in out.glob(".*.tmp*.npz"):
        stale.unlink()
    sizes = cfg.shard_sizes()
    todo = [i for i in range(len(sizes)) if i not in done]
    from tqdm import tqdm

    bar = tqdm(total=cfg.n, initial=sum(sizes[i] for i in done), unit="sample", smoothing=0.05,
               disable=not show_progress, desc="collect")

    def finish(info: dict) -> None:
        done[info["index"]] = info
        atomic_write_json(out / "manifest.json", _manifest(cfg, done))

    atomic_write_json(out / "manifest.json", _manifest(cfg, done))
    if workers == 1 or len(todo) <= 1:
        for i in todo:
            finish(_write_shard(out, i, collect_shard(cfg, i, sizes[i], progress=bar.update)))
    else:
        ctx = mp.get_context("spawn")
        with ctx.Manager() as manager:
            q = manager.Queue()
            with ctx.Pool(min(workers, len(todo))) as pool:
                results = pool.imap_unordered(_worker, [(cfg, str(out), i, sizes[i], q) for i in todo])
                remaining = len(todo)
                while remaining:
                    while not q.empty():
                        bar.update(q.get())
                    try:
                        finish(results.next(timeout=0.1))
                        remaining -= 1
                    except mp.TimeoutError:
                        pass
                while not q.empty():
                    bar.update(q.get())
    bar.close()
    manifest = _manifest(cfg, done)
    atomic_write_json(out / "manifest.json", manifest)
    return manifest
