"""Enumeration speed: (scene, action) queries per second through a run's transition network.

Enumerates every multiset of 1..K codes over the first V codes of the run's exported
vocabulary (RUN/pddl/rules.json) times the 36 actions, as `symlearn export-pddl --rules` does with
`[export] scenes = "all"` in its --config, once per thread count and batch size. The baseline in the same
run is one network call per scene (36 rows), the way a search queries the network. Writes JSON.

    python bench/enumeration.py --run runs/quick32 --out bench/results/enumeration_quick32.json
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch

from pddl_export.enumeration import enumerate_transitions, multiset_indices
from pddl_export.rules_io import load_rules
from pddl_export.symbolic import N_ACTIONS
from symlearn.provenance import atomic_write_json, bench_context
from symlearn.symbolic.learned_transition import LearnedTransition


def per_scene_baseline(transition: LearnedTransition, vocab: tuple[int, ...], k: int, n_scenes: int) -> float:
    """Queries per second calling the network once per scene of k objects (36 rows a call)."""
    rows = multiset_indices(len(vocab), k)[:n_scenes]
    scenes = np.asarray(vocab, np.int64)[rows]
    actions = np.arange(N_ACTIONS)
    t = time.perf_counter()
    for s in scenes:
        transition(np.repeat(s[None], N_ACTIONS, 0), actions)
    return len(scenes) * N_ACTIONS / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True)
    ap.add_argument("--max-objects", type=int, default=3)
    ap.add_argument("--vocabulary", type=int, default=40, help="how many of the exported codes to enumerate over")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--batch-sizes", default="4096,16384")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    rules, _ = load_rules(args.run)
    vocab = tuple(rules.vocabulary[: args.vocabulary])
    transition = LearnedTransition.from_run(args.run)
    rows = []
    for threads in (int(t) for t in args.threads.split(",")):
        torch.set_num_threads(threads)
        base = per_scene_baseline(transition, vocab, args.max_objects, 300)
        for batch in (int(b) for b in args.batch_sizes.split(",")):
            transition.batch_size = batch
            enum = enumerate_transitions(transition, vocab, max_objects=args.max_objects)
            rows.append({"threads": threads, "batch_size": batch, "queries": enum.n_queries,
                         "seconds": enum.seconds, "queries_per_s": enum.queries_per_s,
                         "per_scene_baseline_queries_per_s": base, "speedup": enum.queries_per_s / base})
            print(f"threads {threads} batch {batch}: {enum.n_queries} queries, {enum.queries_per_s:,.0f} q/s "
                  f"({enum.queries_per_s / base:.1f}x one call per scene: {base:,.0f} q/s)")
    atomic_write_json(args.out, {"run": str(args.run), "vocabulary_size": len(vocab), "max_objects": args.max_objects,
                                 **bench_context(), "rows": rows})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
