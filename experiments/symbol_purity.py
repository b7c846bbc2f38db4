"""What a run's symbols encode: how far each code pins down an object's type, location and height, and back.

For every real test object the code of its pre-state crop is compared with its arrangement, read from poses the
model never sees (`symlearn.data.statistics.arrangement_labels`): type, the nearest of the 6 table locations, and
its height level (5 cm steps above the type's resting height). Purity of a property: the share of objects whose code's most common value of that property is theirs.
Determinism: the share of objects whose (type, location, level) group's most common code is theirs: 1.0 means
the same arrangement always gets the same symbol. Also: how many codes change when every crop window is shifted
by 1-2 pixels (placement jitter), and, where the run has m(z), how often it gets the held object's next code
right, against how often the most common next code for the same (code, release location) is the observed one.

    python experiments/symbol_purity.py --runs pretrained/quick-authors12k,RUN2 --data data/paper_a --out bench/results/symbol_purity.json
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np
import torch

from pddl_export.symbolic import codes_from_bits
from symlearn.data.dataset import load_split
from symlearn.data.statistics import arrangement_labels, held_mask
from symlearn.learning.checkpoint import effect_model_sha256, load_effect_model
from symlearn.provenance import atomic_write_json, bench_context
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, load_transition
from symlearn.symbolic.transition_data import build_transition_data, encode_crops
from symlearn.symbolic.transition_model import predict_bits
from symlearn.world import LOCATIONS

SHIFTS = ((1, 0), (0, 1), (2, 0), (0, 2), (-2, -2))


def majority_share(keys: np.ndarray, values: np.ndarray) -> float:
    """Share of items whose key's most common value is their own value."""
    groups: dict = defaultdict(Counter)
    for k, v in zip(keys.tolist(), values.tolist()):
        groups[k][v] += 1
    return round(sum(max(c.values()) for c in groups.values()) / max(len(keys), 1), 4)


def purity(run: Path, data_dir: Path, n_shift: int = 400) -> dict:
    """The purity, determinism and jitter figures of one run on the data set's test split."""
    data = load_split(data_dir, "test")
    model, _ = load_effect_model(run)
    origin = data.pre_origin.astype(np.float32)
    bits = encode_crops(model, data.pre_depth, origin, data.mask)
    m = data.mask
    codes = codes_from_bits(bits.round())[m]
    dist = np.linalg.norm(data.pre_pose[..., None, :2] - np.asarray(LOCATIONS)[None, None], axis=-1)  # (N, K, 6)
    arrangement = arrangement_labels(data)[m]  # type * 1000 + location * 10 + level
    typ, loc, level = arrangement // 1000, arrangement // 10 % 100, arrangement % 10
    sub = slice(0, n_shift)
    base = encode_crops(model, data.pre_depth[sub], origin[sub], data.mask[sub])
    shifted = {}
    for dr, dc in SHIFTS:
        c = encode_crops(model, data.pre_depth[sub], origin[sub] + np.float32([dr, dc]), data.mask[sub])
        shifted[f"{dr},{dc}"] = round(float((c != base).any(-1)[data.mask[sub]].mean()), 4)
    held_next = _held_next_code(run, model, data) if (run / TRANSITION_FILE).exists() else None
    return {"run": str(run), "effect_model_sha256": effect_model_sha256(run), "objects": int(m.sum()),
            "distinct_codes": int(len(np.unique(codes))),
            "type_purity": majority_share(codes, typ), "location_purity": majority_share(codes, loc),
            "level_purity": majority_share(codes, level), "arrangement_purity": majority_share(codes, arrangement),
            "arrangement_determinism": majority_share(arrangement, codes),
            "arrangement_groups": int(len(np.unique(arrangement))),
            "off_location_share": round(float((dist.min(-1)[m] > 0.05).mean()), 4),
            "codes_changed_by_pixel_shift": shifted, "held_next_code": held_next}


def _held_next_code(run: Path, model, data) -> dict:
    """m(z)'s accuracy on the held object's next code, and the ceiling a (code, release location) table reaches."""
    td = build_transition_data(model, data)
    net, _ = load_transition(run / TRANSITION_FILE)
    pred = predict_bits(net, td.before, td.mask, td.action)
    held = held_mask(data) & data.mask
    rows, cols = np.nonzero(held)
    ok = (pred == td.after).all(-1)[rows, cols]
    before = codes_from_bits(td.before.round())[rows, cols]
    after = codes_from_bits(td.after.round())[rows, cols]
    release = (data.action[rows] % len(LOCATIONS)).astype(np.int64)
    return {"held_objects": int(len(rows)), "net_accuracy": round(float(ok.mean()), 4) if len(rows) else None,
            "majority_share": majority_share(before * 10 + release, after)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", required=True, help="comma-separated run folders")
    ap.add_argument("--data", required=True, help="data set whose test split is encoded")
    ap.add_argument("--out", required=True, help="JSON file to write")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)
    torch.set_num_threads(args.threads)
    rows = [purity(Path(r), Path(args.data)) for r in args.runs.split(",")]
    atomic_write_json(args.out, {"data": args.data, **bench_context(), "runs": rows})
    for r in rows:
        print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
