"""Ray against the local process pool for collection, the same worker count, measured in one run; writes JSON.

Three ways to collect the same set (same seed and shard size, so the same bytes, which the script checks):
  local      `collect(workers=W)`: a pool of W spawned processes (today's engine)
  ray        `collect(engine="ray", workers=W)`: a local Ray of W CPUs started and shut down by the call,
             as a one-off `symlearn collect --ray` on one machine pays it
  ray_warm   the same on a Ray already running (started before the clock), as on a cluster whose head
             outlives each collection
Each is run `--repeats` times, interleaved, and the medians compared: ratio = ray time / local time. The
local pool's rate per worker gives the projection of 1M samples in core-hours.

    python bench/ray_overhead.py --out bench/results/ray_overhead.json --n 600 --workers 2
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from symlearn.provenance import atomic_write_json, bench_context
from symlearn.sim.collect import CollectConfig, collect

MILLION = 1_000_000


def timed_collect(folder: Path, cfg: CollectConfig, workers: int, engine: str) -> tuple[float, dict[str, bytes]]:
    """Seconds to collect cfg into a fresh `folder`, and the shard bytes it wrote (the folder is removed after)."""
    shutil.rmtree(folder, ignore_errors=True)
    t = time.perf_counter()
    collect(folder, cfg, workers=workers, show_progress=False, engine=engine)
    seconds = time.perf_counter() - t
    shards = {p.name: p.read_bytes() for p in sorted(folder.glob("shard_*.npz"))}
    shutil.rmtree(folder)
    return seconds, shards


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="bench/results/ray_overhead.json")
    ap.add_argument("--n", type=int, default=600, help="samples per measured collection")
    ap.add_argument("--workers", type=int, default=2, help="pool processes, and Ray CPUs")
    ap.add_argument("--shard-size", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=2, help="runs of each way, interleaved")
    args = ap.parse_args()

    import ray

    cfg = CollectConfig(n=args.n, seed=0, shard_size=args.shard_size)
    load_before = os.getloadavg()[0]
    times: dict[str, list[float]] = {"local": [], "ray": [], "ray_warm": []}
    reference = None
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "set"
        for _ in range(args.repeats):
            for way in times:
                if way == "ray_warm":
                    ray.init(num_cpus=args.workers, include_dashboard=False, log_to_driver=False,
                             configure_logging=False)
                try:
                    seconds, shards = timed_collect(folder, cfg, args.workers, "local" if way == "local" else "ray")
                finally:
                    if way == "ray_warm":
                        ray.shutdown()
                reference = reference or shards
                if shards != reference:
                    raise SystemExit(f"{way}: shards differ from the first run's; the engines must agree byte for byte")
                times[way].append(round(seconds, 2))
    med = {way: statistics.median(ts) for way, ts in times.items()}
    per_core = args.n / med["local"] / args.workers  # samples per second per worker process
    result = {
        "benchmark": "ray_overhead", **bench_context(), "ray": ray.__version__, "n_samples": args.n,
        "workers": args.workers, "shards": len(cfg.shard_sizes()), "repeats": args.repeats,
        "seconds": times, "median_s": {k: round(v, 2) for k, v in med.items()},
        "samples_per_s": {k: round(args.n / v, 2) for k, v in med.items()},
        "ratio_ray_vs_local": round(med["ray"] / med["local"], 3),
        "ratio_ray_warm_vs_local": round(med["ray_warm"] / med["local"], 3),
        "shards_identical": True,
        "load_average_1min": {"before": round(load_before, 2), "after": round(os.getloadavg()[0], 2)},
        "per_core_samples_per_s": round(per_core, 2),
        "core_hours_per_million_samples": round(MILLION / per_core / 3600, 1),
    }
    atomic_write_json(Path(args.out), result)
    print(result)


if __name__ == "__main__":
    main()
