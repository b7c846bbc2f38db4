"""Time loading a run's exported rules (rules.json, outcomes.json), and the check and arrays RuleSet builds on load.

Every `plan` and `benchmark` with a rule planner loads them first; rules of 1-5-object scenes are 115 MB and
272 MB of JSON. On load RuleSet builds each (action, own code) group's bound arrays and checks that the group's
rules are mutually exclusive. The baseline is that step as it was: each rule's bounds computed anew, the arrays
filled entry by entry, and every pair of rules compared on every context code. Both run in this process on the
same rules, and must give identical arrays and the same verdict. Writes JSON.

    python bench/rules_load.py --run RUN --out bench/results/rules_load.json
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np


def baseline_dense_group(group) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A group's bound arrays as RuleSet built them before (bounds per rule, then entry by entry)."""
    from pddl_export.rules import COUNT_CAP, INF

    bounds = [r.bounds() for r in group]
    cols = sorted({x for b in bounds for x in b})
    where = {x: j for j, x in enumerate(cols)}
    lo = np.zeros((len(group), len(cols)), np.int16)
    hi = np.full((len(group), len(cols)), COUNT_CAP + 1, np.int16)
    for i, b in enumerate(bounds):
        for x, (low, high) in b.items():
            lo[i, where[x]], hi[i, where[x]] = low, min(high, COUNT_CAP + 1)
    assert all(h == INF or h <= COUNT_CAP for b in bounds for _, h in b.values())
    return np.array(cols, np.int64), lo, hi, np.array([r.code_to for r in group], np.int64)


def baseline_first_overlap(lo: np.ndarray, hi: np.ndarray, max_cells: int = 1 << 22) -> tuple[int, int] | None:
    """The exclusivity check as it was: every pair of boxes compared on every column, in row chunks."""
    n = len(lo)
    step = max(1, max_cells // max(1, n * lo.shape[1]))
    for s in range(0, n, step):
        a_lo, a_hi = lo[s:s + step, None], hi[s:s + step, None]
        disjoint = np.any(np.maximum(a_lo, lo[None]) >= np.minimum(a_hi, hi[None]), axis=2)
        disjoint[np.arange(len(disjoint)), np.arange(s, s + len(disjoint))] = True
        i, j = np.nonzero(~disjoint)
        if len(i):
            return s + int(i[0]), int(j[0])
    return None


def groups_step(rules, dense_group, first_overlap) -> tuple[float, dict, list]:
    """Seconds to build every group's arrays and check it, the arrays, and each group's overlap verdict (both ways
    on one BLAS thread with the collector paused, as RuleSet loads them)."""
    from threadpoolctl import threadpool_limits

    from pddl_export.rules_io import paused_gc

    t = time.perf_counter()
    dense, verdicts = {}, []
    with threadpool_limits(1, user_api="blas"), paused_gc():
        for key in sorted(rules.dense_groups):
            group = rules.rules_for(*key)
            dense[key] = dense_group(group)
            verdicts.append(first_overlap(*dense[key][1:3]) if len(group) > 1 else None)
    return time.perf_counter() - t, dense, verdicts


def ruleset_step(rules) -> tuple[float, dict, list]:
    """What RuleSet does on load, timed on a fresh RuleSet of the same rules (the collector paused, as rules_io
    loads them): seconds, every group's arrays, and each group's verdict (None: RuleSet refuses overlapping rules,
    so a built RuleSet has no overlap)."""
    from pddl_export.rules import RuleSet
    from pddl_export.rules_io import paused_gc

    t = time.perf_counter()
    with paused_gc():
        fresh = RuleSet(rules.bits, rules.vocabulary, rules.max_objects, rules.rules, rules.n_rules_before_generalization)
    took = time.perf_counter() - t
    return took, {k: fresh.dense_groups[k] for k in sorted(fresh.dense_groups)}, [None] * len(fresh.dense_groups)


def same_arrays(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(
        all(x.dtype == y.dtype and np.array_equal(x, y) for x, y in zip(a[k], b[k])) for k in a)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, help="run directory with pddl/rules.json and pddl/outcomes.json")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    from pddl_export.outcome_rules import load_outcomes
    from pddl_export.rules_io import load_rules
    from symlearn.provenance import atomic_write_json, bench_context

    rows = {}
    for name, load in (("rules", load_rules), ("outcomes", load_outcomes)):
        t = time.perf_counter()
        loaded, model_hash = load(Path(args.run))
        load_s = time.perf_counter() - t
        rules = loaded if name == "rules" else loaded.rules
        new_s, new_dense, new_verdicts = ruleset_step(rules)
        base_s, base_dense, base_verdicts = groups_step(rules, baseline_dense_group, baseline_first_overlap)
        if not same_arrays(new_dense, base_dense) or new_verdicts != base_verdicts:
            raise SystemExit(f"rules_load: {name}: the baseline's arrays or verdicts differ")
        sizes = [len(rules.rules_for(*k)) for k in rules.dense_groups]
        rows[name] = {"n_rules": rules.n_rules, "n_groups": len(sizes), "largest_group": max(sizes, default=0),
                      "context_codes_per_rule": round(float(np.mean([len(r.bounds()) for r in rules.rules])), 2),
                      "load_s": round(load_s, 2), "groups_s": round(new_s, 2), "baseline_groups_s": round(base_s, 2),
                      "groups_speedup": round(base_s / new_s, 1), "model_hash": model_hash}
        print(name, json.dumps(rows[name]))
    atomic_write_json(args.out, {"run": args.run, "rows": rows, **bench_context()})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
