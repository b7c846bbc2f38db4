"""`symlearn report`: RUN/report.html (self-contained) and RUN/report.md from the run's own outputs; `symlearn
plots`: the figures and Markdown tables of saved benchmark results.

    symlearn report --run runs/paper [--data data/paper] [--benchmark runs/paper/benchmark.json]
    symlearn plots bench.json [more.json ...] --out plots/ [--merged all.json]
"""
from __future__ import annotations

import argparse
from pathlib import Path


def cmd_report(args: argparse.Namespace) -> int:
    from symlearn.report.build import build_report, write_report

    opt = lambda v: Path(v) if v else None  # noqa: E731
    rep = build_report(Path(args.run), opt(args.data), opt(args.benchmark), opt(args.recording))
    html_path, md_path = write_report(rep, Path(args.run))
    for s in rep.sections:
        print(f"{s.title}: {s.status}" + (f" ({s.note})" if s.note else ""))
    verdicts = [m.verdict for m in rep.marks()]
    print(f"against the paper: {verdicts.count('met')} met, {verdicts.count('not met')} not met, "
          f"{verdicts.count('not run')} not run")
    print(f"wrote {html_path} and {md_path}")
    return 0


def add_report_command(sub) -> None:
    """Add `report` to the CLI's sub-parsers."""
    r = sub.add_parser("report", help="one HTML page (and Markdown) of a run's results next to the paper's")
    r.add_argument("--run", required=True, help="run directory")
    r.add_argument("--data", help="data set (default: the one recorded in RUN/config.json)")
    r.add_argument("--benchmark", help="benchmark JSON (default: RUN/benchmark.json when present)")
    r.add_argument("--recording", help="plan GIF to show (default: RUN/plan.gif, else RUN/recordings/*.gif)")
    r.set_defaults(func=cmd_report)


def cmd_plots(args: argparse.Namespace) -> int:
    from symlearn.outputs import folder_output
    from symlearn.planning.benchmark_plots import plots_of_results

    folder_output(Path(args.out), "--out")
    written, markdown = plots_of_results([Path(p) for p in args.results], Path(args.out),
                                         Path(args.merged) if args.merged else None)
    for path in written:
        print(f"wrote {path}")
    print()
    print(markdown)
    return 0


def add_plots_command(sub) -> None:
    """Add `plots` to the CLI's sub-parsers."""
    r = sub.add_parser("plots", help="plots and Markdown tables of saved benchmark results (success and executed / "
                                     "shortest plan length by objects x shortest-plan length, ...)")
    r.add_argument("results", nargs="+", metavar="RESULT.json",
                   help="JSON written by symlearn benchmark; several (same run and problems, other planners) merge")
    r.add_argument("--out", required=True, help="folder for the plots")
    r.add_argument("--merged", help="also write the merged result JSON here")
    r.set_defaults(func=cmd_plots)
