"""Success on goals the table locations can name, and on the rest, for benchmark results already written.

`symlearn benchmark` now reports this split itself ("goal_placement"); this script adds it to result files
written before it, from the problem files: a goal is "off the locations" when it puts a judged object more
than 5 cm (xy) from every table location (Problem.goal_off_locations), as a random walk can leave a stick
across two places or an object pushed aside. For each grid and planner: problems, open and closed-loop
success and closed-loop failure causes, by 1-3 and 4-5 objects. Writes JSON.

    python bench/goal_placement.py --problems problems/depth \
        --grids bench/results/depth_grid_quick_stab_astar.json,bench/results/depth_grid_stab_likely.json \
        --out bench/results/goal_placement_depth.json
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path


EMPTY = {"n_problems": 0, "success_rate": None, "success_rate_closed_loop": None, "closed_loop_failure_causes": {}}


def split(rows: list[dict], off: dict[str, int]) -> dict:
    """planner -> objects group -> "on_locations"/"off_locations" -> n, success open / closed, failure causes.

    Each group is summarised by the benchmark's own summary_goal_placement; a part without problems is EMPTY.
    """
    import dataclasses

    from symlearn.planning.benchmark import summary_goal_placement
    from symlearn.planning.execution import ProblemRun

    runs = [dataclasses.replace(ProblemRun(**r), goal_off_locations=off[r["problem"]]) for r in rows]
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in runs):
        for group, ks in (("1-3 objects", (1, 2, 3)), ("4-5 objects", (4, 5))):
            parts = summary_goal_placement([r for r in runs if r.planner == planner and r.n_objects in ks])
            out.setdefault(planner, {})[group] = {name: parts.get(planner, {}).get(name, EMPTY)
                                                  for name in ("on_locations", "off_locations")}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", type=Path, required=True,
                    help="folder whose subfolders are the problem sets the grids name (e.g. problems/depth)")
    ap.add_argument("--grids", required=True, help="comma-separated benchmark result JSON files")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    from pddl_export.files import atomic_write_json
    from symlearn.planning.problem import ON_LOCATION_M, load_problems
    from symlearn.provenance import bench_context

    off = {}
    for folder in sorted(p for p in args.problems.iterdir() if p.is_dir()):
        for _, pr in load_problems(folder):
            off[f"{folder.name}/{pr.name}"] = pr.goal_off_locations
    grids = {}
    for path in args.grids.split(","):
        rows = json.loads(Path(path).read_text())["rows"]
        missing = sorted({r["problem"] for r in rows} - set(off))
        if missing:
            raise SystemExit(f"{path}: problem {missing[0]} is not under {args.problems}")
        grids[path] = split(rows, off)
        for planner, groups in grids[path].items():
            for group, parts in groups.items():
                cells = [f"{k} {c['success_rate']}/{c['success_rate_closed_loop']} ({c['n_problems']})"
                         for k, c in parts.items()]
                print(f"{Path(path).name} {planner} {group}: " + "; ".join(cells))
    n_off = sum(v > 0 for v in off.values())
    atomic_write_json(args.out, {"problems": str(args.problems), "on_location_m": ON_LOCATION_M,
                                 "n_problems": len(off), "n_goals_off_locations": n_off, "grids": grids,
                                 **bench_context()})
    print(f"{n_off} of {len(off)} goals put an object off the locations; wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
