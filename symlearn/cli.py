"""The `symlearn` command line: each sub-command maps its flags onto a config and calls the library.

    symlearn collect --out data/paper --n 12000 --workers 2 --seed 0
    symlearn scenarios --json
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def _objects_range(text: str) -> tuple[int, int]:
    try:
        lo, _, hi = text.partition("-")
        lo_i, hi_i = int(lo), int(hi or lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"object range {text!r} must look like 1-3 or 4") from None
    if lo_i > hi_i:
        raise argparse.ArgumentTypeError(f"object range {text!r} is empty")
    return lo_i, hi_i


def cmd_collect(args: argparse.Namespace) -> int:
    from symlearn.collect import CollectConfig, collect
    from symlearn.dataset import summarize
    from symlearn.exploration import ExplorationConfig

    expl = ExplorationConfig() if args.objects is None else ExplorationConfig.with_k_range(*args.objects)
    cfg = CollectConfig(n=args.n, seed=args.seed, shard_size=args.shard_size, exploration=expl)
    print(f"collect: {cfg.n} samples, seed {cfg.seed}, {len(cfg.shard_sizes())} shards, "
          f"{args.workers} worker(s) -> {args.out}", file=sys.stderr)
    t0 = time.time()
    collect(Path(args.out), cfg, workers=args.workers, show_progress=not args.quiet)
    summary = summarize(Path(args.out))
    summary["wall_s"] = round(time.time() - t0, 1)
    print(json.dumps(summary, indent=2))
    return 0


def cmd_scenarios(args: argparse.Namespace) -> int:
    from symlearn.scenarios import SCENARIO_BY_NAME, SCENARIOS, run_scenario
    from symlearn.simulator import TabletopSimulator

    names = args.names or [s.name for s in SCENARIOS]
    unknown = [n for n in names if n not in SCENARIO_BY_NAME]
    if unknown:
        raise ValueError(f"unknown scenario {unknown[0]!r}; known: {', '.join(SCENARIO_BY_NAME)}")
    with TabletopSimulator(gui=args.gui) as sim:
        results = [run_scenario(sim, SCENARIO_BY_NAME[n]).to_json() for n in names]
    if args.json:
        print(json.dumps(results, indent=2))
        return 0
    for r in results:
        print(f"{r['name']}  (pick {r['action'][0]} -> release {r['action'][1]}): {r['description']}")
        for o in r["objects"]:
            dx, dy, dz = o["effect_mm"]
            print(f"    {o['type']:<6} effect mm  ({dx:7.1f}, {dy:7.1f}, {dz:7.1f})")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="symlearn", description="Learn planning symbols from robot interaction.")
    sub = p.add_subparsers(dest="command", required=True)

    c = sub.add_parser("collect", help="collect interaction data in the simulator")
    c.add_argument("--out", required=True, help="data set directory (created, or resumed)")
    c.add_argument("--n", type=int, default=12000, help="number of samples (actions)")
    c.add_argument("--workers", type=int, default=1, help="worker processes")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--objects", type=_objects_range, default=None,
                   help="objects per scene, e.g. 4-5 (default: the paper's mix of 1-3)")
    c.add_argument("--shard-size", type=int, default=250, help="samples per shard")
    c.add_argument("--quiet", action="store_true", help="no progress bar")
    c.set_defaults(func=cmd_collect)

    s = sub.add_parser("scenarios", help="run the named physics scenarios and print their effects")
    s.add_argument("names", nargs="*", help="scenario names (default: all)")
    s.add_argument("--json", action="store_true", help="print JSON")
    s.add_argument("--gui", action="store_true", help="watch in pybullet's GUI")
    s.set_defaults(func=cmd_scenarios)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, RuntimeError, OSError) as e:
        print(f"symlearn {args.command}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"symlearn {args.command}: interrupted; re-run the same command to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
