"""The side-by-side table of docs/RELATIONS.md: the learned relational route, the oracle predicates and the paper's
whole-code route on the same problems, closed loop, by objects x shortest-plan length.

    python experiments/relations_table.py [--learned RUN/learned/test.json RUN/learned/test68.json] \\
        [--learned-on RUN_ON/learned/test.json ...] [--learned-cover RUN_COVER/learned/test.json ...] \
        [--learned-carry RUN_CARRY/learned/test.json ...] [--benchmark ORACLE.json ...] \
        --out bench/results/relations_test15_table.json

Each ORACLE.json is `symlearn benchmark --run pretrained/recommended --problems A,B --planners
fast-downward-lifted,astar-outcomes` on the same sets (its closed-loop rows are read).
"""
from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from pddl_export.files import atomic_write_json

BANDS = (("1-5", 1, 5), ("6-8", 6, 8), ("9-10", 9, 10), ("6-10", 6, 10))
LENGTHS = (("1", 1, 1), ("2", 2, 2), ("3+", 3, 99))


def table(rows: list[tuple[str, int, int | None, bool, float | None]], structures: set[int] = frozenset()) -> dict:
    """rows of (route, objects, shortest length, success, executed/shortest) -> success per cell, mean length ratio.
    The rows whose index is in `structures` (a structures suite) fill one band of their own, "structures"."""
    cells: dict = defaultdict(list)
    ratio: dict = defaultdict(list)
    for i, (route, k, opt, ok, r) in enumerate(rows):
        for band, lo, hi in (("structures", 0, 99),) if i in structures else BANDS:
            if lo <= k <= hi:
                cells[(route, band, "all")].append(ok)
                ratio[(route, band)] += [r] if r is not None else []
                for name, a, b in LENGTHS:
                    if opt is not None and a <= opt <= b:
                        cells[(route, band, name)].append(ok)
    out: dict = {}
    for (route, band, length), v in sorted(cells.items()):
        out.setdefault(route, {}).setdefault(band, {})[length] = {"success": round(sum(v) / len(v), 3), "n": len(v)}
    for (route, band), v in ratio.items():
        out[route][band]["executed_over_shortest"] = round(float(np.mean(v)), 3) if v else None
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--learned", nargs="*", default=[], help="benchmark-learned result files of the at-only model")
    ap.add_argument("--learned-on", nargs="*", default=[], help="benchmark-learned result files of the rests-on model")
    ap.add_argument("--learned-cover", nargs="*", default=[], help="benchmark-learned result files of the cover model "
                                                                   "(a route per planner their settings name)")
    ap.add_argument("--learned-carry", nargs="*", default=[], help="benchmark-learned result files of the model "
                                                                   "trained with far-stick scenes (pretrained/relations_carry)")
    ap.add_argument("--benchmark", nargs="*", default=[],
                    help="symlearn benchmark files of the oracle and whole-code routes")
    ap.add_argument("--structures", nargs="*", default=[],
                    help="folder names of structures suites: their problems fill a band of their own")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    rows, structures = [], set()
    for route, files in (("learned at", a.learned), ("learned at + on", a.learned_on),
                         ("learned cover at + on", a.learned_cover), ("learned carry", a.learned_carry)):
        for f in files:
            res = json.loads(Path(f).read_text())
            planner = res["settings"]["config"]["planner"]  # one route per planner: "learned at (fd-lama-first)"
            suite = Path(res["settings"]["problems"]).name in a.structures
            for r in res["results"]:
                if suite:
                    structures.add(len(rows))
                opt = r["optimal_length"]
                rows.append((f"{route} ({planner})", r["k"], opt, r["success"],
                             len(r["actions"]) / opt if r["success"] and opt else None))
    names = {"fast-downward-lifted": "oracle predicates (fast-downward-lifted)",
             "astar-outcomes": "whole codes (astar-outcomes)"}
    for r in (r for f in a.benchmark for r in json.loads(Path(f).read_text())["rows"]):
        if r.get("closed_loop") and r["planner"] in names:
            if r["problem"].split("/")[0] in a.structures:
                structures.add(len(rows))
            opt = r.get("optimal_length")
            rows.append((names[r["planner"]], r["n_objects"], opt, r["success"],
                         r["executed_length"] / opt if r["success"] and opt and r.get("executed_length") else None))
    atomic_write_json(Path(a.out), {"learned": a.learned, "learned_on": a.learned_on, "learned_cover": a.learned_cover,
                                    "learned_carry": a.learned_carry, "benchmark": a.benchmark,
                                    "structures": a.structures, "table": table(rows, structures)})


if __name__ == "__main__":
    main()
