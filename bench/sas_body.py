"""Time writing the SAS+ task body (variables, operators, axioms) for n objects from a run's exported rules.

The body is what `fast-downward-sas` and the other SAS+ planners write once per object count, inside the first
call's time limit. Its cost is the context terms of each rule over the n - 1 other objects, and those start
from the assignments of the others that meet the rule's bounds. The baseline tries every assignment,
(m + 1)^(n - 1) for a rule on m codes; `satisfying_cells` builds only those that can meet the bounds. Both are
timed in one process on the same rules, and their bodies must be identical. Writes JSON.

    python bench/sas_body.py --run RUN --objects 2,3,4 --baseline-max-objects 4 --out bench/results/sas_body.json
"""
from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import time
from contextlib import contextmanager
from pathlib import Path


def brute_force_cells(intervals: tuple[tuple[int, int], ...], k: int) -> list[tuple[int, ...]]:
    """Every assignment of k others to m + 1 categories, kept where the bounds hold (the baseline)."""
    m = len(intervals)
    return sorted(c for c in itertools.product(range(m + 1), repeat=k)
                  if all(lo <= c.count(j) < hi for j, (lo, hi) in enumerate(intervals)))


@contextmanager
def cells_function(fn):
    """Make pddl_export.sas_writer enumerate cells with fn, with an empty term cache, for the block."""
    import pddl_export.sas_writer as sw

    saved = sw.satisfying_cells
    sw.satisfying_cells = fn
    sw.context_terms.cache_clear()
    try:
        yield
    finally:
        sw.satisfying_cells = saved
        sw.context_terms.cache_clear()


def time_body(rules, n: int) -> dict:
    """Seconds to write the body for n objects, its size and a digest of its text."""
    from pddl_export.sas_writer import SASEncoder

    t = time.perf_counter()
    body = SASEncoder(rules)._body(n)
    s = time.perf_counter() - t
    digest = hashlib.sha256((body.variables + body.operators + body.axioms).encode()).hexdigest()[:16]
    return {"seconds": round(s, 3), "n_effects": body.n_effects, "n_axioms": body.n_axioms,
            "megabytes": round(len(body.operators) / 1e6, 2), "sha256": digest}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, help="run directory with pddl/rules.json")
    ap.add_argument("--objects", default="2,3,4", help="object counts, comma-separated")
    ap.add_argument("--baseline-max-objects", type=int, default=4, help="largest count the baseline is timed on")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import pddl_export.sas_writer as sw
    from pddl_export.rules_io import load_rules
    from symlearn.provenance import atomic_write_json, bench_context

    rules, model_hash = load_rules(Path(args.run))
    rows = []
    for n in (int(x) for x in args.objects.split(",")):
        with cells_function(sw.satisfying_cells):
            pruned = time_body(rules, n)
        row = {"n_objects": n, "pruned": pruned}
        if n <= args.baseline_max_objects:
            with cells_function(brute_force_cells):
                base = time_body(rules, n)
            if base["sha256"] != pruned["sha256"]:
                raise SystemExit(f"sas_body: the bodies for {n} objects differ ({base['sha256']} against "
                                 f"{pruned['sha256']})")
            row.update(baseline=base, speedup=round(base["seconds"] / pruned["seconds"], 1))
        rows.append(row)
        print(json.dumps(row))
    out = {"run": args.run, "model_hash": model_hash, "bits": rules.bits, "vocabulary_size": len(rules.vocabulary),
           "n_rules": len(rules.rules), "rows": rows, **bench_context()}
    atomic_write_json(args.out, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
