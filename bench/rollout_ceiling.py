"""How far multi-step symbolic prediction can go: m(z) with more attention rounds, and what the symbols allow.

Part 1 trains m(z) (quick preset) on a run's codes with each of --rounds self-attention rounds and each of
--seeds, and scores whole-scene rollout accuracy for 1..8 actions along held-out test episodes.

With --rollout-train L, m(z) with the last of --rounds is also trained on chains of L consecutive
actions, each step fed the previous step's prediction (binarised, straight-through gradient), for the
seeds of --rollout-seeds.

Part 2 asks how deterministic the symbols themselves are, for the run's codes and for arrangement labels
read from poses (type, nearest location, 5 cm height level; symlearn.data.statistics.arrangement_labels),
with a per-object table fitted on train + val: key (own symbol, action, the other objects' symbols as a
multiset), value the most common next symbol. Reported: the share of training objects whose next symbol is
their key's majority (keys seen at least --min-count times), the same per whole scene (every object's key
seen that often), the share of test objects whose key the table holds and its accuracy there, and the
table's rollouts (an unseen key keeps its symbol). A scene-level determinism d caps any model on those
symbols near d ** n at n steps. Writes JSON.

    python bench/rollout_ceiling.py --run pretrained/quick-stab12k --data data/paper_a \
        --out bench/results/rollout_ceiling_quick_stab.json
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np


def _key(state: np.ndarray, i: int, action: int) -> tuple:
    """An object's table key: its symbol, the action and the others' symbols as a sorted tuple."""
    return int(state[i]), action, tuple(sorted(int(x) for j, x in enumerate(state) if j != i and x >= 0))


def fit_table(before: np.ndarray, after: np.ndarray, action: np.ndarray) -> dict:
    """key -> Counter of next symbols, over every real object (symbols >= 0) of every sample."""
    table: dict = defaultdict(Counter)
    for b, a, act in zip(before, after, action.tolist()):
        for i in np.flatnonzero(b >= 0):
            table[_key(b, i, act)][int(a[i])] += 1
    return table


def determinism(table: dict, before: np.ndarray, after: np.ndarray, action: np.ndarray, min_count: int) -> dict:
    """Object- and scene-level share of next symbols that are their key's majority, on keys seen >= min_count."""
    obj_ok = obj_n = scene_ok = scene_n = 0
    for b, a, act in zip(before, after, action.tolist()):
        oks = []
        for i in np.flatnonzero(b >= 0):
            c = table[_key(b, i, act)]
            if sum(c.values()) >= min_count:
                oks.append(c.most_common(1)[0][0] == a[i])
        obj_ok, obj_n = obj_ok + sum(oks), obj_n + len(oks)
        if len(oks) == int((b >= 0).sum()):
            scene_ok, scene_n = scene_ok + all(oks), scene_n + 1
    return {"object": round(float(obj_ok / max(obj_n, 1)), 4), "objects": obj_n,
            "scene": round(scene_ok / max(scene_n, 1), 4), "scenes": scene_n}


def _predict(table: dict, state: np.ndarray, action: int) -> np.ndarray:
    out = state.copy()
    for i in np.flatnonzero(state >= 0):
        c = table.get(_key(state, i, action))
        if c:
            out[i] = c.most_common(1)[0][0]
    return out


def table_scores(table: dict, before: np.ndarray, after: np.ndarray, action: np.ndarray,
                 chains: dict[int, np.ndarray]) -> dict:
    """Test objects whose key the table holds, its accuracy there, and its whole-scene rollouts."""
    seen = right = total = 0
    for b, a, act in zip(before, after, action.tolist()):
        for i in np.flatnonzero(b >= 0):
            total += 1
            c = table.get(_key(b, i, act))
            if c:
                seen += 1
                right += c.most_common(1)[0][0] == a[i]
    roll = {}
    for n, rows in chains.items():
        ok = 0
        for row in rows:
            s = before[row[0]]
            for j in row:
                s = _predict(table, s, int(action[j]))
            ok += bool((s == after[row[-1]]).all())
        roll[str(n)] = round(ok / max(len(rows), 1), 4)
    return {"test_objects_seen": round(seen / max(total, 1), 4), "accuracy_on_seen": round(float(right / max(seen, 1)), 4),
            "rollout_scene_accuracy": roll}


def fit_on_rollouts(cfg, train, val, seed: int, steps: int):
    """m(z) trained on chains of `steps` actions, each fed the previous prediction; best validation weights."""
    import torch

    from symlearn.symbolic.transition_metrics import rollout_chains
    from symlearn.symbolic.transition_model import masked_bce
    from symlearn.symbolic.transition_training import fit_transition

    chains = torch.from_numpy(rollout_chains(train, steps))
    x, m, a, y = (torch.from_numpy(v) for v in (train.before, train.mask, train.action, train.after))

    def chain_epoch(net, opt, gen, epoch: int) -> float:
        net.train()
        perm = torch.randperm(len(chains), generator=gen)
        losses = []
        for b in range(0, len(chains), cfg.batch_size):
            ch = chains[perm[b:b + cfg.batch_size]]
            mask, state, loss = m[ch[:, 0]], x[ch[:, 0]], 0.0
            for j in range(steps):  # each step is fed the previous step's binarised prediction (straight through)
                out = net(state, mask, a[ch[:, j]])
                loss = loss + masked_bce(out.logits, y[ch[:, j]], mask)
                p = torch.sigmoid(out.logits)
                state = ((p > 0.5).float() + p - p.detach()) * mask[..., None]
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            losses.append(float(loss.detach()) / steps)
        return sum(losses) / max(len(losses), 1)

    return fit_transition(cfg, train, val, seed, train_epoch=chain_epoch)[0]


