"""Solve one problem with every available planner on the exported domain and print the plans.

    python examples/call_planners.py --run runs/quick --problem problems/p100/problem_0000.json

Codes come from the run's encoder (initial scene and goal scene); planners are the learned-net
A* and the classical planners on RUN/pddl (run examples/generate_domain.py first).
"""
import argparse
from pathlib import Path

from pddl_export.symbolic import SymbolicGoal, code_str
from symlearn.learning.checkpoint import load_effect_model
from symlearn.planning.execution import safe_plan
from symlearn.planning.lifted_export import LIFTED_FILE
from symlearn.planning.planners import PLANNERS, make_planners
from symlearn.planning.problem import load_problem
from symlearn.planning.scenes import goal_codes, place_scene
from symlearn.sim.simulator import TabletopSimulator
from symlearn.symbolic.learned_transition import LearnedTransition
from symlearn.symbolic.transition_data import encode_observation
from symlearn.world import decode_action


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--problem", required=True)
    ap.add_argument("--timeout", type=float, default=30.0)
    args = ap.parse_args()
    run = Path(args.run)
    names = list(PLANNERS)
    if not (run / "pddl" / LIFTED_FILE).is_file():  # the lifted domain needs an m(z) on 9 location bits
        names = [n for n in names if not PLANNERS[n].needs_lifted]
        print(f"no {run / 'pddl' / LIFTED_FILE}: the planners on the lifted domain are left out "
              f"(symlearn export-pddl --lifted writes it)")
    planners = make_planners(names, run)
    encoder, _ = load_effect_model(run)
    transition = LearnedTransition.from_run(run)
    problem = load_problem(Path(args.problem))
    with TabletopSimulator() as sim:
        goal = goal_codes(sim, encoder, problem)
        place_scene(sim, problem.initial)
        start = encode_observation(encoder, sim.observe())
    bits = transition.bits
    print(f"{problem.name}: start {[code_str(c, bits) for c in start]} -> goal {[code_str(c, bits) for c in goal]}")
    for name, fn in planners.items():
        res = safe_plan(name, fn, transition, start, SymbolicGoal(tuple(int(c) for c in goal)), args.timeout)
        steps = ", ".join(f"pick {decode_action(a).pick} release {decode_action(a).release}" for a in res.plan)
        print(f"{name:>18}: {res.status.value:<10} {res.planning_time_s:7.3f} s  [{steps}] {res.message[:80]}")


if __name__ == "__main__":
    main()
