"""The symbolic model against the simulator on whole problem sets: run every recorded shortest plan there.

For each problem with an `optimal_length`, its `optimal_plan` is executed in the simulator from the initial
scene; the check holds when every judged object ends within 2 cm of its goal position, and the plan is no
longer than the reference plan (when there is one). tests/test_shortest.py does the same on a few small
problems; this script covers sets (e.g. problems/dev) and writes the counts, the misses and the time as JSON.

    python experiments/shortest_check.py --problems problems/dev --out bench/results/shortest_check_dev.json
"""
from __future__ import annotations

import argparse
import collections
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    from symlearn.problems.problem import GOAL_TOLERANCE_M, load_problems, max_goal_distance
    from symlearn.provenance import atomic_write_json
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.world import decode_action

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", required=True, help="problem folders, comma-separated")
    ap.add_argument("--out", required=True, type=Path, help="JSON file for the counts and misses")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    checked, misses, longer, undecided = 0, [], [], collections.Counter()
    with TabletopSimulator() as sim:
        for folder in [Path(x) for x in args.problems.split(",") if x.strip()]:
            for path, p in load_problems(folder):
                if p.optimal_length is None:
                    undecided[p.optimal_reason or "not computed"] += 1
                    continue
                sim.reset(p.initial)
                for a in p.optimal_plan:
                    sim.step(decode_action(a))
                dist = max_goal_distance(sim.get_scene(), p.goal, p.free)
                checked += 1
                if dist > GOAL_TOLERANCE_M:
                    misses.append({"problem": str(path), "distance_m": round(dist, 4), "plan": list(p.optimal_plan)})
                if p.generator_length and p.optimal_length > p.generator_length:
                    longer.append(str(path))
    out = {"problems": args.problems, "checked": checked, "reached": checked - len(misses), "misses": misses,
           "longer_than_reference": longer, "undecided": dict(undecided),
           "wall_time_s": round(time.perf_counter() - t0, 1)}
    atomic_write_json(args.out, out)
    print(f"{checked} shortest plans run, {checked - len(misses)} reached their goals within 2 cm, "
          f"{len(longer)} longer than the reference; undecided {dict(undecided)}; wrote {args.out}")
    return 0 if not misses and not longer else 1


if __name__ == "__main__":
    raise SystemExit(main())
