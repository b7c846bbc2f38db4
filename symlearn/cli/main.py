"""The `symlearn` command line: each sub-command maps its flags onto a config and calls the library.

    symlearn collect --out data/paper --n 12000 --workers 2 --seed 0
    symlearn collect --out /shared/data/big --n 1000000 --workers 64 --ray auto
    symlearn scenarios --json
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from symlearn.cli.args import (THREADS_HELP, OneLineParser, add_config_flag, add_preset_flag, add_ray_flag,
                               config_from_file, int_range, non_negative_int, positive_int, ray_engine, set_threads, thread_count)
from symlearn.cli.pipeline import add_pipeline_command
from symlearn.cli.planning import add_planning_commands
from symlearn.cli.relations import add_relations_commands
from symlearn.cli.report import add_plots_command, add_report_command
from symlearn.config_file import RECIPE
from symlearn.outputs import folder_output

if TYPE_CHECKING:  # the configs' modules load torch, numpy or the simulator: imported where a command runs
    from symlearn.export.lifted_export import LiftedConfig
    from symlearn.learning.training import TrainConfig
    from symlearn.sim.collect import CollectConfig


LIFTED_DEFAULT = "fast"  # export-pddl's preset: LiftedConfig()'s own values (lifted_export.LIFTED_PRESETS; a test)


def collect_config(args: argparse.Namespace) -> CollectConfig:
    """CollectConfig's defaults with --config's [collect] table and the flags over them."""
    from symlearn.config_file import replace_nested
    from symlearn.sim.collect import CollectConfig

    cfg = config_from_file(args, "collect", lambda v: replace_nested(CollectConfig(), v))
    if args.objects is not None:  # over the file's other exploration settings (a far-stick scene draw), not instead
        cfg = dataclasses.replace(cfg, exploration=cfg.exploration.over_objects(*args.objects))
    return dataclasses.replace(cfg, **{k: v for k, v in dict(n=args.n, seed=args.seed).items() if v is not None})


def cmd_collect(args: argparse.Namespace) -> int:
    from symlearn.cluster import check_engine
    from symlearn.data.dataset import summarize
    from symlearn.sim.collect import collect

    cfg = collect_config(args)
    engine, address = ray_engine(args)
    check_engine(engine, address)  # before any work: a missing Ray is refused in one line
    where = f" on Ray{f' at {address}' if address else ''}" if engine == "ray" else ""
    print(f"collect: {cfg.n} samples, seed {cfg.seed}, {len(cfg.shard_sizes())} shards, "
          f"{args.workers} worker(s){where} -> {args.out}", file=sys.stderr)
    t0 = time.time()
    collect(Path(args.out), cfg, workers=args.workers, show_progress=not args.quiet, engine=engine, address=address)
    summary = summarize(Path(args.out))
    summary["wall_s"] = round(time.time() - t0, 1)
    print(json.dumps(summary, indent=2, allow_nan=False))
    return 0


def cmd_scenarios(args: argparse.Namespace) -> int:
    from symlearn.sim.scenarios import SCENARIO_BY_NAME, SCENARIOS, run_scenario
    from symlearn.sim.simulator import TabletopSimulator

    names = args.names or [s.name for s in SCENARIOS]
    unknown = [n for n in names if n not in SCENARIO_BY_NAME]
    if unknown:
        raise ValueError(f"unknown scenario {unknown[0]!r}; known: {', '.join(SCENARIO_BY_NAME)}")
    with TabletopSimulator(gui=args.gui) as sim:
        results = [run_scenario(sim, SCENARIO_BY_NAME[n]).to_json() for n in names]
    if args.json:
        print(json.dumps(results, indent=2, allow_nan=False))
        return 0
    for r in results:
        print(f"{r['name']}  (pick {r['action'][0]} -> release {r['action'][1]}): {r['description']}")
        for o in r["objects"]:
            dx, dy, dz = o["effect_mm"]
            print(f"    {o['type']:<6} effect mm  ({dx:7.1f}, {dy:7.1f}, {dz:7.1f})")
    return 0


def _init_distributed() -> bool:
    """Join the process group when launched by torchrun (WORLD_SIZE > 1); whether it joined one."""
    import os

    if int(os.environ.get("WORLD_SIZE", "1")) > 1:
        import torch
        import torch.distributed as dist

        dist.init_process_group("nccl" if torch.cuda.is_available() else "gloo")
        return True
    return False


def _leave_distributed(finished: bool) -> None:
    """Leave the process group; after a finished run, first wait for every rank. A rank that exits with its gloo
    connections open can abort (SIGABRT) while a peer still writes its files. A failed rank does not wait: its peers
    may never reach the barrier, and torchrun stops them once it exits."""
    import torch.distributed as dist

    if dist.is_initialized():
        try:
            if finished:
                dist.barrier()
        finally:
            dist.destroy_process_group()


def train_config(args: argparse.Namespace) -> TrainConfig:
    """The --preset's TrainConfig with --config's [train] table and the flags over it."""
    from symlearn.config_file import flat_overrides
    from symlearn.learning.training import TrainConfig

    flags = {k: v for k, v in dict(epochs=args.epochs, seed=args.seed).items() if v is not None}
    if args.no_attention:
        flags["attention"] = False
    return config_from_file(args, "train",  # [train] and [train.model]
                            lambda v: TrainConfig.from_preset(args.preset, **{**flat_overrides(v), **flags}))


def cmd_train(args: argparse.Namespace) -> int:
    from symlearn.learning.training import train

    cfg = train_config(args)
    folder_output(Path(args.out), "--out")
    set_threads(args.threads)
    joined = _init_distributed()
    print(f"train: preset {cfg.preset}, {cfg.epochs} epochs, seed {cfg.seed}, attention {cfg.model.attention} "
          f"-> {args.out}", file=sys.stderr)
    finished = False
    try:
        out = train(Path(args.data), Path(args.out), cfg, resume=not args.no_resume, show_progress=not args.quiet)
        finished = True
    finally:
        if joined:
            _leave_distributed(finished)
    last = out["history"][-1] if out["history"] else {}
    print(json.dumps({"run": args.out, "best_val_loss": out["best_val_loss"], "last_epoch": last}, indent=2,
                     allow_nan=False))
    return 0


def cmd_evaluate(args: argparse.Namespace) -> int:
    from symlearn.learning.evaluation import evaluate, format_table

    res = evaluate(Path(args.run), Path(args.data), Path(args.baseline_run) if args.baseline_run else None)
    print(format_table(res))
    print(f"wrote {Path(args.run) / 'eval.json'}")
    return 0


def cmd_table1(args: argparse.Namespace) -> int:
    from symlearn.learning.table1 import format_table1, table1

    res = table1(Path(args.run))
    print(format_table1(res))
    print(f"mean absolute error mm {res['mean_abs_error_mm']}; wrote {Path(args.run) / 'table1.json'}")
    return 0


def cmd_symbols(args: argparse.Namespace) -> int:
    from symlearn.symbolic.symbols import analyse_symbols

    given = {} if args.min_count is None else {"min_count": args.min_count}  # else the library's default
    res = analyse_symbols(Path(args.run), Path(args.data), symbol=args.symbol, **given)
    print(f"{res['n_objects']} training objects, {res['n_distinct']} distinct symbols, "
          f"{res['n_symbols_for_95pct']} cover 95%; weighted type purity {res['weighted_type_purity']}, "
          f"moved-when-picked purity {res.get('weighted_moved_purity')}")
    print(f"{'symbol':>10} {'count':>7} {'x px':>6} {'y px':>6} {'cube':>6} {'picked':>7} {'moved':>6}")
    for r in res["symbols"][:20]:
        mv = "-" if r["moved_when_picked"] is None else f"{r['moved_when_picked']:.2f}"
        print(f"{r['code']:>10} {r['count']:7d} {r['mean_x_px']:6.0f} {r['mean_y_px']:6.0f} "
              f"{r['cube_fraction']:6.2f} {r['times_picked']:7d} {mv:>6}")
    print(f"wrote symbols.json, symbols.png and symbol_examples.png (symbol {res['example_symbol']}) in {args.run}")
    return 0


def lifted_config(args: argparse.Namespace) -> LiftedConfig:
    """The --preset's LiftedConfig with --config's [lifted] table over it."""
    from symlearn.config_file import replace_nested
    from symlearn.export.lifted_export import LIFTED_PRESETS

    return config_from_file(args, "lifted", lambda v: replace_nested(LIFTED_PRESETS[args.preset], v))


def cmd_export_lifted(args: argparse.Namespace) -> int:
    from symlearn.export.lifted_export import (LIFTED_DIR, LIFTED_FILE, MAX_DATA_OBJECTS, export_lifted,
                                                 export_paths, write_problem_folder)
    from symlearn.problems.problem import load_problems

    cfg = lifted_config(args)
    out = Path(args.out) if args.out else None
    folders = export_paths(Path(args.run), out, [Path(d) for d in args.problems or []])  # every output, first
    for d in folders:
        load_problems(d)  # a missing, empty or malformed problem set is refused before any work
    set_threads(args.threads)
    rep = export_lifted(Path(args.run), Path(args.data[0]), tuple(Path(d) for d in args.data[1:]), cfg, out)
    where = out or Path(args.run) / "pddl"
    print(f"kept learned bits {rep['kept_bits']} (bits {rep['position_bits']} track the location); "
          f"{rep['moves']} moves on training scenes ({rep['config']['source']} outcomes) -> {rep['rules']} lifted rules "
          f"({rep['domain_bytes']} bytes of PDDL)")
    for data, checks in rep["checks_test_split"].items():
        for group, c in checks.items():
            print(f"  {data} test split, {group} objects ({c['cases']} steps): fidelity to m(z) "
                  f"{c['fidelity_to_net']:.3f}; accuracy against what was observed: rules {c['accuracy_rules']:.3f}, "
                  f"m(z) {c['accuracy_net']:.3f}; where they disagree ({c['disagree']}) the world sides with the rules "
                  f"{c['world_sides_with_rules']} times, with m(z) {c['world_sides_with_net']}")
    print(f"wrote {where / LIFTED_DIR / 'domain.pddl'} and {where / LIFTED_FILE}")
    for d, folder in folders.items():
        index = write_problem_folder(Path(args.run), d, folder, pddl_dir=out)
        print(f"wrote {folder}: domain.pddl and {len(index['problems'])} problems (p01.pddl ...), index.json")
        if index["zero_shot"]:
            print(f"warning: {len(index['zero_shot'])} problems of {d} have more than {MAX_DATA_OBJECTS} objects, "
                  f"more than any scene the rules were distilled from", file=sys.stderr)
    return 0


def cmd_export_pddl(args: argparse.Namespace) -> int:
    from symlearn.config_file import replace_nested
    from symlearn.export.rules_export import ExportConfig, export_pddl

    if not args.rules:
        return cmd_export_lifted(args)
    if args.problems:
        raise ValueError("--problems writes problem folders of the lifted domain; --rules does not")
    if args.preset != LIFTED_DEFAULT:
        raise ValueError(f"--preset {args.preset} chooses the lifted domain's settings; --rules takes [export] ones")
    cfg = config_from_file(args, "export", lambda v: replace_nested(ExportConfig(), v))
    out = folder_output(Path(args.out), "--out") if args.out else None  # before hours of enumeration
    set_threads(args.threads)
    rep = export_pddl(Path(args.run), Path(args.data[0]), cfg, out, extra_data=tuple(Path(d) for d in args.data[1:]))
    where = out or Path(args.run) / "pddl"
    print(f"vocabulary {rep['vocabulary_size']} codes; {rep['n_enumerated_cases']} enumerated cases at "
          f"{rep['enumeration_queries_per_s']:.0f} queries/s; rules {rep['n_rules_before_generalization']} -> "
          f"{rep['n_rules']} after generalization over {rep['n_actions_with_rules']} actions")
    through = (f"({rep['pddl_fidelity_cases']} sampled cases) {rep['pddl_fidelity']}"
               if rep["pddl_fidelity"] is not None else "not measured (pddl_fidelity_cases = 0)")
    print(f"fidelity (rules, every case) {rep['fidelity']:.4f}; through the PDDL {through}")
    for d in rep["disagreements"][:5]:
        print(f"  disagreement: {d}")
    oc = rep["outcomes"]
    print(f"second outcomes (at least {oc['min_ratio']} as likely): {oc['n_alternatives']} alternatives, "
          f"{oc['n_rules']} rules, fidelity {oc['fidelity']:.4f}")
    print(f"wrote {where / 'domain.pddl'}, rules.json, outcomes.json, report.json")
    return 0


def add_collect_command(sub) -> None:
    """Add `collect` to the CLI's sub-parsers."""
    c = sub.add_parser("collect", help="collect interaction data in the simulator")
    c.add_argument("--out", required=True, help="data set directory (created, or resumed)")
    c.add_argument("--n", type=positive_int, help="number of samples (actions; default 12000)")
    c.add_argument("--seed", type=non_negative_int, help="default 0")
    c.add_argument("--objects", type=int_range, default=None,
                   help="objects per scene, e.g. 4-5 (default: the paper's mix of 1-3)")
    c.add_argument("--workers", type=positive_int, default=1,
                   help="worker processes (with --ray: shards in flight at once, and a local Ray's CPUs)")
    add_ray_flag(c, "shard")
    add_config_flag(c, "[collect] (CollectConfig: shard_size, [collect.exploration], [collect.sim]; carrying scenes: "
                       "[collect.exploration] scene_draw = \"far-stick\", episode_lengths = [4])")
    c.add_argument("--quiet", action="store_true", help="no progress bar")
    c.set_defaults(func=cmd_collect)