def sweep_rounds(splits: dict, rounds: list[int], seeds: list[int]) -> dict:
    """Rollout scene accuracies of m(z) (quick preset) for each number of attention rounds and seed, with mean ± std."""
    from symlearn.symbolic.transition_metrics import evaluate_transition
    from symlearn.symbolic.transition_model import TransitionConfig
    from symlearn.symbolic.transition_training import fit_transition

    nets = {}
    for r in rounds:
        per_seed = {}
        for seed in seeds:
            cfg = TransitionConfig.from_preset("quick", attention_rounds=r)
            net, _, _ = fit_transition(cfg, splits["train"], splits["val"], seed)
            m = evaluate_transition(net, splits["test"])
            per_seed[str(seed)] = {n: v["scene_accuracy"] for n, v in m["rollout"].items()}
            print(f"m(z), {r} attention rounds, seed {seed}: 1 step {per_seed[str(seed)]['1']:.3f}, "
                  f"5 steps {per_seed[str(seed)]['5']:.3f}", flush=True)
        summary = {n: {"mean": round(statistics.mean(v[n] for v in per_seed.values()), 4),
                       "std": round(statistics.pstdev(v[n] for v in per_seed.values()), 4)}
                   for n in next(iter(per_seed.values()))}
        nets[str(r)] = {"seeds": per_seed, "mean_std": summary}
    return nets


def sweep_rollout_training(splits: dict, rounds: int, seeds: list[int], steps: int) -> dict:
    """Rollout scene accuracies of m(z) with `rounds` attention rounds trained on `steps`-action chains, per seed."""
    from symlearn.symbolic.transition_metrics import evaluate_transition
    from symlearn.symbolic.transition_model import TransitionConfig

    cfg = TransitionConfig.from_preset("quick", attention_rounds=rounds)
    per_seed = {}
    for seed in seeds:
        net = fit_on_rollouts(cfg, splits["train"], splits["val"], seed, steps)
        per_seed[str(seed)] = {n: v["scene_accuracy"]
                               for n, v in evaluate_transition(net, splits["test"])["rollout"].items()}
        print(f"m(z), {rounds} rounds, trained on {steps}-step rollouts, seed {seed}: "
              f"5 steps {per_seed[str(seed)]['5']:.3f}", flush=True)
    return {"seeds": per_seed}


def symbol_tables(splits: dict, data_dir: Path, min_count: int) -> dict:
    """Determinism and table scores for the run's codes and for the pose-read arrangement labels."""
    from pddl_export.symbolic import codes_from_bits
    from symlearn.data.dataset import load_split
    from symlearn.data.statistics import arrangement_labels
    from symlearn.symbolic.transition_metrics import ROLLOUT_STEPS, rollout_chains

    test = splits["test"]
    chains = {n: rollout_chains(test, n) for n in range(1, ROLLOUT_STEPS + 1)}
    raw = {s: load_split(data_dir, s) for s in ("train", "val", "test")}

    def codes(s: str, after: bool) -> np.ndarray:
        d = splits[s]
        return np.where(d.mask, codes_from_bits((d.after if after else d.before).round()), -1)

    out = {}
    for name, sym in (("codes", codes), ("arrangement", lambda s, after: arrangement_labels(raw[s], after))):
        fit_b = np.concatenate([sym("train", False), sym("val", False)])
        fit_a = np.concatenate([sym("train", True), sym("val", True)])
        fit_act = np.concatenate([splits["train"].action, splits["val"].action])
        table = fit_table(fit_b, fit_a, fit_act)
        out[name] = {"distinct": int(len(np.unique(fit_b[fit_b >= 0]))),
                     "train_determinism": determinism(table, fit_b, fit_a, fit_act, min_count),
                     **table_scores(table, sym("test", False), sym("test", True), test.action, chains)}
        print(name, json.dumps(out[name]), flush=True)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True)
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--rounds", default="1,3", help="comma-separated attention rounds to train m(z) with")
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--rollout-train", type=int, default=0, help="also train on chains of this many actions")
    ap.add_argument("--rollout-seeds", default="0")
    ap.add_argument("--min-count", type=int, default=5)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    from pddl_export.files import atomic_write_json
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.provenance import bench_context
    from symlearn.symbolic.transition_training import encode_splits

    t0 = time.perf_counter()
    encoder, _ = load_effect_model(args.run)
    splits = encode_splits(encoder, args.data, 512)
    rounds = [int(r) for r in args.rounds.split(",")]
    nets = sweep_rounds(splits, rounds, [int(s) for s in args.seeds.split(",")])
    if args.rollout_train > 1:
        nets[f"{rounds[-1]}, trained on {args.rollout_train}-step rollouts"] = sweep_rollout_training(
            splits, rounds[-1], [int(s) for s in args.rollout_seeds.split(",")], args.rollout_train)
    result = {"run": str(args.run), "data": str(args.data), "min_count": args.min_count,
              "transition_net_by_attention_rounds": nets,
              "symbol_tables": symbol_tables(splits, args.data, args.min_count),
              **bench_context(), "wall_s": round(time.perf_counter() - t0, 1)}
    atomic_write_json(args.out, result)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
