"""Run every planner on a problem set, execute the plans in simulation, save a table and a plot.

    python examples/compare_planners.py --run runs/quick --problems problems/p100 --out runs/quick/compare
"""
import argparse
from pathlib import Path

from symlearn.planning.benchmark import benchmark, format_table
from symlearn.planning.planners import PLANNERS


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--problems", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--planners", default=",".join(n for n, s in PLANNERS.items() if not s.needs_lifted))
    ap.add_argument("--timeout", type=float, default=30.0)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    planners = args.planners.split(",")
    res = benchmark(Path(args.run), Path(args.problems), planners, out / "benchmark.json", closed_loop=False,
                    timeout_s=args.timeout, show_progress=False)
    table = format_table(res)
    (out / "table.txt").write_text(table + "\n")
    print(table)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(res["summary"])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.5))
    a1.bar(names, [res["summary"][n]["success_rate"] or 0 for n in names])
    a1.set_ylabel("success rate in simulation")
    a2.bar(names, [res["summary"][n]["median_time_s"] or 0 for n in names])
    a2.set_ylabel("median planning time (s)")
    a2.set_yscale("log")
    for ax in (a1, a2):
        ax.tick_params(axis="x", rotation=30)
    fig.tight_layout()
    fig.savefig(out / "comparison.png", dpi=100)
    print(f"wrote {out / 'table.txt'}, {out / 'comparison.png'} and {out / 'benchmark.json'}")


if __name__ == "__main__":
    main()
