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

The unified-planning route runs beside them under the names `up-fast-downward`, `up-pyperplan` and `up-symk`
(search.classical.solve_pddl: OneshotPlanner, every plan checked by UP's PlanValidator). With `--shortest
OUT/problems.json` (symlearn export-learned-problems), each row gets the simulator's shortest plan length and each
planner's summary counts the reachable goals it reported unsolvable and its mean plan length over the shortest:

    symlearn export-learned-problems --run pretrained/relations_on --problems problems/rel_test3 --out lp3 \
        --goal-relations on
    python bench/stock_fd.py --domain lp3/domain.pddl --problems lp3 --shortest lp3/problems.json \
        --planners fd-lama-first,fd-lmcut,pyperplan,up-fast-downward,up-pyperplan --out x.json

With `--focus DIR` (export-learned-problems --focus writes OUT/focus), a problem with a file of the same name in DIR
is planned as the closed loop plans its first and last calls: that focus problem first, in half the time limit, and
where it yields no plan the whole problem in the time left (the loop tries the focus and the tops of the other
stacks between them: learned_calls.object_sets). The row's status and plan are the last call's; its times are the two
calls' sums (a call that reported no Fast Downward clocks adds its whole call time), and `focus` says how the first
ended.

    python bench/stock_fd.py --domain lp3/domain.pddl --problems lp3 --focus lp3/focus --shortest lp3/problems.json \
        --out x.json
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

DEFAULT_PLANNERS = ("fd-lama-first", "fd-lmcut")
FOCUS_SHARE = 0.5  # of the time limit for a focus problem, as symlearn.planning.learned_calls.FOCUS_SHARE
SUMMED = ("call_time_s", "fd_translate_time_s", "fd_total_time_s", "translate_plus_search_s")
UP_PLANNERS = {"up-fast-downward": "fast-downward", "up-pyperplan": "pyperplan", "up-symk": "symk"}
MAX_MANIFEST_BYTES = 16 << 20


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


def read_shortest(path: Path) -> dict[str, int | None]:
    """Problem file name -> the simulator's shortest plan length, from export-learned-problems' problems.json.

    SystemExit (one line) for a file that is missing, too large or not such a manifest."""
    try:
        if path.stat().st_size > MAX_MANIFEST_BYTES:
            raise SystemExit(f"stock_fd: {path} is larger than {MAX_MANIFEST_BYTES} bytes")
        man = json.loads(path.read_text(encoding="utf-8"))
        return {str(r["file"]): (None if r["shortest"] is None else int(r["shortest"])) for r in man["rows"]}
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise SystemExit(f"stock_fd: {path} is not a problems.json of symlearn export-learned-problems ({e})") from None


def summarize(rows: list[dict], planners: list[str]) -> dict:
    """Per planner: counts by status, and median / max of translate + search and of the whole call; with the
    shortest plan lengths, the reachable goals reported unsolvable and the mean plan length over the shortest."""
    out = {}
    for name in planners:
        runs = [r["planners"][name] for r in rows if name in r["planners"]]
        counts = {s: sum(x["status"] == s for x in runs) for s in ("solved", "unsolvable", "timeout", "error")}
        entry: dict = {"problems": len(runs), **counts}
        if any("focus" in x for x in runs):
            entry["focus_solved"] = sum(x.get("focus") == "solved" for x in runs)
        known = [(r["planners"][name], r["shortest"]) for r in rows if name in r["planners"] and "shortest" in r]
        if known:
            entry["reachable_reported_unsolvable"] = sum(x["status"] == "unsolvable" for x, _ in known)
            ratios = [x["plan_length"] / n for x, n in known if x["status"] == "solved" and n]
            entry["plan_over_shortest"] = round(statistics.mean(ratios), 4) if ratios else None
        for key in ("translate_plus_search_s", "fd_translate_time_s", "fd_total_time_s", "call_time_s"):
            vals = [x[key] for x in runs if x.get(key) is not None]
            if vals:
                entry[key] = {"median": round(statistics.median(vals), 4), "max": round(max(vals), 4)}
        out[name] = entry
    return out


def solve(domain: Path, problem: Path, planner: str, timeout_s: float):
    """One call: a stock planner on the files, or a unified-planning engine on their texts (validated)."""
    from search.stock_planners import solve_files

    if planner in UP_PLANNERS:
        from search.classical import solve_pddl

        return solve_pddl(domain.read_text(encoding="utf-8"), problem.read_text(encoding="utf-8"),
                          UP_PLANNERS[planner], timeout_s)
    return solve_files(domain, problem, planner, timeout_s)


def solve_focused(domain: Path, problem: Path, few: Path | None, planner: str, timeout_s: float) -> dict:
    """One row's record: the problem alone, or with its focus problem `few`, that one first in FOCUS_SHARE of the
    time and the whole problem in the time left where it finds no plan."""
    from search.stock_planners import call_record

    if few is None:
        return call_record(solve(domain, problem, planner, timeout_s))
    first = call_record(solve(domain, few, planner, timeout_s * FOCUS_SHARE))
    if first["status"] == "solved":
        return {**first, "focus": "solved"}
    second = call_record(solve(domain, problem, planner, max(timeout_s - first["call_time_s"], 1.0)))
    sums = {k: round(first.get(k, first["call_time_s"]) + second[k], 4) for k in SUMMED if k in second}
    return {**second, **sums, "focus": first["status"]}


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
    ap.add_argument("--shortest", type=Path, help="problems.json of symlearn export-learned-problems: the "
                                                  "simulator's shortest plan length of each problem")
    ap.add_argument("--focus", type=Path, help="folder of focus problems (export-learned-problems --focus): each "
                                               "planned first, the whole problem where it finds no plan")
    args = ap.parse_args(argv)
    from search.stock_planners import STOCK_PLANNERS
    from symlearn.provenance import atomic_write_json, bench_context, sha256_file

    try:
        planners = [p for p in args.planners.split(",") if p]
        bad = [p for p in planners if p not in STOCK_PLANNERS and p not in UP_PLANNERS]
        if bad or not planners:
            raise SystemExit(f"stock_fd: unknown planner(s) {bad or planners}; known: "
                             f"{', '.join([*STOCK_PLANNERS, *UP_PLANNERS])}")
        if not args.domain.is_file():
            raise SystemExit(f"stock_fd: domain file not found: {args.domain}")
        if not (args.timeout > 0 and args.timeout < float("inf")):
            raise SystemExit(f"stock_fd: --timeout must be a positive number of seconds, got {args.timeout}")
        if args.focus is not None and not args.focus.is_dir():
            raise SystemExit(f"stock_fd: --focus folder not found: {args.focus}")
        if not args.out.parent.is_dir() or args.out.is_dir():
            raise SystemExit(f"stock_fd: cannot write {args.out} (its folder does not exist, or it is a folder)")
        problems = problem_files(args.domain, args.problems)
        shortest = read_shortest(args.shortest) if args.shortest else None
        missing = [p.name for p in problems if shortest is not None and p.name not in shortest]
        if missing:
            raise SystemExit(f"stock_fd: {args.shortest} has no shortest length for {missing[0]}")
        if args.focus is not None:
            if any(p.parent.resolve() == args.focus.resolve() for p in problems):
                raise SystemExit(f"stock_fd: --focus {args.focus} holds the problems themselves; name the folder of "
                                 "their focus problems (export-learned-problems --focus writes OUT/focus)")
            if not any((args.focus / p.name).is_file() for p in problems):
                raise SystemExit(f"stock_fd: no file in --focus {args.focus} has the name of a problem")
    except SystemExit as e:
        print(e, file=sys.stderr)
        return 2
    key = {"domain": str(args.domain), "domain_sha256": sha256_file(args.domain), "planners": planners,
           "timeout_s": args.timeout, **({"shortest": str(args.shortest)} if args.shortest else {}),
           **({"focus": str(args.focus)} if args.focus else {})}
    done = _previous(args.out, key)
    rows = []
    for problem in problems:
        few = args.focus / problem.name if args.focus is not None else None
        few = few if few is not None and few.is_file() else None  # its focus problem, where it has one
        digest = sha256_file(problem) + (f"+{sha256_file(few)}" if few is not None else "")
        old = done.get(str(problem))
        if old is not None and old.get("sha256") == digest and set(old.get("planners", {})) == set(planners):
            rows.append(old)
            continue
        rec = {"problem": str(problem), "sha256": digest, "planners": {}}
        if shortest is not None:
            rec["shortest"] = shortest[problem.name]
        for name in planners:
            rec["planners"][name] = solve_focused(args.domain, problem, few, name, args.timeout)
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
