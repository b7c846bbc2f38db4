"""Fault-injection summary: run every probe of the fault suites and count what held.

Each probe in tests/test_faults_*.py feeds one bad input or interruption to a stage (a corrupted
manifest, a hostile problem name, a SIGTERM mid-collection, ...) and asserts the guarantee of
docs/RELIABILITY.md: a one-line refusal naming the problem and the file, or a clean resume, with no
process, temp file or half-written output left. This script runs them (pytest, JUnit XML) and
writes the tally per suite: tried, held, failed.

    python experiments/faults.py --out bench/results/faults.json
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

from symlearn.provenance import atomic_write_json, bench_context

ROOT = Path(__file__).resolve().parents[1]


def run_suites(timeout_s: float) -> dict:
    """Run the fault suites once; per suite file: probes tried, held (passed) and failed, with failing ids."""
    suites = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "tests").glob("test_faults*.py"))
    with tempfile.TemporaryDirectory(prefix="symlearn-faults-") as tmp:
        report = Path(tmp) / "junit.xml"
        subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:warnings", "-m", "", f"--junitxml={report}",
                        *suites], cwd=ROOT, timeout=timeout_s, check=False)
        tree = ET.parse(report)
    out: dict[str, dict] = {}
    for case in tree.iter("testcase"):
        suite = case.get("classname", "").split(".")[-1]
        row = out.setdefault(suite, {"tried": 0, "held": 0, "failed": 0, "skipped": 0, "failures": []})
        row["tried"] += 1
        if case.find("skipped") is not None:
            row["skipped"] += 1
        elif case.find("failure") is not None or case.find("error") is not None:
            row["failed"] += 1
            row["failures"].append(case.get("name"))
        else:
            row["held"] += 1
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="bench/results/faults.json")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds for the whole run")
    args = ap.parse_args()
    suites = run_suites(args.timeout)
    total = {k: sum(s[k] for s in suites.values()) for k in ("tried", "held", "failed", "skipped")}
    result = {**bench_context(), "total": total, "suites": suites}
    atomic_write_json(Path(args.out), result)
    print(f"{total['tried']} probes: {total['held']} held, {total['failed']} failed, {total['skipped']} skipped")
    for name, s in suites.items():
        print(f"  {name}: {s['tried']} tried, {s['held']} held" + (f", failed: {s['failures']}" if s["failed"] else ""))


if __name__ == "__main__":
    main()
