"""Levers on multi-step symbolic prediction: the transition network alone, and observed tables with it as fallback.

The run's effect model encodes the data set's train, val and test splits. The observed table maps a
whole symbolic state and an action (as seen in train + val) to the next state seen most often after
it; "table+net" answers from the table where it has the (state, action) and from the network
elsewhere. Both roll 1..--steps actions along held-out test episodes from the encoder's codes and are
scored by whole-scene accuracy against the encoder's codes after the last action. Also reported, on
the one-step test transitions whose (state, action) the table holds: how often the test outcome is
the table's majority (a ceiling for any deterministic model on those codes) and how often the network
is right there. Writes JSON.

    python bench/transition_levers.py --run pretrained/quick-authors12k --data data/paper_a \
        --out bench/results/transition_levers.json
"""
from __future__ import annotations

import argparse
import time
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np


def _states(data, rows: np.ndarray, which: str) -> list[tuple[int, ...]]:
    """The codes (of real objects) before or after each of the rows, as tuples."""
    from pddl_export.symbolic import codes_from_bits

    codes = codes_from_bits(getattr(data, which)[rows])  # (n, K)
    mask = data.mask[rows]
    return [tuple(int(c) for c, ok in zip(r, m) if ok) for r, m in zip(codes, mask)]


def observed_table(splits) -> dict:
    """(state, action) -> the next state seen most often, over the train and val splits."""
    counts: dict = defaultdict(Counter)
    for s in ("train", "val"):
        d = splits[s]
        rows = np.arange(len(d))
        for a, b, act in zip(_states(d, rows, "before"), _states(d, rows, "after"), d.action.tolist()):
            counts[(a, int(act))][b] += 1
    return {k: c.most_common(1)[0][0] for k, c in counts.items()}


def rollouts(transition, table: dict, data, steps: int) -> dict:
    """Whole-scene rollout accuracy of the network and of table+net for 1..steps actions on test episodes."""
    from symlearn.symbolic.transition_metrics import rollout_chains

    out = {}
    for n in range(1, steps + 1):
        chains = rollout_chains(data, n)
        if not len(chains):
            break
        net = tab = hits = 0
        for row in chains:
            s_net = s_tab = _states(data, row[:1], "before")[0]
            for j in row:
                act = int(data.action[j])
                s_net = tuple(transition(np.array([s_net]), np.array([act]))[0].tolist())
                hit = table.get((s_tab, act))
                hits += hit is not None
                s_tab = hit if hit is not None else tuple(transition(np.array([s_tab]), np.array([act]))[0].tolist())
            truth = _states(data, row[-1:], "after")[0]
            net += s_net == truth
            tab += s_tab == truth
        out[str(n)] = {"n": int(len(chains)), "net": round(net / len(chains), 4),
                       "table+net": round(tab / len(chains), 4), "table_hit_rate": round(hits / (n * len(chains)), 4)}
    return out


def consistency(transition, table: dict, data) -> dict:
    """On test steps whose (state, action) the table holds: majority agreement and the network's accuracy."""
    rows = np.arange(len(data))
    before, after = _states(data, rows, "before"), _states(data, rows, "after")
    seen = [i for i, (s, a) in enumerate(zip(before, data.action.tolist())) if (s, int(a)) in table]
    if not seen:
        return {"n": 0}
    agree = sum(table[(before[i], int(data.action[i]))] == after[i] for i in seen)
    net = sum(tuple(transition(np.array([before[i]]), np.array([int(data.action[i])]))[0].tolist()) == after[i]
              for i in seen)
    return {"n": len(seen), "share_of_test_steps": round(len(seen) / len(rows), 4),
            "table_majority_right": round(agree / len(seen), 4), "network_right": round(net / len(seen), 4)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True)
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    from pddl_export.files import atomic_write_json
    from symlearn.provenance import bench_context
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_training import encode_splits

    t0 = time.perf_counter()
    encoder, transition = planning_models(args.run)
    splits = encode_splits(encoder, args.data, 512)
    table = observed_table(splits)
    result = {"run": str(args.run), "data": str(args.data), "table_entries": len(table),
              "rollout_scene_accuracy": rollouts(transition, table, splits["test"], args.steps),
              "one_step_on_table_states": consistency(transition, table, splits["test"]),
              **bench_context(), "wall_s": round(time.perf_counter() - t0, 1)}
    atomic_write_json(args.out, result)
    for n, r in result["rollout_scene_accuracy"].items():
        print(f"{n} steps: net {r['net']:.3f}  table+net {r['table+net']:.3f}  (table hits {r['table_hit_rate']:.2f})")
    print("one step, states the table holds:", result["one_step_on_table_states"])
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
