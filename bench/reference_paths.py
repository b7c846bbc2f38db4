"""Failed benchmark goals replayed: does the generator's own route reach them, and how sure is m(z) of it?

For every problem a benchmark JSON marks failed (closed loop), the initial scene is built and the
problem's generating actions are executed in the simulator, encoding the scene after each. Per problem it
records whether that replay ends within tolerance of the goal (the simulator is deterministic, so it
should), whether its final codes equal the goal's codes, m(z)'s -log P of each observed step (under its
bit probabilities) and whether m(z)'s likeliest prediction was right at each step. A route m(z) is sure of
that A* did not take points at the search; a route with one unlikely step, at the model. Writes JSON.

    python bench/reference_paths.py --run RUN --benchmark GRID.json --problems problems/depth \
        --out bench/results/reference_paths.json
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path


def replay(sim, reader, transition, problem) -> dict:
    """Execute the problem's own actions; m(z)'s view of each observed step."""
    import numpy as np

    from pddl_export.symbolic import bits_from_codes
    from symlearn.planning.scenes import max_goal_distance, place_scene, symbolic_goal
    from symlearn.symbolic.transition_data import encode_observation
    from symlearn.world import decode_action

    goal = symbolic_goal(sim, reader, problem)
    place_scene(sim, problem.initial)
    codes = np.asarray(encode_observation(reader, sim.observe()), np.int64)
    nll, right = [], []
    for a in problem.actions:
        probs = transition.bit_probabilities(codes[None], np.int64([a]))[0]
        predicted = transition(codes[None], np.int64([a]))[0]
        sim.step(decode_action(int(a)))
        nxt = np.asarray(encode_observation(reader, sim.observe()), np.int64)
        bits = bits_from_codes(nxt, transition.bits)
        nll.append(float(-np.log(np.clip(np.where(bits > 0.5, probs, 1 - probs), 1e-12, 1)).sum()))
        right.append(bool((predicted == nxt).all()))
        codes = nxt
    return {"n_objects": problem.k, "goal_off_locations": problem.goal_off_locations,
            "distance_m": round(float(max_goal_distance(sim.get_scene(), problem.goal, problem.free)), 5),
            "codes_reach_goal": all(g is None or g == int(c) for g, c in zip(goal.codes, codes)),
            "step_nll": [round(x, 3) for x in nll], "path_nll": round(sum(nll), 3), "steps_right": right}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True)
    ap.add_argument("--benchmark", type=Path, required=True, help="a `symlearn benchmark` JSON with closed-loop rows")
    ap.add_argument("--problems", type=Path, default=Path("problems/depth"),
                    help="the folder the benchmark's problem labels are relative to")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()

    import torch

    from symlearn.planning.problem import load_problem
    from symlearn.provenance import atomic_write_json
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    torch.set_num_threads(1)
    grid = json.loads(args.benchmark.read_text())
    failed = sorted({r["problem"] for r in grid["rows"] if r["closed_loop"] and not r["success"]})
    reader, transition = planning_models(args.run)
    rows = {}
    with TabletopSimulator() as sim:
        for label in failed:
            rows[label] = replay(sim, reader, transition, load_problem(args.problems / f"{label}.json"))
    n = len(rows)
    summary = {"failed": n,
               "replay_within_tolerance": sum(r["distance_m"] <= 0.02 for r in rows.values()),
               "replay_codes_reach_goal": sum(r["codes_reach_goal"] for r in rows.values()),
               "path_nll_at_most_13": sum(r["path_nll"] <= 13 for r in rows.values()),
               "every_step_predicted": sum(all(r["steps_right"]) for r in rows.values())}
    atomic_write_json(args.out, {"run": str(args.run), "benchmark": str(args.benchmark), "summary": summary,
                                 "problems": rows})
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
