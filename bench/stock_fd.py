"""Stock Fast Downward on a PDDL domain and its problems: translate, search and whole-call time per problem.

Each problem is planned by each configuration of search.stock_planners (default: lama-first and
astar(lmcut())) through the stock `fast-downward.py` driver with its own translator, as a planning user
would run it. Per problem and planner it records the status, the plan length and cost, the translator's
wall clock, the search component's own times, the process wall clock (driver start-up included) and the
translator's task size; per planner, medians and maxima of translate + search (Fast Downward's own
clocks) and of the whole call. A problem folder is read as its *.pddl files other than the domain
(names starting with "domain"). The JSON is rewritten after each problem; a run interrupted and started
again with the same arguments keeps the rows it has (same domain, planners, time limit and problem bytes).

    python bench/stock_fd.py --domain RUN/pddl/lifted/domain.pddl --problems RUN/pddl/lifted \
        --out bench/results/stock_fd.json
    python bench/stock_fd.py --domain d.pddl --problems p01.pddl,p02.pddl --planners fd-lama-first --out x.json
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

DEFAULT_PLANNERS = ("fd-lama-first", "fd-lmcut")


def problem_files(domain: Path, specs: list[str]) -> list[Path]:
    """The problem files named by specs (files, folders, comma-separated lists), in the given order, folders sorted.

    SystemExit (one line) for a name that is neither a file nor a folder, or a folder without problems.
    """
    out: list[Path] = []
    for spec in (s for arg in specs for s in arg.split(",") if s):
        p = Path(spec)
        if p.is_dir():
            found = sorted(f for f in p.glob("*.pddl") if f.is_file() and not f.name.lower().startswith("domain")
                           and f.resolve() != domain.resolve())
            if not found:
                raise SystemExit(f"stock_fd: no problem files (*.pddl other than domain*) in {p}")
            out += found
        elif p.is_file():
            out.append(p)
        else:
            raise SystemExit(f"stock_fd: problem file or folder not found: {p}")
    return out


def summarize(rows: list[dict], planners: list[str]) -> dict:
    """Per planner: counts by status, and median / max of translate + search and of the whole call."""
    out = {}
    for name in planners:
        runs = [r["planners"][name] for r in rows if name in r["planners"]]
        counts = {s: sum(x["status"] == s for x in runs) for s in ("solved", "unsolvable", "timeout", "error")}
        entry: dict = {"problems": len(runs), **counts}
        for key in ("translate_plus_search_s", "fd_translate_time_s", "fd_total_time_s", "call_time_s"):
            vals = [x[key] for x in runs if x.get(key) is not None]
            if vals:
                entry[key] = {"median": round(statistics.median(vals), 4), "max": round(max(vals), 4)}
        out[name] = entry
    return out


def _previous(out: Path, key: dict) -> dict[str, dict]:
    """Rows of an earlier run of the same benchmark at out (problem path -> row), or {}."""
    if not out.is_file() or out.stat().st_size > 64 << 20:
        return {}
    try:
        old = json.loads(out.read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(old, dict) or any(old.get(k) != v for k, v in key.items()):
        return {}
    return {r["problem"]: r for r in old.get("rows", []) if isinstance(r, dict) and "problem" in r}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", required=True, type=Path, help="domain.pddl")
    ap.add_argument("--problems", required=True, nargs="+", help="problem files and/or folders (comma-separated)")
    ap.add_argument("--out", required=True, type=Path, help="JSON file to write")
    ap.add_argument("--planners", default=",".join(DEFAULT_PLANNERS), help="search.stock_planners names")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per call (translate + search)")
    args = ap.parse_args(argv)
    from search.stock_planners import STOCK_PLANNERS, call_record, solve_files
    from symlearn.provenance import atomic_write_json, bench_context, sha256_file

    try:
        planners = [p for p in args.planners.split(",") if p]
        bad = [p for p in planners if p not in STOCK_PLANNERS]
        if bad or not planners:
            raise SystemExit(f"stock_fd: unknown planner(s) {bad or planners}; known: {', '.join(STOCK_PLANNERS)}")
        if not args.domain.is_file():
            raise SystemExit(f"stock_fd: domain file not found: {args.domain}")
        if not (args.timeout > 0 and args.timeout < float("inf")):
            raise SystemExit(f"stock_fd: --timeout must be a positive number of seconds, got {args.timeout}")
        if not args.out.parent.is_dir() or args.out.is_dir():
            raise SystemExit(f"stock_fd: cannot write {args.out} (its folder does not exist, or it is a folder)")
        problems = problem_files(args.domain, args.problems)
    except SystemExit as e:
        print(e, file=sys.stderr)
        return 2
    key = {"domain": str(args.domain), "domain_sha256": sha256_file(args.domain), "planners": planners,
           "timeout_s": args.timeout}
    done = _previous(args.out, key)
    rows = []
    for problem in problems:
        digest = sha256_file(problem)
        old = done.get(str(problem))
        if old is not None and old.get("sha256") == digest and set(old.get("planners", {})) == set(planners):
            rows.append(old)
            continue
        rec = {"problem": str(problem), "sha256": digest, "planners": {}}
        for name in planners:
            rec["planners"][name] = call_record(solve_files(args.domain, problem, name, args.timeout))
        rows.append(rec)
        print(f"{problem.name}: " + ", ".join(f"{n} {r['status']} {r['call_time_s']:.2f}s"
                                             for n, r in rec["planners"].items()), flush=True)
        atomic_write_json(args.out, {**key, "complete": False, "rows": rows, **bench_context()})
    out = {**key, "complete": True, "summary": summarize(rows, planners), "rows": rows, **bench_context()}
    atomic_write_json(args.out, out)
    print(json.dumps(out["summary"], indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
