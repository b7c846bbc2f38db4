"""Collection speed: samples/s with 1 and 2 workers, against the original code's motion timing.

The baseline is this same simulator run at the original code's timing (docs/DESIGN.md, reference facts:
1/240 s steps, pybullet's 50 solver iterations, about 1.5 s of arm motion per segment), measured
in the same run, so the figures are ratios on one machine. Writes JSON.

    python bench/collect.py --out bench/results/collect.json
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from symlearn.sim.collect import CollectConfig, collect, collect_shard
from symlearn.data.dataset import effect_statistics, load_split
from symlearn.provenance import bench_context
from symlearn.sim.simulator import SimConfig

ORIGINAL_TIMING = SimConfig(time_step=1 / 240, solver_iterations=50, accel_free=0.5, accel_loaded=0.5,
                            accel_loaded_vertical=0.5)


def rate_in_process(cfg: CollectConfig, n: int) -> float:
    t = time.perf_counter()
    collect_shard(cfg, 0, n)
    return n / (time.perf_counter() - t)


def rate_with_workers(cfg: CollectConfig, workers: int) -> tuple[float, dict]:
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        collect(Path(d) / "set", cfg, workers=workers, show_progress=False)
        rate = cfg.n / (time.perf_counter() - t)
        stats = effect_statistics(load_split(Path(d) / "set", "all"))
    return rate, stats


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/results/collect.json")
    ap.add_argument("--n", type=int, default=480, help="samples per measured run")
    ap.add_argument("--baseline-n", type=int, default=40)
    args = ap.parse_args()

    cfg = CollectConfig(n=args.n, seed=0, shard_size=args.n // 12)
    one, stats = rate_with_workers(cfg, 1)
    two, _ = rate_with_workers(cfg, 2)
    base = rate_in_process(CollectConfig(n=args.baseline_n, seed=0, sim=ORIGINAL_TIMING), args.baseline_n)
    result = {
        "benchmark": "collect", **bench_context(), "n_samples": args.n, "crop": cfg.sim.crop,
        "samples_per_s_1_worker": round(one, 2), "samples_per_s_2_workers": round(two, 2),
        "scaling_2_workers": round(two / one, 2),
        "baseline_original_timing_samples_per_s": round(base, 2),
        "speedup_vs_original_timing_1_worker": round(one / base, 1),
        "effect_statistics": stats,
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
