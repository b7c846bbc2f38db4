"""Write the PDDL domain of a trained run, without any training.

    python examples/generate_domain.py --run runs/quick --data data/paper [--out runs/quick/pddl]

Needs a run with best.pt (symlearn train) and transition.pt (symlearn train-transition).
"""
import argparse
from pathlib import Path

from symlearn.planning.export import ExportConfig, export_pddl


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--out")
    ap.add_argument("--pddl-fidelity-cases", type=int, default=200)
    args = ap.parse_args()
    report = export_pddl(Path(args.run), Path(args.data), ExportConfig(pddl_fidelity_cases=args.pddl_fidelity_cases),
                         Path(args.out) if args.out else None)
    out = Path(args.out) if args.out else Path(args.run) / "pddl"
    print((out / "domain.pddl").read_text()[:1500])
    print(f"... {report['n_rules']} rules over {report['vocabulary_size']} codes, fidelity {report['fidelity']}, "
          f"through the PDDL {report['pddl_fidelity']} ({report['pddl_fidelity_cases']} cases); wrote {out}")


if __name__ == "__main__":
    main()
