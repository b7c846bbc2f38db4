"""Planning time of every planner in a `symlearn benchmark` JSON, by scene size, as ratios to the A*.

Reads the rows that `symlearn benchmark` wrote (every planner ran on the same problems in the
same process, so the learned-net A* of that run is the baseline) and reports per planner and
per number of objects: success, median planning time, the ratio of that median to the A*'s,
and the medians of the parts the planner reports (SAS+/PDDL writing, the planner process,
the planner's own total and search times). `--floor` also times the Fast Downward binary on a
one-variable task: the cost of starting and ending the process, which no call can go below.

    python bench/planners.py --benchmark runs/quick32/bench_sas.json --floor --out bench/results/planners_sas.json
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from search.sas_planners import search_binary
from symlearn.provenance import atomic_write_json, bench_context

PARTS = ("sas_write_time_s", "pddl_write_time_s", "planner_time_s", "fd_total_time_s", "fd_search_time_s")
TINY_SAS = "\n".join(["begin_version", "3", "end_version", "begin_metric", "0", "end_metric", "1",
                      "begin_variable", "v0", "-1", "2", "Atom a", "Atom b", "end_variable", "0",
                      "begin_state", "0", "end_state", "begin_goal", "1", "0 1", "end_goal", "1",
                      "begin_operator", "go", "0", "1", "0 0 -1 1", "1", "end_operator", "0", ""])


def _median(xs: list[float]) -> float | None:
    return statistics.median(xs) if xs else None


def summarize(bench: dict) -> dict:
    """planner -> {"all" | "1" | "2" | ...: success, median time, ratio to A*, median parts}."""
    rows = bench["rows"]
    sizes = sorted({r["n_objects"] for r in rows})
    base = {str(n): _median([r["planning_time_s"] for r in rows if r["planner"] == "astar" and r["n_objects"] == n])
            for n in sizes}
    base["all"] = _median([r["planning_time_s"] for r in rows if r["planner"] == "astar"])
    out: dict = {}
    for planner in bench["planners"]:
        mine = [r for r in rows if r["planner"] == planner]
        groups = {"all": mine, **{str(n): [r for r in mine if r["n_objects"] == n] for n in sizes}}
        out[planner] = {}
        for key, rs in groups.items():
            med = _median([r["planning_time_s"] for r in rs])
            entry = {"n": len(rs), "success": sum(r["success"] for r in rs) / max(len(rs), 1),
                     "median_time_s": med,
                     "ratio_to_astar": med / base[key] if med is not None and base.get(key) else None}
            for part in PARTS:
                vals = [r["timings"][part] for r in rs if r.get("timings", {}).get(part) is not None]
                if vals:
                    entry[f"median_{part}"] = _median(vals)
            if entry.get("median_fd_search_time_s") is not None and base.get(key):
                entry["search_time_ratio_to_astar"] = entry["median_fd_search_time_s"] / base[key]
            out[planner][key] = entry
    return out


def process_floor(repeats: int) -> dict:
    """Wall time of the Fast Downward binary on a one-variable task, and the time it reports itself."""
    binary = search_binary("up_fast_downward")
    if binary is None:
        return {"error": "up-fast-downward is not installed"}
    walls, own = [], []
    with tempfile.TemporaryDirectory() as tmp:
        task = Path(tmp) / "tiny.sas"
        task.write_text(TINY_SAS)
        for _ in range(repeats):
            t = time.perf_counter()
            with open(task) as f:
                proc = subprocess.run([str(binary), "--search", "astar(blind())", "--internal-plan-file",
                                       str(Path(tmp) / "plan")], stdin=f, capture_output=True, text=True,
                                      timeout=60, check=True)
            walls.append(time.perf_counter() - t)
            own.append(float(re.findall(r"Total time: ([0-9.eE+-]+)s", proc.stdout)[-1]))
    return {"repeats": repeats, "median_wall_s": _median(walls), "median_fd_total_s": _median(own)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--benchmark", type=Path, required=True, help="JSON written by symlearn benchmark")
    ap.add_argument("--floor", action="store_true", help="also time the Fast Downward binary on a trivial task")
    ap.add_argument("--repeats", type=int, default=30)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    bench = json.loads(args.benchmark.read_text())
    if "rows" not in bench or "planners" not in bench:
        raise SystemExit(f"{args.benchmark} is not a symlearn benchmark JSON (no rows/planners)")
    result = {"benchmark": str(args.benchmark), "problems": bench.get("problems"), "closed_loop": bench.get("closed_loop"),
              **bench_context(), "planners": summarize(bench)}
    if args.floor:
        result["process_floor"] = process_floor(args.repeats)
    atomic_write_json(args.out, result)
    for planner, groups in result["planners"].items():
        cells = [f"{k}: {g['success']:.2f} / {1000 * g['median_time_s']:.1f} ms" + (
            f" ({g['ratio_to_astar']:.1f}x A*)" if g["ratio_to_astar"] else "") for k, g in groups.items()]
        print(f"{planner:22s} " + "; ".join(cells))
    if args.floor:
        f = result["process_floor"]
        print(f"Fast Downward on a one-variable task: {f}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
