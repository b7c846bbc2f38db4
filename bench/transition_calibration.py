"""Does m(z) know when it is right? Its probability of a prediction against how often the prediction holds.

For each run, the test split is encoded by the run's effect model and rolled forward with its m(z) for 1, 3
and 5 actions along held-out episodes (as in the rollout accuracy). A rollout's probability is the product,
over its steps, of P(predicted next codes) under m(z) (`predict_scored`: each step scored on the predicted
state it starts from), the quantity `astar-likely` maximises (search.learned_astar). Reported per horizon:
the share of whole scenes predicted right, the ROC AUC of the probability for telling right from wrong, the
accuracy of the most and least probable halves, and a reliability table (probability bins: count, mean
probability, accuracy) with its expected calibration error. Writes JSON.

    python bench/transition_calibration.py --runs pretrained/quick-stab12k,pretrained/quick-authors12k \
        --data data/paper_a --out bench/results/transition_calibration.json
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

HORIZONS = (1, 3, 5)
BINS = (0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0)


def calibration(p: np.ndarray, right: np.ndarray) -> dict:
    """How well probabilities p (N,) of predictions separate and match the right ones (N,) bool."""
    from sklearn.metrics import roc_auc_score

    order = np.argsort(-p, kind="stable")
    half = len(p) // 2
    table, ece = [], 0.0
    for lo, hi in zip(BINS[:-1], BINS[1:]):
        sel = (p >= lo) & ((p < hi) if hi < 1.0 else (p <= hi))
        if sel.any():
            table.append({"p": [lo, hi], "n": int(sel.sum()), "mean_p": round(float(p[sel].mean()), 4),
                          "accuracy": round(float(right[sel].mean()), 4)})
            ece += sel.mean() * abs(p[sel].mean() - right[sel].mean())
    both = 0 < right.sum() < len(right)
    return {"n": int(len(p)), "scene_accuracy": round(float(right.mean()), 4),
            "mean_p": round(float(p.mean()), 4),
            "auc": round(float(roc_auc_score(right, p)), 4) if both else None,
            "accuracy_most_probable_half": round(float(right[order[:half]].mean()), 4),
            "accuracy_least_probable_half": round(float(right[order[half:]].mean()), 4),
            "expected_calibration_error": round(float(ece), 4), "reliability": table}


def rollout_scores(net, data, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Probability of each n-step rollout along a test episode and whether its final scene is right."""
    from symlearn.symbolic.transition_metrics import rollout

    chains, state, nll = rollout(net, data, n)
    right = ((state == data.after[chains[:, -1]]).all(-1) | ~data.mask[chains[:, 0]]).all(-1)
    return np.exp(-nll), right


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", required=True, help="comma-separated run folders holding best.pt and transition.pt")
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    from pddl_export.files import atomic_write_json
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.provenance import bench_context
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, load_transition
    from symlearn.symbolic.transition_data import build_transition_data
    from symlearn.data.dataset import load_split

    t0 = time.perf_counter()
    runs = {}
    test = load_split(args.data, "test")
    for run in [Path(r) for r in args.runs.split(",")]:
        encoder, _ = load_effect_model(run)
        net, _ = load_transition(run / TRANSITION_FILE)
        data = build_transition_data(encoder, test, 512)
        runs[str(run)] = {str(n): calibration(*rollout_scores(net, data, n)) for n in HORIZONS}
        for n, c in runs[str(run)].items():
            print(f"{run} {n} steps: accuracy {c['scene_accuracy']} AUC {c['auc']} "
                  f"most/least probable half {c['accuracy_most_probable_half']}/{c['accuracy_least_probable_half']} "
                  f"ECE {c['expected_calibration_error']}")
    atomic_write_json(args.out, {"data": str(args.data), "split": "test", "runs": runs,
                                 **bench_context(),
                                 "wall_s": round(time.perf_counter() - t0, 1)})
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
