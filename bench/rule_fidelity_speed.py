"""Applying and checking a big rule set: rules grouped by (action, own code) against one rule at a time.

`export-pddl` checks its rules on every enumerated case (rule_fidelity -> apply_rules_batch) and
every RuleSet checks that the rules of each (action, own code) are mutually exclusive. Until
2026-11-29 apply_rules_batch compared every row of an action with each of its rules in turn, and
the exclusivity check built (R, R, C) int64 arrays per group: with the 5-object rules (55k rules,
165k second-outcome rules) the two fidelity passes took 263 s and 632 s of a 15-min export. Now both
use RuleSet.dense_groups: each group's rules as int16 bound arrays, compared at once with only the
(row, object) pairs holding that group's code, in chunks.

Scenes: `--scenes` random multisets of 1..max_objects codes of the rules' vocabulary (seeded),
each under all 36 actions. Both ways run in the same process on the same batch, baseline first,
and must give equal next codes.

    python bench/rule_fidelity_speed.py --run RUN --scenes 3000 --out bench/results/rule_fidelity_speed.json
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from pddl_export.outcome_rules import load_outcomes
from pddl_export.rules import INF, Rule, RuleSet, apply_rules_batch
from pddl_export.rules_io import load_rules
from pddl_export.symbolic import N_ACTIONS
from symlearn.provenance import atomic_write_json, bench_context


def per_rule_batch(rules: RuleSet, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
    """The baseline: apply_rules_batch as it was, every row of an action compared with each rule in turn."""
    out = codes.copy()
    by_action: dict[int, list[Rule]] = {}
    for r in rules.rules:
        by_action.setdefault(r.action, []).append(r)
    for a, group in by_action.items():
        rows = np.flatnonzero(actions == a)
        if not rows.size:
            continue
        sub = codes[rows]
        totals: dict[int, np.ndarray] = {}
        for r in group:
            ok = sub == r.code_from
            if not ok.any():
                continue
            for x, (lo, hi) in r.bounds().items():
                if x not in totals:
                    totals[x] = (sub == x).sum(1)
                others = totals[x][:, None] - (sub == x)
                ok &= (others >= lo) & (others < hi)
            rr, kk = np.nonzero(ok)
            out[rows[rr], kk] = r.code_to
    return out


def pairwise_int64_overlap(rules: RuleSet) -> int:
    """The baseline exclusivity check: (R, R, C) int64 arrays per group; returns the groups checked."""
    n = 0
    for group in (rules.rules_for(a, c) for a, c in rules.dense_groups):
        if len(group) < 2:
            continue
        boxes = [r.bounds() for r in group]
        codes = sorted({x for b in boxes for x in b})
        lo = np.array([[b.get(x, (0, INF))[0] for x in codes] for b in boxes], np.int64)
        hi = np.array([[b.get(x, (0, INF))[1] for x in codes] for b in boxes], np.int64)
        disjoint = np.any(np.maximum(lo[:, None], lo[None]) >= np.minimum(hi[:, None], hi[None]), axis=2)
        if (~disjoint & ~np.eye(len(boxes), dtype=bool)).any():
            raise SystemExit("baseline check found overlapping rules")
        n += 1
    return n


def dense_overlap(rules: RuleSet) -> int:
    """The exclusivity check as RuleSet runs it now (group arrays built, then compared in chunks): a fresh RuleSet
    of the same rules, which refuses overlapping ones; returns the groups checked."""
    try:
        fresh = RuleSet(rules.bits, rules.vocabulary, rules.max_objects, rules.rules, rules.n_rules_before_generalization)
    except ValueError as e:
        raise SystemExit(f"dense check found overlapping rules: {e}") from None
    return sum(len(fresh.rules_for(a, c)) > 1 for a, c in fresh.dense_groups)


def batch(rules: RuleSet, n_scenes: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(n_scenes * 36, max_objects) codes padded with -1, and their actions."""
    rng = np.random.default_rng(seed)
    vocab = np.array(rules.vocabulary)
    k = rules.max_objects
    scenes = np.full((n_scenes, k), -1, np.int64)
    sizes = rng.integers(1, k + 1, n_scenes)
    for i, s in enumerate(sizes.tolist()):
        scenes[i, :s] = np.sort(rng.choice(vocab, s))
    return np.repeat(scenes, N_ACTIONS, 0), np.tile(np.arange(N_ACTIONS), n_scenes)


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, help="a run with pddl/rules.json and pddl/outcomes.json")
    ap.add_argument("--scenes", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    run = Path(args.run)
    rules, _ = load_rules(run)
    outcomes, _ = load_outcomes(run)
    report = {**bench_context(), "run": str(run), "scenes": args.scenes, "seed": args.seed, "rule_sets": {}}
    for name, rs in (("rules", rules), ("outcome_rules", outcomes.rules)):
        codes, actions = batch(rs, args.scenes, args.seed)
        want, t_base = timed(per_rule_batch, rs, codes, actions)
        got, t_new = timed(apply_rules_batch, rs, codes, actions)
        if not np.array_equal(want, got):
            raise SystemExit(f"{name}: the two ways gave different next codes")
        n_base, c_base = timed(pairwise_int64_overlap, rs)
        n_new, c_new = timed(dense_overlap, rs)
        assert n_base == n_new
        report["rule_sets"][name] = {
            "n_rules": rs.n_rules, "max_objects": rs.max_objects, "rows": len(codes),
            "changed_objects": int((got != codes).sum()),
            "apply_per_rule_s": round(t_base, 3), "apply_grouped_s": round(t_new, 3),
            "apply_speedup": round(t_base / t_new, 2),
            "groups_checked": n_new, "check_int64_pairs_s": round(c_base, 3), "check_dense_chunks_s": round(c_new, 3),
            "check_speedup": round(c_base / c_new, 2)}
        print(name, report["rule_sets"][name])
    atomic_write_json(Path(args.out), report)


if __name__ == "__main__":
    main()
