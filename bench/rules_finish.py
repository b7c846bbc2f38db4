"""Whether the rule-based planners finish (plan, or prove no plan exists for their rules) every problem in time.

Every problem of the given folders with at most --max-objects objects and a reference plan of at most
--max-length actions is encoded once in the simulator; each planner then gets one call of --timeout
seconds from the start codes to the goal codes. Reports per planner and object count how many calls
finished (solved or unsolvable), how many were solved, and the slowest finished call.

    python bench/rules_finish.py --run pretrained/quick-authors12k --problems problems/walks,problems/structures \\
        --planners rules-bfs,fast-downward-sas --timeout 60 --out bench/results/rules_finish.json
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from depth_speed import select, time_planners  # noqa: E402

FINISHED = ("solved", "unsolvable")


def summarize(records: list[dict], planners: list[str]) -> dict:
    """planner -> objects -> {n, finished, solved, slowest finished s}; and whether each planner finished all."""
    out = {}
    for name in planners:
        per_k: dict[str, dict] = {}
        for r in records:
            x = r["planners"][name]
            cell = per_k.setdefault(str(r["n_objects"]), {"n": 0, "finished": 0, "solved": 0, "slowest_finished_s": 0.0})
            cell["n"] += 1
            if x["status"] in FINISHED:
                cell["finished"] += 1
                cell["solved"] += x["status"] == "solved"
                cell["slowest_finished_s"] = max(cell["slowest_finished_s"], x["time_s"])
        out[name] = {"by_objects": dict(sorted(per_k.items())),
                     "finished_all": all(c["finished"] == c["n"] for c in per_k.values())}
    return out


def main() -> None:
    from symlearn.provenance import atomic_write_json, bench_context

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True, help="run with best.pt, transition.pt and pddl/rules.json")
    ap.add_argument("--problems", required=True, help="comma-separated problem folders")
    ap.add_argument("--planners", default="rules-bfs,fast-downward-sas", help="rule-based planners to time")
    ap.add_argument("--min-objects", type=int, default=1)
    ap.add_argument("--max-objects", type=int, default=5)
    ap.add_argument("--max-length", type=int, default=8, help="longest reference plan kept")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per planner call")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    planners = [p for p in args.planners.split(",") if p]
    folders = [Path(p) for p in args.problems.split(",") if p]
    problems = [(label, p) for label, p in select(folders, (args.min_objects, args.max_objects), 0)
                if p.generator_length <= args.max_length]
    t0 = time.perf_counter()
    records = time_planners(args.run, problems, planners, args.timeout, float("inf"))
    result = {"run": str(args.run), "problems": [str(d) for d in folders], "n": len(records),
              "min_objects": args.min_objects, "max_objects": args.max_objects, "max_length": args.max_length, "timeout_s": args.timeout,
              "wall_time_s": round(time.perf_counter() - t0, 1), **bench_context(),
              "planners": summarize(records, planners), "records": records}
    atomic_write_json(args.out, result)
    for name, s in result["planners"].items():
        print(f"{name}: finished every problem: {s['finished_all']}")
        for k, c in s["by_objects"].items():
            print(f"  {k} objects: {c['finished']}/{c['n']} finished ({c['solved']} solved), "
                  f"slowest finished {c['slowest_finished_s']:.2f} s")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
