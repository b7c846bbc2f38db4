"""Interaction data collection: random exploration episodes in the simulator, written in shards.

Each shard is an independent run of whole episodes from its own seed `(seed, shard index)` in
a fresh simulator, so the arrays do not depend on how many worker processes ran. Shards are
written atomically (temp file, then rename); `manifest.json` records the settings, each
finished shard's checksum, and the train / val / test split by shards. Re-running with the same
settings resumes: finished shards whose checksum matches are skipped, and temp files a killed run
left are removed. SIGINT or SIGTERM of the collecting process ends its workers (which also end on
their own when their parent dies) and leaves no temp file. The format is described in
docs/DATA_FORMAT.md and read back by `symlearn.data.dataset`.

With `engine="ray"` (symlearn.cluster) each missing shard is a Ray task that collects it from the
same seed and returns its arrays; this process writes them through the same atomic shard writer, so a
Ray collection is byte for byte the local one, and resumes the same way.

    >>> cfg = CollectConfig(n=40, seed=1)          # doctest: +SKIP
    >>> collect(Path("data/tiny"), cfg, workers=2)  # doctest: +SKIP
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import multiprocessing as mp
import os
import signal
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from pddl_export.bounded_json import JsonFileError, read_json_file
from symlearn.sim.data_format import DATA_KIND, FORMAT_VERSION, SPLITS, DataError, check_shard_entries, shard_sha256
from symlearn.sim.exploration import ExplorationConfig, sample_action, sample_scene_spec
from symlearn.folder_lock import folder_lock
from symlearn.provenance import atomic_write_bytes, atomic_write_json, sha256_file, versions
from symlearn.sim.simulator import SimConfig, TabletopSimulator

MAX_FAILED_EPISODES = 1000  # consecutive episodes without a sample before collect_shard gives up
PARENT_POLL_S = 0.5  # how often a worker checks that the collecting process is still alive
TEMP_PATTERNS = (".manifest.json.tmp*", ".manifest.json.*.tmp", ".shard_*.tmp*.npz", ".shard_*.npz.*.tmp")


class CollectError(RuntimeError):
    """A collection request that cannot be honoured (bad settings, foreign or mismatched DIR)."""


class CollectInterrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM reached the collecting process; the workers are ended and resuming finishes the job."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"signal {signal.Signals(signum).name}")
        self.signum = signum


MAX_SAMPLES = 10**9  # a data set of 4 TB of crops: a larger n is a typo, and only its shard list would take memory
MAX_SHARDS = 1_000_000  # the manifest lists every shard


@dataclass(frozen=True)
class CollectConfig:
    """What to collect; the paper's set is the default (12,000 samples, 10,000/1,000/1,000)."""

    n: int = 12000  # samples (actions) in all
    seed: int = 0
    shard_size: int = 250  # samples per shard: 48 shards for the paper set, split 40/4/4
    exploration: ExplorationConfig = field(default_factory=ExplorationConfig)
    sim: SimConfig = field(default_factory=SimConfig)

    def __post_init__(self) -> None:
        if not _is_int(self.n) or self.n < 3:
            raise CollectError(f"n={self.n!r}: need at least 3 samples (one shard per split)")
        if not _is_int(self.shard_size) or self.shard_size < 1:
            raise CollectError(f"shard_size={self.shard_size!r} must be a positive integer")
        if not _is_int(self.seed) or self.seed < 0:
            raise CollectError(f"seed={self.seed!r} must be a non-negative integer")
        if self.n > MAX_SAMPLES or math.ceil(self.n / self.shard_size) > MAX_SHARDS:
            raise CollectError(f"n={self.n!r} in shards of {self.shard_size!r}: at most {MAX_SAMPLES} samples in "
                               f"at most {MAX_SHARDS} shards")

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
        """The settings as strict JSON (tuples as lists), as recorded in manifest.json."""
        return json.loads(json.dumps(dataclasses.asdict(self), allow_nan=False))


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


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
    """File name of shard `index`."""
    return f"shard_{index:05d}.npz"


def _write_shard(out: Path, index: int, arrays: dict[str, np.ndarray]) -> dict:
    """Write one shard atomically (pddl_export.files: temp file, fsync, rename); returns its manifest entry."""
    import io

    final = out / shard_name(index)
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(final, buf.getvalue())
    return {"name": final.name, "index": index, "n_samples": int(arrays["action"].shape[0]),
            "episodes": int(arrays["episode"].max()) + 1 if arrays["episode"].size else 0,
            "dropped_samples": int(arrays["dropped"]), "sha256": sha256_file(final)}


_progress_queue = None  # a worker's queue of progress counts, set by _worker_init


def _worker_init(q, parent_pid: int) -> None:
    """In each worker: ignore SIGINT (the parent decides), end cleanly on SIGTERM, and end when the parent dies."""
    global _progress_queue
    _progress_queue = q
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="watch-parent").start()


