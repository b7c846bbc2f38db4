"""Whole-call planning time of a learned-net A* and the other planners where search is hard.

On problems of 4-5 objects and reference plans of 5 or more actions (or, with --by shortest, shortest plans
of that length), every planner plans from the same start and goal codes (each problem's scenes are encoded
once in the simulator), and the whole planner call is timed: writing the task, starting the process,
searching and reading the plan back. Reports per planner the median whole-call time (time-outs count as
their time), the number solved, the ratio baseline median / planner median (the baseline: --baseline, the
learned-net `astar` unless told) and the fastest other planner; and the same medians per cell of object
count x plan length, to show how each grows and where they cross. Without --problems, a small set is
generated into OUT's folder first.

    python bench/depth_speed.py --run pretrained/quick-authors12k --timeout 30 --out bench/results/depth_speed.json
    python bench/depth_speed.py --run runs/paper --problems problems/o4-l5,problems/o5-l7 --out depth.json
    python bench/depth_speed.py --run RUN --problems problems/test,problems/zeroshot --objects 1-8 --by shortest \
        --min-length 1 --baseline astar-outcomes --planners fast-downward-lifted --timeout 10 --out scale.json
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

OTHER_PLANNERS = ("fast-downward-lifted", "rules-outcomes", "rules-bfs")  # timed against the baseline unless told


def _range(text: str) -> tuple[int, int]:
    lo, _, hi = text.partition("-")
    return int(lo), int(hi or lo)


def plan_length(problem, by: str) -> int | None:
    """The length a problem is placed by: its reference (generator) plan's, or its shortest plan's (None: unknown)."""
    return problem.generator_length if by == "reference" else problem.optimal_length


def select(folders: list[Path], objects: tuple[int, int], min_length: int,
           by: str = "reference") -> list[tuple[str, object]]:
    """(label, problem) for the problems of the folders with objects[0]..objects[1] objects and a long plan."""
    from symlearn.problems.problem import load_problems

    out = []
    for d in folders:
        for _, p in load_problems(d):
            length = plan_length(p, by)
            if objects[0] <= p.k <= objects[1] and length is not None and length >= min_length:
                out.append((f"{d.name}/{p.name}" if len(folders) > 1 else p.name, p))
    return out


def time_planners(run: Path, problems: list, planners: list[str], timeout_s: float, budget_s: float) -> list[dict]:
    """One record per problem: each planner's status, whole-call time, plan length; stops at the time budget."""
    from symlearn.planning.execution import safe_plan
    from symlearn.planning.planners import make_planners
    from symlearn.symbolic.scenes import scene_codes, symbolic_goal
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    fns = make_planners(planners, run)
    encoder, transition = planning_models(run)  # the codes m(z) plans over: with its location bits, if any
    records, t0 = [], time.perf_counter()
    with TabletopSimulator() as sim:
        for label, problem in problems:
            if time.perf_counter() - t0 > budget_s:
                break
            goal = symbolic_goal(sim, encoder, problem)
            start = scene_codes(sim, encoder, problem.initial)
            rec = {"problem": label, "n_objects": problem.k, "reference_length": problem.generator_length,
                   "shortest_length": problem.optimal_length,
                   "start": [int(c) for c in start], "goal": list(goal.codes), "planners": {}}
            for name in planners:
                t = time.perf_counter()
                res = safe_plan(name, fns[name], transition, start, goal, timeout_s)
                took = time.perf_counter() - t
                rec["planners"][name] = {"status": res.status.value, "time_s": round(took, 4),
                                         "plan_length": len(res.plan) if res.found else None,
                                         "expansions": res.expansions}
            records.append(rec)
            print(f"{label} ({problem.k} objects, reference {problem.generator_length}): " + ", ".join(
                f"{n} {r['status']} {r['time_s']:.2f}s" for n, r in rec["planners"].items()), flush=True)
    return records


def _medians(records: list[dict], planners: list[str], baseline: str) -> dict:
    per = {}
    for name in planners:
        runs = [r["planners"][name] for r in records]
        solved = [x["time_s"] for x in runs if x["status"] == "solved"]
        per[name] = {"n": len(runs), "solved": len(solved),
                     "median_time_s": round(statistics.median(x["time_s"] for x in runs), 4) if runs else None,
                     "median_solved_time_s": round(statistics.median(solved), 4) if solved else None}
    base = per[baseline]["median_time_s"]
    for name, s in per.items():
        s["baseline_over_planner"] = round(base / s["median_time_s"], 3) if base and s["median_time_s"] else None
    return per


