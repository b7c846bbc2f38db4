"""Rollout accuracy of each run's m(z) on the test splits of several data sets, by objects in the scene.

Made to compare m(z) trained on one data set with m(z) given more transition data (`symlearn
train-transition --extra-data`, for instance a 1-5-object set): each run's test episodes of each set
are encoded by the run's effect model and rolled forward 1..8 actions (as `train-transition` reports);
whole-scene accuracy is given for all chains and per object count. Each run's record names what its
m(z) was trained on (its transition_metrics.json). Writes JSON.

    python bench/transition_volume.py --runs RUN_A,RUN_B --labels a,b --data data/paper_a,data/k15 \
        --out bench/results/transition_volume.json
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

STEPS = (1, 2, 3, 5, 8)


def rollout_by_objects(net, data, n: int) -> dict:
    """Scene accuracy of n-step rollouts along test episodes: all chains, and per object count."""
    from symlearn.symbolic.transition_metrics import rollout

    chains, state, _ = rollout(net, data, n)
    mask = data.mask[chains[:, 0]]
    right = ((state == data.after[chains[:, -1]]).all(-1) | ~mask).all(-1)
    k = mask.sum(1)
    out = {"all": {"n": int(len(right)), "scene_accuracy": round(float(right.mean()), 4) if len(right) else None}}
    for kk in sorted(set(k.tolist())):
        sel = k == kk
        out[str(kk)] = {"n": int(sel.sum()), "scene_accuracy": round(float(right[sel].mean()), 4)}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", required=True, help="comma-separated run folders holding best.pt and transition.pt")
    ap.add_argument("--data", required=True, help="comma-separated data sets whose test splits are rolled out")
    ap.add_argument("--labels", help="comma-separated names for the runs in the JSON (default: their paths)")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    from pddl_export.files import atomic_write_json
    from symlearn.data.dataset import data_fingerprint, load_split
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.provenance import bench_context
    from symlearn.symbolic.transition_data import build_transition_data
    from symlearn.symbolic.transition_training import METRICS_FILE

    t0 = time.perf_counter()
    sets = [Path(d) for d in args.data.split(",")]
    tests = {d: load_split(d, "test") for d in sets}
    runs, paths = {}, [Path(r) for r in args.runs.split(",")]
    labels = args.labels.split(",") if args.labels else [str(r) for r in paths]
    if len(labels) != len(paths):
        raise SystemExit(f"--labels names {len(labels)} runs, --runs gives {len(paths)}")
    for run, label in zip(paths, labels):
        encoder, transition = planning_models(run)  # the codes m(z) reads, location bits included
        net = transition.net
        trained = json.loads((run / METRICS_FILE).read_text())
        rec = {"transition_data": [trained["data"], *(e["data"] for e in trained.get("extra_data", []))],
               "transition_seed": trained["seed"], "test": {}}
        for d, test in tests.items():
            data = build_transition_data(encoder, test, 512)
            rec["test"][str(d)] = {str(n): rollout_by_objects(net, data, n) for n in STEPS}
            print(f"{label} on {d}: " + ", ".join(f"{n} steps {r['all']['scene_accuracy']}"
                                                for n, r in rec["test"][str(d)].items()), flush=True)
        runs[label] = rec
    atomic_write_json(args.out, {"data": {str(d): data_fingerprint(d) for d in sets}, "split": "test",
                                 "steps": list(STEPS), "runs": runs, **bench_context(),
                                 "wall_s": round(time.perf_counter() - t0, 1)})
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
