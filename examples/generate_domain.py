"""Write a run's lifted PDDL domain and one problem file per problem, ready for any PDDL planner: no data, no training.

    python examples/generate_domain.py                      # pretrained/recommended -> ./lifted_domain
    python examples/generate_domain.py --run RUN --problems DIR --out OUT

The domain is the run's lifted rules (RUN/pddl/lifted.json, written by `symlearn export-pddl`) as typed
STRIPS schemas; each problem's start and goal are the run's codes of its scenes, rendered in the simulator. Then
e.g. `fast-downward.py --alias lama-first OUT/domain.pddl OUT/p01.pddl`.
"""
import argparse
import re
from pathlib import Path

from symlearn.export.lifted_export import COST_FORM_DIR, check_problem_folder, write_problem_folder
from symlearn.planning.run_folder import Run

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    try:
        write_and_show()
    except ValueError as e:  # a refusal (a bad --out, a lifted.json of another transition.pt): one line
        raise SystemExit(f"generate_domain.py: error: {e}") from None


def write_and_show() -> None:
    """Check --out and the run's lifted rules (those of its transition.pt, as `symlearn plan` checks them), then
    write the folder and say what it holds."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", default=str(ROOT / "pretrained" / "recommended"))
    ap.add_argument("--problems", help="problem folder (default RUN/problems)")
    ap.add_argument("--out", default="lifted_domain", help="folder to write (refused if it holds other files)")
    args = ap.parse_args()
    run, out = Path(args.run), Path(args.out)
    problems = Path(args.problems) if args.problems else run / "problems"
    check_problem_folder(out, "--out")  # before any work: a folder of other files is refused
    rules = Run(run).lifted()  # refused if exported from another transition.pt than the run's
    index = write_problem_folder(run, problems, out, rules=rules)
    domain = (out / "domain.pddl").read_text()
    print(f"domain {out / 'domain.pddl'}: {len(domain) / 1000:.0f} KB, {domain.count('(:action ')} typed STRIPS "
          f"schemas distilled from {rules.stats.get('moves')} observed moves, the same file for any number of objects")
    print("predicates: " + " ".join(sorted(set(re.findall(r"\((bit-\d+|no-bit-\d+|[a-z]+) \?", domain)))))
    costed = (out / COST_FORM_DIR / "domain.pddl").read_text()
    print(f"all-outcomes cost form {out / COST_FORM_DIR}/: {costed.count('(:action ')} schemas, one per outcome of a "
          f"rule, each costing by how often m(z) answered it (for a cost-aware planner, e.g. A* with LM-cut)")
    print(f"\n{'problem':<8} {'objects':>7} {'shortest plan':>13}  source")
    for name, p in index["problems"].items():
        print(f"{name:<8} {p['objects']:>7} {str(p['optimal_length']):>13}  {p['file']}")
    first = domain.index("\n  ; ") + 1  # the first schema's comment (how many moves it rests on)
    print("\nthe first rule:\n" + domain[first:domain.index("\n  ;", first + 1)])


if __name__ == "__main__":
    main()