def _exit_on_sigterm(signum, frame) -> None:
    """SIGTERM in a worker: unwind (a shard being written removes its temp file) and exit."""
    raise SystemExit(128 + signum)


def _watch_parent(parent_pid: int) -> None:
    """Poll the parent; once it is gone, SIGTERM this worker, and after a grace period end it hard."""
    while os.getppid() == parent_pid:
        time.sleep(PARENT_POLL_S)
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(10)
    os._exit(1)


def _worker(args) -> dict:
    """One shard in a pool worker: collect it, write it, return its manifest entry."""
    cfg, out, index, size = args
    q = _progress_queue
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


# exploration settings added after data sets were collected, with the value every earlier collection had
ADDED_EXPLORATION_KEYS = {"scene_draw": "near-row", "far_prob": 0.7}


def _upgraded(settings):
    """Recorded settings with the exploration keys added since given the value they had then, so that a data set
    collected before them resumes under the same arguments."""
    if not (isinstance(settings, dict) and isinstance(settings.get("exploration"), dict)):
        return settings
    return {**settings, "exploration": {**settings["exploration"],
                                        **{k: v for k, v in ADDED_EXPLORATION_KEYS.items()
                                           if k not in settings["exploration"]}}}


def _resume_state(out: Path, cfg: CollectConfig) -> dict[int, dict]:
    """Finished shards of an earlier run with the same settings; refuses a foreign or different DIR."""
    mpath = out / "manifest.json"
    if not mpath.exists():
        if out.exists() and any(p for p in out.iterdir() if not p.name.startswith(".")):
            raise CollectError(f"{out} exists and is not a symlearn data set (no manifest.json); "
                               "choose an empty or new --out")
        return {}
    try:
        old = read_json_file(mpath, what="data set manifest")
    except JsonFileError as e:
        raise CollectError(f"{e}; remove it or choose another --out") from None
    if not isinstance(old, dict):
        raise CollectError(f"{mpath} is not a data set manifest (a JSON {type(old).__name__}); choose another --out")
    if old.get("kind") != DATA_KIND or old.get("format_version") != FORMAT_VERSION:
        raise CollectError(f"{out} holds a foreign data set or format version "
                           f"{old.get('format_version')!r} (expected {FORMAT_VERSION})")
    settings, want = _upgraded(old.get("settings")), cfg.to_json()
    if settings != want:
        diff = _first_difference(settings, want)
        raise CollectError(f"{out} was collected with different settings ({diff}); "
                           "use the same arguments to resume or choose another --out")
    try:
        check_shard_entries(mpath, old)
    except DataError as e:
        raise CollectError(f"{e}; remove it or choose another --out") from None
    done = {}
    for d in old["shards"]:
        p = out / d["name"]
        try:  # a FIFO or device in a shard's place is refused at once (open_shard), not hashed forever
            if p.exists() and shard_sha256(p) == d["sha256"]:
                done[int(d["index"])] = {k: v for k, v in d.items() if k != "split"}
        except DataError as e:
            raise CollectError(f"{e}; remove it or choose another --out") from None
    return done


def _first_difference(a, b, path: str = "") -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if a.get(key) != b.get(key):
                return _first_difference(a.get(key), b.get(key), f"{path}.{key}" if path else key)
    return f"{path}: {a!r} there, {b!r} now"


def remove_temp_files(out: Path) -> list[str]:
    """Delete what a killed collection can leave in `out`: temp files of the manifest and of shards."""
    removed = []
    for pattern in TEMP_PATTERNS:
        for p in out.glob(pattern):
            p.unlink(missing_ok=True)
            removed.append(p.name)
    return removed


def _refuse_run_folder(out: Path) -> None:
    """Refuse to collect into a training run's folder (it holds checkpoints or a run's config.json)."""
    if (out / "manifest.json").exists():
        return
    if any((out / name).exists() for name in ("best.pt", "last.pt", "transition.pt", "metrics.json")):
        raise CollectError(f"{out} is a training run folder (it holds checkpoints); choose another --out for data")


