"""Lifted rules against m(z) on a fresh data set that neither was trained nor chosen on: every split of it.

A data set's test split is 1,000 steps: the difference between the rules' accuracy and m(z)'s (both against what
the robot observed next) then has a standard error of about 0.011 (0.0033 on 12,000 steps), as large as the
differences between the settings of the lifted export. This script reads a whole further data set (`symlearn
collect` with a seed of its own; all its splits are unseen by the run), checks each setting's rules on every step
of it beside m(z), and gives the difference with a paired bootstrap 95% interval, by object count and by what the
rules make of a step (`step_checks`, which `check_lifted` tallies).

    symlearn collect --out data/k15h2 --n 12000 --objects 1-5 --workers 2 --seed 102
    python experiments/heldout_accuracy.py --run RUN --data data/paper_a data/k15 --heldout data/k15h2 \
        --setting fast=min_count:50,rider_min_count:3 --setting m20r6=min_count:20,rider_min_count:6 \
        --setting accurate=min_count:30,pair_min_count:10,pool_min_count:20,pool_classes:cube,pool_structure_min:12,end_min_count:6 \
        --out bench/results/heldout_k15h2.json

A setting is NAME=FIELD:VALUE,... over LiftedConfig's fields, as in experiments/preset_sweep.py; empty: the defaults
(min count 20, rider moves 6 since 2026-12-06: `m20r6` above; `fast` there is the earlier default).
"""
from __future__ import annotations

import argparse
import dataclasses
from collections import Counter
from pathlib import Path

import numpy as np

from preset_sweep import parse_settings  # experiments/preset_sweep.py, beside this script (NAME=FIELD:VALUE,...)

SPLITS = ("train", "val", "test")
GROUPS = (("all", lambda k: k > 0), ("1-3", lambda k: k <= 3), ("4-5", lambda k: k >= 4))


def paired_interval(right: np.ndarray, net_right: np.ndarray, seed: int, n_boot: int = 2000) -> list[float]:
    """95% bootstrap interval of mean(right - net_right) over steps resampled with replacement."""
    d = right.astype(float) - net_right.astype(float)
    rng = np.random.default_rng(seed)
    means = [d[rng.integers(0, len(d), len(d))].mean() for _ in range(n_boot)]
    return [round(float(np.percentile(means, 2.5)), 4), round(float(np.percentile(means, 97.5)), 4)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, type=Path, help="a run with m(z) on 9 location bits")
    ap.add_argument("--data", required=True, type=Path, nargs="+", help="the data sets export-pddl reads "
                    "(their training splits give the rules)")
    ap.add_argument("--heldout", required=True, type=Path, help="a data set neither of the run nor of --data")
    ap.add_argument("--setting", action="append", required=True, help="NAME=FIELD:VALUE,... (repeat)")
    ap.add_argument("--seed", type=int, default=0, help="the bootstrap's seed")
    ap.add_argument("--out", required=True, type=Path)
    args = ap.parse_args(argv)
    settings = parse_settings(args.setting, "heldout_accuracy")
    for d in (*args.data, args.heldout):
        if not (d / "manifest.json").is_file():
            raise SystemExit(f"heldout_accuracy: no data set at {d} (no manifest.json)")
    if args.heldout.resolve() in {d.resolve() for d in args.data}:
        raise SystemExit(f"heldout_accuracy: {args.heldout} is one of --data: its training split made the rules")
    from pddl_export.files import sha256_file
    heldout_hash = sha256_file(args.heldout / "manifest.json")
    same = [d for d in args.data if sha256_file(d / "manifest.json") == heldout_hash]
    if same:
        raise SystemExit(f"heldout_accuracy: {args.heldout} is a copy of {same[0]} (the same manifest.json): "
                         "its training split made the rules")
    first = next(iter(settings.values()))

    from symlearn.export.lifted_export import distil_rules, network_steps, split_codes, step_checks, \
        training_moves
    from symlearn.provenance import atomic_write_json, bench_context
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    reader, transition = planning_models(args.run)
    model_hash = sha256_file(args.run / TRANSITION_FILE)[:16]
    seen = training_moves(reader, transition, list(args.data), first)
    rules = {n: distil_rules(seen, c, model_hash) for n, c in settings.items()}
    right: dict = {n: [] for n in rules}
    net_right: dict = {n: [] for n in rules}
    counts: dict = {n: [] for n in rules}
    by_case: dict = {n: {} for n in rules}
    for split in SPLITS:
        s = split_codes(reader, args.heldout, split)
        net = network_steps(transition, s.before, s.action, s.mask)
        for n, r in rules.items():
            for c in step_checks(r, s, net):
                right[n].append(c.rules_right)
                net_right[n].append(c.net_right)
                counts[n].append(c.objects)
                for group in (g for g, pick in GROUPS if pick(c.objects)):
                    t = by_case[n].setdefault(group, {}).setdefault(c.case, Counter())
                    t["cases"] += 1
                    t["rules_right"] += c.rules_right
                    t["m(z)_right"] += c.net_right
    report = {}
    for n in rules:
        mine, net_a, counts_a = np.array(right[n]), np.array(net_right[n]), np.array(counts[n])
        report[n] = {"setting": dataclasses.asdict(settings[n]), "rules": len(rules[n].rules),
                     "end_rules": len(rules[n].end_rules)}
        for group, pick in GROUPS:
            sel = pick(counts_a)
            report[n][group] = {"steps": int(sel.sum()), "rules": round(float(mine[sel].mean()), 4),
                                "m(z)": round(float(net_a[sel].mean()), 4),
                                "difference": round(float(mine[sel].mean() - net_a[sel].mean()), 4),
                                "ci95": paired_interval(mine[sel], net_a[sel], args.seed)}
        report[n]["by_case"] = {g: {c: dict(t) for c, t in sorted(d.items(), key=lambda x: -x[1]["cases"])}
                                for g, d in by_case[n].items()}
        a = report[n]["all"]
        print(f"{n}: rules {a['rules']:.4f}, m(z) {a['m(z)']:.4f}, difference {a['difference']:+.4f} "
              f"(95% {a['ci95'][0]:+.4f} to {a['ci95'][1]:+.4f}); 1-3 objects {report[n]['1-3']['difference']:+.4f},"
              f" 4-5 {report[n]['4-5']['difference']:+.4f}")
    atomic_write_json(args.out, {"run": str(args.run), "run_model_hash": model_hash,
                                 "data": [str(d) for d in args.data], "heldout": str(args.heldout),
                                 "heldout_manifest_sha256": heldout_hash[:16],
                                 "seed": args.seed, "summary": report, **bench_context()})
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
