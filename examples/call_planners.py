"""Solve one problem with every planner the run supports and print a table of the plans, without executing them.

    python examples/call_planners.py                         # pretrained/recommended, its tower_of_two problem
    python examples/call_planners.py --run RUN --problem FILE [--timeout S]

Start and goal codes come from the run's encoder on the problem's scenes (rendered in the simulator). The planners
are every registry planner whose inputs the run holds: the learned-net searches always, the planners on the exported
rules where RUN/pddl/rules.json exists, the stock Fast Downward ones where RUN/pddl/lifted.json does. Their task files
go to a temporary folder, not into the run.
"""
import argparse
import tempfile
from pathlib import Path

from pddl_export.symbolic import SymbolicGoal, code_str
from symlearn.planning.execution import safe_plan
from symlearn.planning.planners import PLANNERS, make_planners
from symlearn.planning.run_folder import Run
from symlearn.problems.problem import load_problem
from symlearn.symbolic.scenes import scene_codes, symbolic_goal
from symlearn.sim.simulator import TabletopSimulator
from symlearn.world import decode_action

ROOT = Path(__file__).resolve().parents[1]


def supported(run: Path) -> list[str]:
    """The planners whose inputs the run holds, in the registry's order (by family)."""
    has_rules, has_lifted = Run(run).rules_file.is_file(), Run(run).lifted_file.is_file()
    return [n for n in PLANNERS if (has_rules or not PLANNERS[n].needs_rules) and (has_lifted or not PLANNERS[n].needs_lifted)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", default=str(ROOT / "pretrained" / "recommended"))
    ap.add_argument("--problem", help="problem JSON file (default RUN/problems/tower_of_two.json)")
    ap.add_argument("--timeout", type=float, default=10.0)
    args = ap.parse_args()
    run = Path(args.run)
    problem = load_problem(Path(args.problem) if args.problem else run / "problems" / "tower_of_two.json")
    names = supported(run)
    reader, transition = Run(run).planning_models()
    with TabletopSimulator() as sim:
        goal = symbolic_goal(sim, reader, problem)
        start = scene_codes(sim, reader, problem.initial)
    bits = transition.bits
    print(f"{problem.name} ({problem.k} objects, shortest plan {problem.optimal_length}): start "
          f"{[code_str(c, bits) for c in start]}\n  goal {[code_str(c, bits) if c is not None else '*' for c in goal.codes]}")
    print(f"\n{'planner':<26} {'status':<9} {'time s':>7} {'length':>6}  plan (pick -> release)")
    with tempfile.TemporaryDirectory(prefix="call-planners-") as tmp:
        planners = make_planners(names, run, write_dir=Path(tmp))
        for name, fn in planners.items():
            res = safe_plan(name, fn, transition, start, goal, args.timeout)
            steps = ", ".join(f"{decode_action(a).pick}->{decode_action(a).release}" for a in res.plan)
            print(f"{name:<26} {res.status.value:<9} {res.planning_time_s:7.3f} {len(res.plan):>6}  {steps}")


if __name__ == "__main__":
    main()