@contextlib.contextmanager
def _interruptible() -> Iterator[None]:
    """Turn SIGTERM (and SIGINT) into CollectInterrupted in the main thread, so cleanup runs; later ones are ignored.

    A signal ignored on entry (SIG_IGN) is left ignored."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    # a signal the caller ignores (SIGINT in a shell's background job) stays ignored
    sigs = tuple(s for s in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(s) != signal.SIG_IGN)
    old = {s: signal.getsignal(s) for s in sigs}

    def handler(signum, frame):
        for s in sigs:  # a second signal must not interrupt the cleanup of the first
            signal.signal(s, signal.SIG_IGN)
        raise CollectInterrupted(signum)

    for s in sigs:
        signal.signal(s, handler)
    try:
        yield
    finally:
        for s in sigs:
            signal.signal(s, old[s])


def _collect_parallel(out: Path, cfg: CollectConfig, todo: list[int], workers: int,
                      finish: Callable[[dict], None], update: Callable[[int], None]) -> None:
    """Collect shards `todo` in a pool of spawned workers; ending the pool ends every worker."""
    sizes = cfg.shard_sizes()
    ctx = mp.get_context("spawn")
    q = ctx.SimpleQueue()  # progress counts; pipes only: no manager process, no temp folder
    pool = ctx.Pool(min(workers, len(todo)), initializer=_worker_init, initargs=(q, os.getpid()))
    try:
        results = pool.imap_unordered(_worker, [(cfg, str(out), i, sizes[i]) for i in todo])
        remaining = len(todo)
        while remaining:
            while not q.empty():
                update(q.get())
            try:
                finish(results.next(timeout=0.1))
                remaining -= 1
            except mp.TimeoutError:
                pass
        while not q.empty():
            update(q.get())
        pool.close()  # the workers take the end-of-work sentinel and exit
    except BaseException:
        pool.terminate()  # SIGTERM to every worker: each unwinds, removing a half-written shard
        raise
    finally:
        pool.join()
        q.close()
        remove_temp_files(out)


def _ray_shard(cfg: CollectConfig, index: int, size: int) -> dict[str, np.ndarray]:
    """One shard as a Ray task: its arrays, collected in the worker from the shard's own seed."""
    return collect_shard(cfg, index, size)


def _collect_ray(out: Path, cfg: CollectConfig, todo: list[int], workers: int, address: str | None,
                 finish: Callable[[dict], None], update: Callable[[int], None]) -> None:
    """Collect shards `todo` as Ray tasks, `workers` at once; this process writes each as it arrives."""
    from symlearn.cluster import as_finished, ray_session

    sizes = cfg.shard_sizes()
    with ray_session(address, num_cpus=workers) as ray:
        for index, arrays in as_finished(ray, _ray_shard, ((i, (cfg, i, sizes[i])) for i in todo), window=workers):
            finish(_write_shard(out, index, arrays))
            update(1)


def collect(out: Path, cfg: CollectConfig, workers: int = 1, show_progress: bool = True, engine: str = "local",
            address: str | None = None) -> dict:
    """Collect (or finish collecting) a data set into `out`; returns the final manifest.

    engine "local" runs shards in this process (workers=1) or a pool of `workers` processes; "ray" runs
    them as Ray tasks, `workers` in flight, on the cluster at `address` or a local Ray of `workers` CPUs
    (symlearn.cluster), with a progress bar over shards. Either way the shards are the same bytes.
    SIGINT or SIGTERM ends the workers (cancels the tasks), removes temp files and raises
    CollectInterrupted; re-running the same call resumes.
    """
    from symlearn.cluster import EngineError, check_engine

    out = Path(out)
    if not _is_int(workers) or workers < 1:
        raise CollectError(f"workers={workers!r} must be at least 1")
    try:
        check_engine(engine, address)
    except EngineError as e:
        raise CollectError(str(e)) from None
    with folder_lock(out):  # one writer: a second `collect` into this folder is refused at once
        _refuse_run_folder(out)
        done = _resume_state(out, cfg)
        return _collect_locked(out, cfg, workers, show_progress, done, engine, address)


def _collect_locked(out: Path, cfg: CollectConfig, workers: int, show_progress: bool, done: dict, engine: str,
                    address: str | None) -> dict:
    """collect's work, inside the folder's lock: the shards not in `done`, then the final manifest."""
    remove_temp_files(out)
    sizes = cfg.shard_sizes()
    todo = [i for i in range(len(sizes)) if i not in done]
    from tqdm import tqdm

    if engine == "ray":  # results come whole, a shard at a time
        bar = tqdm(total=len(sizes), initial=len(done), unit="shard", disable=not show_progress, desc="collect")
    else:
        bar = tqdm(total=cfg.n, initial=sum(sizes[i] for i in done), unit="sample", smoothing=0.05,
                   disable=not show_progress, desc="collect")

    def finish(info: dict) -> None:
        done[info["index"]] = info
        atomic_write_json(out / "manifest.json", _manifest(cfg, done))

    with _interruptible():
        try:
            atomic_write_json(out / "manifest.json", _manifest(cfg, done))
            if engine == "ray" and todo:
                _collect_ray(out, cfg, todo, workers, address, finish, bar.update)
            elif workers == 1 or len(todo) <= 1:
                for i in todo:
                    finish(_write_shard(out, i, collect_shard(cfg, i, sizes[i], progress=bar.update)))
            else:
                _collect_parallel(out, cfg, todo, workers, finish, bar.update)
        finally:
            bar.close()
    manifest = _manifest(cfg, done)
    atomic_write_json(out / "manifest.json", manifest)
    return manifest
