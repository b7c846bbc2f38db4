"""What the bounded JSON reader costs on a rules-like document, against plain json.loads.

pddl_export.bounded_json parses with two hooks (NaN/Infinity refused, every float checked finite) and, in
files up to SCAN_BYTES, walks the parsed value once more for nesting depth and 64-bit integers. This times,
in one process on the same text (a synthetic rules.json of --rules rules, 12-bit codes): json.loads, the
bounded parse without the walk (what a larger file gets) and with it. Ratios are against json.loads, the
best of --repeat runs each, the garbage collector paused as rules_io.paused_gc does. Writes JSON.

    python bench/json_reader.py --rules 100000 --out bench/results/json_reader.json
"""
from __future__ import annotations

import argparse
import gc
import json
import random
import sys
import time
from pathlib import Path

from pddl_export.bounded_json import loads_bounded
from symlearn.provenance import atomic_write_json, bench_context


def rules_text(n_rules: int, seed: int = 0) -> str:
    """A rules.json-shaped document of n_rules rules (12-bit codes, a few conditions each)."""
    rng = random.Random(seed)

    def code() -> str:
        return format(rng.getrandbits(12), "012b")

    doc = {"bits": 12, "vocabulary": [code() for _ in range(300)], "max_objects": 3,
           "n_rules_before_generalization": n_rules,
           "rules": [{"action": rng.randrange(36), "pick": 1, "release": 2, "from": code(), "to": code(),
                      "requires": [code(), code()], "forbids": [code()], "at_least": [[code(), 2]],
                      "fewer_than": [[code(), 3]]} for _ in range(n_rules)]}
    return json.dumps(doc)


def best_of(fn, repeat: int) -> float:
    """Fastest of `repeat` calls, in seconds, with cyclic garbage collection paused."""
    times = []
    for _ in range(repeat):
        gc.collect()
        gc.disable()
        try:
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        finally:
            gc.enable()
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rules", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default="bench/results/json_reader.json")
    args = ap.parse_args()
    text = rules_text(args.rules)
    plain = best_of(lambda: json.loads(text), args.repeat)
    hooks = best_of(lambda: loads_bounded(text, "bench", scan=False), args.repeat)
    walked = best_of(lambda: loads_bounded(text, "bench", scan=True), args.repeat)
    result = {**bench_context(), "command": " ".join(["python"] + sys.argv), "rules": args.rules,
              "megabytes": round(len(text) / 1e6, 1), "json_loads_s": round(plain, 3),
              "bounded_no_walk_s": round(hooks, 3), "bounded_with_walk_s": round(walked, 3),
              "ratio_no_walk": round(hooks / plain, 2), "ratio_with_walk": round(walked / plain, 2)}
    atomic_write_json(Path(args.out), result)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
