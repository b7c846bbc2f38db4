"""Run planners on a problem set, execute every plan in simulation (closed loop), and save a table and a plot.

    python examples/compare_planners.py                      # pretrained/recommended's problems -> ./compare
    python examples/compare_planners.py --run RUN --problems DIR --out OUT --planners P,Q [--timeout S]

By default: the learned-net searches and stock Fast Downward on the lifted domain, on the shipped run of the
recommended recipe and its four example problems (about a minute on 2 cores). The run is only read: OUT holds
everything written.
"""
import argparse
from pathlib import Path

from symlearn.planning.benchmark import benchmark
from symlearn.planning.benchmark_summary import format_table

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_PLANNERS = "astar-outcomes,astar,fast-downward-lifted,fast-downward-lifted-opt"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", default=str(ROOT / "pretrained" / "recommended"))
    ap.add_argument("--problems", help="problem folder (default RUN/problems)")
    ap.add_argument("--out", default="compare", help="output folder: benchmark.json, table.txt, plot")
    ap.add_argument("--planners", default=DEFAULT_PLANNERS)
    ap.add_argument("--timeout", type=float, default=10.0)
    args = ap.parse_args()
    run, out = Path(args.run), Path(args.out)
    problems = Path(args.problems) if args.problems else run / "problems"
    out.mkdir(parents=True, exist_ok=True)
    planners = args.planners.split(",")
    res = benchmark(run, problems, planners, out / "benchmark.json", closed_loop=True, timeout_s=args.timeout,
                    show_progress=False)
    table = format_table(res)
    (out / "table.txt").write_text(table + "\n")
    print(table)

    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(res["summary"])[::-1]  # the first planner on top
    s = res["summary"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 0.5 * len(names) + 1.2), sharey=True)
    a1.barh(names, [s[n].get("success_rate_closed_loop") or 0 for n in names], color="tab:green")
    a1.set_xlabel("success in simulation, closed loop")
    a1.set_xlim(0, 1)
    a2.barh(names, [s[n]["median_time_s"] or 0 for n in names], color="tab:blue")
    a2.set_xlabel("median planning time per call (s)")
    a2.set_xscale("log")
    a2.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())  # decades only: the minor labels overlap
    fig.tight_layout()
    fig.savefig(out / "comparison.png", dpi=100)
    print(f"wrote {out / 'table.txt'}, {out / 'comparison.png'} and {out / 'benchmark.json'}")


if __name__ == "__main__":
    main()
