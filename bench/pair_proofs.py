"""Which open problems the pair projections of the rules prove unreachable (search.rule_abstraction).

Reads the start and goal codes a bench/rules_finish.py (or depth_speed.py) result recorded per problem and, for
every call of --planner that did not finish (timeout or node limit), asks pair_unreachable for a proof; also
times it on the calls that did finish, and checks it never contradicts one that found a plan.

    python bench/pair_proofs.py --run pretrained/quick-authors12k --records bench/results/rules_finish_bfs_quick12k.json \\
        --out bench/results/pair_proofs_quick12k.json
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    from pddl_export.rules_io import load_rules
    from pddl_export.symbolic import SymbolicGoal
    from search.rule_abstraction import pair_unreachable
    from symlearn.provenance import atomic_write_json, bench_context

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True, help="run whose pddl/rules.json the records were planned on")
    ap.add_argument("--records", type=Path, required=True, help="a rules_finish.py / depth_speed.py result JSON")
    ap.add_argument("--planner", default="rules-bfs")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    rules = load_rules(args.run)[0]
    records = json.loads(args.records.read_text())["records"]
    rows = []
    for r in records:
        status = r["planners"][args.planner]["status"]
        t = time.perf_counter()
        proof = pair_unreachable(rules, r["start"], SymbolicGoal(tuple(r["goal"])))
        took = time.perf_counter() - t
        if proof is not None and status == "solved":
            print(f"error: pair proof {proof} contradicts a plan found for {r['problem']}", file=sys.stderr)
            return 1
        rows.append({"problem": r["problem"], "n_objects": r["n_objects"], "status": status,
                     "pair_proof": list(proof) if proof else None, "time_s": round(took, 4)})
    open_rows = [x for x in rows if x["status"] not in ("solved", "unsolvable")]
    summary = {"open_calls": len(open_rows), "proved_open": sum(x["pair_proof"] is not None for x in open_rows),
               "proved_of_unsolvable": sum(x["pair_proof"] is not None for x in rows if x["status"] == "unsolvable"),
               "unsolvable": sum(x["status"] == "unsolvable" for x in rows),
               "slowest_s": max((x["time_s"] for x in rows), default=0.0)}
    atomic_write_json(args.out, {"run": str(args.run), "records": str(args.records), "planner": args.planner,
                                 **bench_context(), "summary": summary, "rows": rows})
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
