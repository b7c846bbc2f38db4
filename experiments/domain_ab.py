"""Two forms of a PDDL domain on the same problems, interleaved: stock Fast Downward's translate + search time.

A change to the writer (a predicate added, an action split) is judged against the form before it on the same
tasks, in one process, each problem run on both forms in turn and the order swapped every repeat, so that the load
of the machine falls on both alike. Folder A and folder B each hold a domain.pddl and the same pNN.pddl names (the
problems as each form writes them); the JSON has every call and, per object count where the folders' index.json
gives it, the medians of both and their ratio.

    # the shipped test folder against the same export without `stands` (each fact is one line of a problem)
    mkdir -p base && git show be6739b:pretrained/recommended/pddl/lifted/domain.pddl > base/domain.pddl
    for f in RUN/pddl/lifted/test/p*.pddl; do grep -v '(stands ' "$f" > base/$(basename "$f"); done
    python experiments/domain_ab.py --a base --b RUN/pddl/lifted/test --out bench/results/stands_ab.json
"""
from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from search.stock_planners import call_record


def _problems(folder: Path) -> list[str]:
    names = sorted(f.stem for f in folder.glob("p*.pddl") if f.is_file())
    if not (folder / "domain.pddl").is_file() or not names:
        raise SystemExit(f"domain_ab: {folder} needs a domain.pddl and pNN.pddl problems")
    return names


def main(argv: list[str] | None = None) -> int:
    from pddl_export.bounded_json import read_json_file
    from search.stock_planners import solve_files
    from symlearn.provenance import atomic_write_json, bench_context

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a", required=True, type=Path, help="the baseline folder (domain.pddl, pNN.pddl)")
    ap.add_argument("--b", required=True, type=Path, help="the folder compared with it, the same problem names")
    ap.add_argument("--planner", default="fd-lama-first", help="a search.stock_planners name")
    ap.add_argument("--repeats", type=int, default=2, help="runs of each problem on each form (order swapped)")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per call")
    ap.add_argument("--out", required=True, type=Path)
    args = ap.parse_args(argv)
    names = _problems(args.a)
    missing = sorted(set(names) - set(_problems(args.b)))
    if missing:
        raise SystemExit(f"domain_ab: {args.b} lacks {', '.join(missing[:5])}")
    if args.repeats < 1:
        raise SystemExit(f"domain_ab: --repeats {args.repeats} must be at least 1")
    index = args.b / "index.json"
    objects = {}
    if index.is_file():
        problems = read_json_file(index, what="problem folder index", max_bytes=16 << 20).get("problems", {})
        objects = {n: v.get("objects") for n, v in problems.items()}
    calls: list[dict] = []
    for rep in range(args.repeats):
        for name in names:
            for form in (("a", "b") if rep % 2 == 0 else ("b", "a")):
                folder = args.a if form == "a" else args.b
                rec = call_record(solve_files(folder / "domain.pddl", folder / f"{name}.pddl", args.planner,
                                      timeout_s=args.timeout))
                calls.append({"problem": name, "form": form, "repeat": rep, "objects": objects.get(name),
                              **{k: rec.get(k) for k in ("status", "translate_plus_search_s", "call_time_s")}})
    groups: dict = {}
    for c in calls:  # a call without Fast Downward's own clocks (a timeout, an error) has no translate + search time
        if c["translate_plus_search_s"] is not None:
            for key in ("all", str(c["objects"])):
                groups.setdefault(key, {"a": [], "b": []})[c["form"]].append(c["translate_plus_search_s"])
    summary = {k: {"calls": len(v["a"]), "median_a_s": round(statistics.median(v["a"]), 4),
                   "median_b_s": round(statistics.median(v["b"]), 4),
                   "b_over_a": round(statistics.median(v["b"]) / max(statistics.median(v["a"]), 1e-9), 3)}
               for k, v in sorted(groups.items()) if v["a"] and v["b"]}
    status = {(c["problem"], c["repeat"], c["form"]): c["status"] for c in calls}
    same = all(status[(n, r, "a")] == status[(n, r, "b")] for n in names for r in range(args.repeats))
    atomic_write_json(args.out, {"a": str(args.a), "b": str(args.b), "planner": args.planner,
                                 "repeats": args.repeats, "timeout_s": args.timeout, "same_status": same,
                                 "summary": summary, "calls": calls, **bench_context()})
    for k, v in summary.items():
        print(f"{k:>4}: {v['calls']} calls, median A {v['median_a_s']:.3f} s, B {v['median_b_s']:.3f} s, "
              f"B/A {v['b_over_a']:.2f}")
    print(f"same status on every problem: {same}; wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