def add_scenarios_command(sub) -> None:
    """Add `scenarios` to the CLI's sub-parsers."""
    s = sub.add_parser("scenarios", help="run the named physics scenarios and print their effects")
    s.add_argument("names", nargs="*", help="scenario names (default: all)")
    s.add_argument("--json", action="store_true", help="print JSON")
    s.add_argument("--gui", action="store_true", help="watch in pybullet's GUI")
    s.set_defaults(func=cmd_scenarios)


def add_train_command(sub) -> None:
    """Add `train` to the CLI's sub-parsers."""
    t = sub.add_parser("train", help="train the attentive effect model (runs under torchrun too)")
    t.add_argument("--data", required=True)
    t.add_argument("--out", required=True, help="run directory (resumed if it holds the same run)")
    add_preset_flag(t, "symlearn.learning.training:TRAIN_PRESETS", RECIPE,
                    "one of %(choices)s (symlearn/learning/training.py, TRAIN_PRESETS): recommended (default): the "
                    "quick sizes, the stability loss and the action on the held object's token, the recipe that "
                    "plans best; quick: the small model alone; paper: the paper's sizes and schedule")
    add_config_flag(t, "[train] (TrainConfig) and [train.model] (ModelConfig), e.g. batch_size, lr, bf16, "
                       "stability_weight, rider_weight, bits")
    t.add_argument("--epochs", type=positive_int)
    t.add_argument("--seed", type=non_negative_int)
    t.add_argument("--no-attention", action="store_true", help="the DeepSym baseline without attention")
    t.add_argument("--no-resume", action="store_true", help="start over even if RUN/last.pt exists")
    t.add_argument("--threads", type=thread_count, help="CPU threads; use 1 per process when the cores are shared "
                   "(OpenMP threads that wait for busy cores slow training several-fold)")
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(func=cmd_train)


