"""What the symbol-aliasing failures of benchmark runs miss by, and where their goals stand.

A failure counts as aliasing when the final codes meet the goal's codes and the poses do not (2 cm tolerance).
Per benchmark JSON and planner this lists each closed-loop aliasing failure: how far the farthest object ended
from its goal, and for each goal object its nearest table location, how far from it, and its place (the 3-bit
field of `--location-bits 9`: on, -y/+y near/mid/far, x). Misses within the place's band (a stick 14 or 16 cm
off, both "far") are what a finer code would have to name. Reads JSON only; writes JSON.

With `--replay-run RUN` (the run the benchmarks planned with) each aliasing failure is planned and executed again
in the simulator, closed loop, with the benchmark's planner, time limit and replans, and each judged object's end
is compared with its goal: dx, dy and dz in cm, so a miss along x inside a y band (which no place field names) is
told from one along y. A replay is one more run, not the recorded one: its own outcome is reported beside it.

    python bench/aliasing_misses.py --benchmarks A.json B.json --problems problems/depth \
        --out bench/results/aliasing_misses.json [--replay-run RUN]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

MISS_BINS_M = (0.025, 0.05)  # misses up to 2.5 cm (just over tolerance), 2.5-5 cm, over 5 cm


def goal_places(problem: dict) -> list[dict]:
    """Each goal object's type, nearest location, distance to it and 9-bit place label."""
    from pddl_export.symbolic import codes_from_bits
    from symlearn.symbolic.locations import OFF_PLACES, location_bits
    from symlearn.world import LOCATIONS

    objects = problem["goal"]["objects"]
    xy = np.float32([o["position"][:2] for o in objects])
    bits = location_bits(xy, 6)  # nearest location and place: the first 6 of the 9 bits
    nearest_of, place_of = codes_from_bits(bits[:, :3]).tolist(), codes_from_bits(bits[:, 3:]).tolist()
    out = []
    for o, nearest, place, p in zip(objects, nearest_of, place_of, xy):
        out.append({"type": o["type"], "nearest_location": nearest, "place": OFF_PLACES[place],
                    "distance_m": round(float(np.linalg.norm(p - np.float32(LOCATIONS[nearest]))), 4)})
    return out


def object_offsets(final: np.ndarray, goal: np.ndarray, judged: list[bool]) -> list[dict | None]:
    """Per object: its end minus its goal position in x, y and z (cm), the miss (as the benchmark's distance) and
    the axis that carries most of it; None for an object the goal does not judge."""
    out = []
    for delta, ok in zip((np.asarray(final, np.float64) - np.asarray(goal, np.float64)) * 100, judged):
        out.append({"dx_cm": round(float(delta[0]), 2), "dy_cm": round(float(delta[1]), 2),
                    "dz_cm": round(float(delta[2]), 2), "miss_cm": round(float(np.linalg.norm(delta)), 2),
                    "axis": "xyz"[int(np.argmax(np.abs(delta)))]} if ok else None)
    return out


def replay(run: Path, bench: dict, planner: str, names: list[str], problems_root: Path) -> dict:
    """problem -> the replay's success, symbolic match, cause and each object's offsets (closed loop, as `bench`)."""
    import torch

    from symlearn.planning.execution import ExecutionConfig, run_problem
    from symlearn.planning.planners import make_planners
    from symlearn.planning.problem import load_problem
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE
    from symlearn.provenance import sha256_file

    have = sha256_file(run / TRANSITION_FILE)[:16]
    if have != bench.get("transition_sha256"):
        raise SystemExit(f"aliasing_misses: {run / TRANSITION_FILE} ({have}) is not the transition model the "
                         f"benchmark planned with ({bench.get('transition_sha256')}); replay with that run")
    torch.set_num_threads(1)
    fn = make_planners([planner], run, risk_weight=float(bench.get("risk_weight", 1.0)))[planner]
    encoder, transition = planning_models(run)
    config = ExecutionConfig(closed_loop=True, timeout_s=float(bench["timeout_s"]),
                             max_replans=int(bench["max_replans"]))
    out = {}
    with TabletopSimulator() as sim:
        for name in names:
            problem = load_problem(problems_root / f"{name}.json")
            row = run_problem(sim, encoder, transition, problem, planner, fn, config)
            final = np.float64([o.position for o in sim.get_scene().objects])
            goal = np.float64([o.position for o in problem.goal.objects])
            judged = [i not in problem.free for i in range(len(goal))]
            out[name] = {"success": row.success, "symbolic_match": row.symbolic_match, "cause": row.failure_cause,
                         "max_distance_m": row.max_distance_m, "objects": object_offsets(final, goal, judged)}
    return out


def summarize(bench: dict, problems_root: Path) -> dict:
    """planner -> failures, aliasing failures, their share, misses by bin and the rows (closed loop)."""
    out = {}
    for planner in bench["planners"]:
        rows = [r for r in bench["rows"] if r["planner"] == planner and r["closed_loop"]]
        failed = [r for r in rows if not r["success"]]
        aliased = [r for r in failed if r.get("failure_cause") == "symbol_aliasing"]
        misses = np.float64([r["max_distance_m"] for r in aliased])
        edges = np.searchsorted(np.float64(MISS_BINS_M), misses, side="right")
        detail = []
        for r in aliased:
            problem = json.loads((problems_root / f"{r['problem']}.json").read_text())
            detail.append({"problem": r["problem"], "n_objects": r["n_objects"], "miss_m": r["max_distance_m"],
                           "goal_off_locations": r["goal_off_locations"], "goal": goal_places(problem)})
        out[planner] = {"n_problems": len(rows), "n_failures": len(failed), "n_aliasing": len(aliased),
                        "aliasing_share": round(len(aliased) / len(failed), 4) if failed else None,
                        "misses_by_bin": {label: int((edges == i).sum()) for i, label in
                                          enumerate(("up to 2.5 cm", "2.5-5 cm", "over 5 cm"))},
                        "rows": detail}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--benchmarks", nargs="+", required=True, help="benchmark JSON files (symlearn benchmark --out)")
    ap.add_argument("--problems", default="problems/depth", help="the folder the rows' problem names are under")
    ap.add_argument("--replay-run", help="run directory the benchmarks planned with: replay each aliasing failure")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    from symlearn.provenance import atomic_write_json, bench_context

    root = Path(args.problems)
    result = {"problems": str(root), "benchmarks": {}, "replay_run": args.replay_run}
    for path in args.benchmarks:
        try:
            bench = json.loads(Path(path).read_text())
            result["benchmarks"][path] = summarize(bench, root)
        except (OSError, ValueError, KeyError) as e:
            raise SystemExit(f"aliasing_misses: cannot read benchmark {path}: {type(e).__name__}: {e}") from None
        if args.replay_run:
            for planner, summary in result["benchmarks"][path].items():
                again = replay(Path(args.replay_run), bench, planner, [r["problem"] for r in summary["rows"]], root)
                for r in summary["rows"]:
                    r["replay"] = again[r["problem"]]
                    print(f"{path}: {planner}: {r['problem']} replayed: {r['replay']}")
    for path, per in result["benchmarks"].items():
        for planner, s in per.items():
            print(f"{path}: {planner}: {s['n_aliasing']} of {s['n_failures']} failures aliasing, "
                  f"misses {s['misses_by_bin']}")
    atomic_write_json(args.out, {**result, **bench_context()})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