LENGTH_CELLS = ((1, 2), (3, 4), (5, 6), (7, 8), (9, 12))


def summarize(records: list[dict], planners: list[str], baseline: str = "astar", by: str = "reference") -> dict:
    """Per planner: median whole-call time, solved count, median over solved calls; ratios to the baseline; the
    fastest other planner; the same medians per cell of object count x plan length (`by_cell`)."""
    per = _medians(records, planners, baseline)
    others = [n for n in planners if n != baseline and per[n]["median_time_s"] is not None]
    fastest = min(others, key=lambda n: (per[n]["median_time_s"], -per[n]["solved"])) if others else None
    key = "reference_length" if by == "reference" else "shortest_length"
    cells = {}
    for k in sorted({r["n_objects"] for r in records}):
        for lo, hi in LENGTH_CELLS:
            rows = [r for r in records if r["n_objects"] == k and r[key] is not None and lo <= r[key] <= hi]
            if rows:
                cells[f"k{k} {lo}-{hi}"] = _medians(rows, planners, baseline)
    return {"baseline": baseline, "planners": per, "fastest_other_planner": fastest, "by_cell": cells}


def main() -> None:
    from symlearn.provenance import atomic_write_json, bench_context

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True, help="run with best.pt, transition.pt and pddl/rules.json")
    ap.add_argument("--problems", help="comma-separated problem folders (default: generate a set beside --out)")
    ap.add_argument("--planners", default=",".join(OTHER_PLANNERS), help="planners timed against the baseline")
    ap.add_argument("--baseline", default="astar", help="the planner the others are compared with (default astar)")
    ap.add_argument("--by", choices=("reference", "shortest"), default="reference",
                    help="place problems by their reference plan's length or their shortest plan's")
    ap.add_argument("--objects", type=_range, default=(4, 5), help="objects per problem, e.g. 4-5")
    ap.add_argument("--length", type=_range, default=(5, 8), help="reference lengths generated, e.g. 5-8")
    ap.add_argument("--min-length", type=int, default=5, help="shortest reference length kept")
    ap.add_argument("--n", type=int, default=10, help="problems generated when --problems is not given")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds per planner call")
    ap.add_argument("--budget", type=float, default=float("inf"), help="start no new problem after this many seconds")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import torch

    torch.set_num_threads(1)
    planners = [args.baseline] + [p for p in args.planners.split(",") if p and p != args.baseline]
    if args.problems:
        folders = [Path(p) for p in args.problems.split(",") if p]
    else:
        from symlearn.problems.problem_generation import generate_problems

        folders = [args.out.parent / f"{args.out.stem}_problems"]
        generate_problems(folders[0], args.n, objects=args.objects, length=args.length, seed=args.seed)
    problems = select(folders, args.objects, args.min_length, args.by)
    if not problems:
        raise SystemExit(f"no problem of {args.objects[0]}-{args.objects[1]} objects and {args.by} length "
                         f">= {args.min_length} in {', '.join(map(str, folders))}")
    t0 = time.perf_counter()
    records = time_planners(args.run, problems, planners, args.timeout, args.budget)
    result = {"run": str(args.run), "problems": [str(d) for d in folders], "n_selected": len(problems),
              "n_timed": len(records), "objects": list(args.objects), "min_length": args.min_length,
              "by": args.by, "timeout_s": args.timeout, "torch_threads": 1,
              "wall_time_s": round(time.perf_counter() - t0, 1), **bench_context(),
              **summarize(records, planners, args.baseline, args.by), "records": records}
    atomic_write_json(args.out, result)
    for title, per in [("all", result["planners"])] + list(result["by_cell"].items()):
        print(f"\n{title}\n{'planner':<32}{'solved':>8}{'median s':>10}{'solved med s':>14}{'base/planner':>14}")
        for name, s in per.items():
            cells = [f"{s['solved']}/{s['n']}", s["median_time_s"], s["median_solved_time_s"],
                     s["baseline_over_planner"]]
            print(f"{name:<32}{cells[0]:>8}" + "".join(f"{'-' if v is None else f'{v:.3f}':>{w}}"
                                                      for v, w in zip(cells[1:], (10, 14, 14))))
    print(f"fastest planner against {args.baseline}: {result['fastest_other_planner']}\nwrote {args.out}")


if __name__ == "__main__":
    main()