def add_analysis_commands(sub) -> None:
    """Add `evaluate`, `table1` and `symbols` (reports on a trained run) to the CLI's sub-parsers."""
    e = sub.add_parser("evaluate", help="effect errors on the test split, with ablation rows")
    e.add_argument("--run", required=True)
    e.add_argument("--data", required=True)
    e.add_argument("--baseline-run", help="a run trained with --no-attention, for the ablation row")
    e.set_defaults(func=cmd_evaluate)

    t1 = sub.add_parser("table1", help="the paper's Table I: predicted vs true effects in three stick cases")
    t1.add_argument("--run", required=True)
    t1.set_defaults(func=cmd_table1)

    sy = sub.add_parser("symbols", help="symbol counts, prototypes (Fig. 4), examples (Fig. 5) and purity")
    sy.add_argument("--run", required=True)
    sy.add_argument("--data", required=True)
    sy.add_argument("--symbol", help="bit string of the symbol to show examples of")
    sy.add_argument("--min-count", type=positive_int,
                    help="a symbol is frequent from this many objects (default symbols.FREQUENT_MIN_COUNT, 100)")
    sy.set_defaults(func=cmd_symbols)


def add_export_pddl_command(sub) -> None:
    """Add `export-pddl` to the CLI's sub-parsers."""
    x = sub.add_parser("export-pddl", help="distil the transition network into PDDL: the lifted domain (default) "
                                           "or the rules over whole codes (--rules)")
    x.add_argument("--run", required=True)
    x.add_argument("--data", required=True, nargs="+", metavar="DIR",
                   help="the data sets whose training scenes m(z) is asked about: the first is the main set, the "
                        "others' training scenes (and, with --rules, codes) join it")
    x.add_argument("--out", help="output directory (default RUN/pddl)")
    x.add_argument("--rules", action="store_true",
                   help="the rules over whole codes (rules.json, outcomes.json, domain.pddl; read by the rules-* and "
                        "unified-planning planners) instead of the lifted domain (lifted.json, lifted/domain.pddl: typed STRIPS "
                        "schemas; needs m(z) on 9 location bits, docs/DOMAIN.md)")
    x.add_argument("--problems", nargs="+", metavar="DIR",
                   help="lifted domain: also write each problem set as a standalone folder "
                        "(RUN/pddl/lifted/SET/domain.pddl, p01.pddl, ..., index.json)")
    add_config_flag(x, "[lifted] (LiftedConfig: min_count, rider_min_count) or, with --rules, [export] "
                       "(ExportConfig: max_objects, min_count, scenes, larger_scenes, pddl_fidelity_cases, ...)")
    add_preset_flag(x, "symlearn.export.lifted_export:LIFTED_PRESETS", LIFTED_DEFAULT,
                    "lifted domain, one of %(choices)s (symlearn/export/lifted_export.py, LIFTED_PRESETS): fast "
                    "(default: LiftedConfig's own values, the rules Fast Downward translates fastest), accurate "
                    "(also rarer structures, rarer cube structures pooled, and picks at a stick's end: closer to "
                    "what the robot saw than m(z) on 1-5-object scenes, about 2x Fast Downward's time; "
                    "docs/DOMAIN.md) or small (fast for a data set of a few thousand samples, as the demo's: a "
                    "structure seen 3 times becomes a rule); [lifted] settings apply on top")
    x.add_argument("--threads", type=thread_count, help=THREADS_HELP)
    x.set_defaults(func=cmd_export_pddl)


def build_parser() -> argparse.ArgumentParser:
    """The `symlearn` parser with every sub-command, in the order `symlearn --help` lists them; refusals are one line."""
    p = OneLineParser(prog="symlearn", description="Learn planning symbols from robot interaction.")
    sub = p.add_subparsers(dest="command", required=True)
    add_collect_command(sub)
    add_scenarios_command(sub)
    add_train_command(sub)
    add_relations_commands(sub)
    add_analysis_commands(sub)
    add_export_pddl_command(sub)
    add_planning_commands(sub)
    add_report_command(sub)
    add_plots_command(sub)
    add_pipeline_command(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, RuntimeError, OSError) as e:
        print(f"symlearn {args.command}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:  # Ctrl-C, SIGINT / SIGTERM turned into CollectInterrupted, PlannerInterrupted
        why = f" ({e})" if str(e) else ""
        print(f"symlearn {args.command}: interrupted{why}; re-run the same command to resume", file=sys.stderr)
        return 128 + getattr(e, "signum", 2)


if __name__ == "__main__":
    sys.exit(main())
