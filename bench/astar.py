"""Learned-net A*: node expansions per second on CPU, batched against one forward pass per action.

Start states are the encoder's codes of test-split scenes (1-3 objects); each goal is the state
the transition network predicts after `--length` random actions, so every problem is solvable
under the network. Both searches run the same problems in the same process: `batched` is
search.learned_astar as shipped (all 36 actions of an expansion in one forward pass), the
baseline calls the network once per action. Writes JSON.

    python bench/astar.py --run runs/quick32 --data data/paper --out bench/results/astar.json
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

from search.learned_astar import plan_symbolic
from pddl_export.symbolic import N_ACTIONS, SymbolicGoal, codes_from_bits
from symlearn.learning.checkpoint import load_effect_model
from symlearn.data.dataset import load_split
from symlearn.provenance import atomic_write_json, bench_context
from symlearn.symbolic.learned_transition import LearnedTransition


class OneActionPerCall:
    """The same network, called once per (state, action) row: the unbatched baseline."""

    def __init__(self, inner: LearnedTransition) -> None:
        self.inner, self.bits = inner, inner.bits

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        return np.concatenate([self.inner(codes[i:i + 1], actions[i:i + 1]) for i in range(len(actions))])


def problems(run: Path, data: Path, n: int, length: int, seed: int, transition: LearnedTransition):
    """n (start codes, goal codes) pairs from test-split scenes, goals from network rollouts."""
    reader = transition.reader(load_effect_model(run)[0])  # the codes m(z) reads, location bits included
    split = load_split(data, "test")
    rng = np.random.default_rng(seed)
    idx = rng.choice(len(split.action), size=min(n, len(split.action)), replace=False)
    bits = reader.encode(split.pre_depth[idx], split.pre_origin[idx], split.mask[idx])
    codes = codes_from_bits(bits.astype(np.int64))
    out = []
    for row, i in enumerate(idx):
        start = codes[row][split.mask[i]]
        state = start[None]
        for a in rng.integers(0, N_ACTIONS, size=length):
            state = transition(state, np.array([a]))
        out.append((start, SymbolicGoal(tuple(int(c) for c in state[0]))))
    return out


def measure(transition, tasks, uniform_cost: bool, timeout_s: float) -> dict:
    """Expansions, seconds and solved count of one search mode over the tasks."""
    expansions, seconds, solved = 0, 0.0, 0
    for start, goal in tasks:
        r = plan_symbolic(transition, start, goal, uniform_cost=uniform_cost, timeout_s=timeout_s)
        expansions += r.expansions or 0
        seconds += r.planning_time_s
        solved += r.found
    return {"problems": len(tasks), "solved": solved, "expansions": expansions, "seconds": round(seconds, 4),
            "nodes_per_s": round(expansions / seconds, 1) if seconds else None}


def main() -> None:
    """Build the problems, time batched and unbatched search, write the JSON report."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, default=Path("runs/quick32"))
    ap.add_argument("--data", type=Path, default=Path("data/paper"))
    ap.add_argument("--n", type=int, default=100, help="problems for the batched search")
    ap.add_argument("--n-baseline", type=int, default=20, help="of those, problems for the unbatched baseline")
    ap.add_argument("--length", type=int, default=4, help="random actions from start to goal")
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path("bench/results/astar.json"))
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    transition = LearnedTransition.from_run(args.run)
    tasks = problems(args.run, args.data, args.n, args.length, args.seed, transition)
    base = tasks[: args.n_baseline]
    result = {"run": str(args.run), "data": str(args.data), "length": args.length, "seed": args.seed,
              "threads": args.threads, "objects": {str(k): sum(len(s) == k for s, _ in tasks) for k in (1, 2, 3)},
              **bench_context()}
    for mode, uniform in (("astar", False), ("uniform_cost", True)):
        batched_all = measure(transition, tasks, uniform, args.timeout)
        batched = measure(transition, base, uniform, args.timeout)
        single = measure(OneActionPerCall(transition), base, uniform, args.timeout)
        result[mode] = {"batched_all": batched_all, "batched": batched, "one_action_per_call": single,
                        "speedup": round(batched["nodes_per_s"] / single["nodes_per_s"], 2)
                        if batched["nodes_per_s"] and single["nodes_per_s"] else None}
        print(f"{mode}: {batched_all['nodes_per_s']} nodes/s batched over {batched_all['problems']} problems; "
              f"on {len(base)}: {batched['nodes_per_s']} batched vs {single['nodes_per_s']} one action per call "
              f"({result[mode]['speedup']}x)")
    result["wall_time"] = time.strftime("%Y-%m-%d %H:%M:%S")
    atomic_write_json(args.out, result)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
