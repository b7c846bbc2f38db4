"""`symlearn report`: RUN/report.html (self-contained) and RUN/report.md from the run's own outputs.

    symlearn report --run runs/paper [--data data/paper] [--benchmark runs/paper/benchmark.json]
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
