"""The learned route's closed loop under other loop settings: unary bits, keeping a plan, shortening it.

`symlearn benchmark-learned` runs the loop as LearnedLoopConfig's defaults have it (execution monitoring on, an
object's bits those it showed so far in the episode, each plan shortened in up to 2 s). This runs the same benchmark,
resumable, with those levers set otherwise, as the dev comparisons behind the defaults did
(bench/results/relations_dev_loop.json):

    python experiments/learned_loop_ab.py --run pretrained/relations_carry --problems problems/rel_dev68 \
        --out dev68_each_off.json --monitor off --unary each [--shorten-s 0] [--planner fd-lama-first]
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from symlearn.planning.learned_benchmark import benchmark_learned
from symlearn.planning.learned_loop import LearnedLoopConfig


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--problems", required=True)
    ap.add_argument("--out", required=True, help="result JSON file (resumed: finished problems are kept)")
    ap.add_argument("--planner", default=LearnedLoopConfig.planner)
    ap.add_argument("--monitor", choices=("on", "off"), default="on" if LearnedLoopConfig.monitor else "off")
    ap.add_argument("--unary", choices=("each", "first", "seen"), default=LearnedLoopConfig.unary)
    ap.add_argument("--shorten-s", type=float, default=LearnedLoopConfig.shorten_s,
                    help="seconds of a call for shortening the plan (0: executed as the planner gives it)")
    a = ap.parse_args(argv)
    cfg = LearnedLoopConfig(planner=a.planner, goal_relations=("on",), relax_unreachable=True,
                            monitor=a.monitor == "on", unary=a.unary, shorten_s=a.shorten_s)
    res = benchmark_learned(Path(a.run), Path(a.problems), Path(a.out), cfg)
    print(json.dumps({band: v["success"] for band, v in res["summary"].items()}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
