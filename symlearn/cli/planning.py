"""Planning sub-commands of the `symlearn` CLI: train-transition, problems, plan, benchmark.

symlearn.cli.main's build_parser calls `add_planning_commands(sub)`; each command maps its flags onto
a config and calls one library function, returning an exit code. Errors are raised as
ValueError / RuntimeError with one-line messages, which the main CLI prints.

    symlearn train-transition --run runs/paper --data data/paper --preset paper
    symlearn problems --out problems/p13 --n 50 --objects 1-3 --length 1-4 --seed 0
    symlearn problems --suite structures --out problems/structures --n 22 --objects 1-5 --seed 0
    symlearn problems --stratify --out problems/dev --n 10 --objects 1-5 --seed 1000
    symlearn problems --annotate --out problems/p13
    symlearn problems --goal examples/goals/fig6_composite.json --out problems/goals
    symlearn plan --run runs/paper --problem problems/p13/problem_0000.json --planner astar --closed-loop
    symlearn benchmark --run runs/paper --problems problems/p13 --planners astar,astar-ucs --out bench.json
    symlearn benchmark --run runs/paper --problems problems/grid --planners astar,symk-sas --out g.json --plots plots/
    symlearn benchmark --run runs/paper --problems problems/grid --planners astar --out g.json --engine ray --workers 8

`problems` records its settings in OUT/problems.manifest: the same command again completes an
interrupted set, other settings are refused unless --overwrite. `benchmark` appends every finished
row to OUT.rows.jsonl: the same command again after a kill resumes there (other settings are refused).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from symlearn.cli.args import (THREADS_HELP, add_engine_flags, int_range, non_negative_int, planner_list,
                               positive_finite_float, positive_int, set_threads, thread_count)
from symlearn.planning.planner_catalogue import DEFAULT_PLANNER, planners_help
from symlearn.symbolic.locations import DEFAULT_LOCATION_BITS, LOCATION_BITS


MAX_TIMEOUT_S = 86_400.0  # one day: larger values are typos, and the SAS+ planners need a finite limit


def timeout_seconds(text: str) -> float:
    """argparse type: a finite number of seconds in (0, MAX_TIMEOUT_S]; inf, nan, 0 and negatives are refused."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"timeout {text!r} is not a number of seconds") from None
    if not (math.isfinite(v) and 0 < v <= MAX_TIMEOUT_S):
        raise argparse.ArgumentTypeError(f"timeout {text!r} must be a finite number of seconds in (0, {MAX_TIMEOUT_S:g}]")
    return v


def cmd_train_transition(args: argparse.Namespace) -> int:
    from symlearn.symbolic.transition_model import TransitionConfig
    from symlearn.symbolic.transition_training import train_transition

    over = {k: v for k, v in (("epochs", args.epochs), ("copy_prior", args.copy_prior),
                              ("attention_rounds", args.attention_rounds), ("modes", args.modes),
                              ("location_bits", args.location_bits)) if v is not None}
    cfg = TransitionConfig.from_preset(args.preset, **over)
    set_threads(args.threads)
    located = f", {cfg.location_bits} location bits" if cfg.location_bits else ""
    modes = f", {cfg.modes} outcome modes" if cfg.modes > 1 else ""
    print(f"train-transition: preset {cfg.preset}, {cfg.attention_rounds} attention round(s){located}{modes}, "
          f"{cfg.epochs} epochs, seed {args.seed}, run {args.run}, "
          f"data {args.data}" + "".join(f" + {d}" for d in args.extra_data), file=sys.stderr)
    m = train_transition(Path(args.run), Path(args.data), cfg, seed=args.seed, show_progress=not args.quiet,
                         extra_data=tuple(Path(d) for d in args.extra_data))
    test = m["test"]
    out = {"run": args.run, "best_val_loss": m["best_val_loss"],
           "test": {k: test[k] for k in ("bit_accuracy", "object_accuracy", "scene_accuracy")},
           "rollout_scene_accuracy": {n: r["scene_accuracy"] for n, r in test["rollout"].items()}}
    if m["extra_test"]:
        out["extra_test_rollout_scene_accuracy"] = {d: {n: r["scene_accuracy"] for n, r in t["rollout"].items()}
                                                    for d, t in m["extra_test"].items()}
    print(json.dumps(out, indent=2))
    return 0


def cmd_problems(args: argparse.Namespace) -> int:
    from symlearn.planning.problem_generation import N_PROBLEMS, generate_problems

    if args.exclude and not args.stratify:
        raise ValueError("--exclude applies to --stratify sets only")
    if args.annotate:
        return _cmd_annotate(args)
    if args.suite or args.goal:
        for flag in ("stratify", "stratify_reference", "on_locations"):
            if getattr(args, flag):
                raise ValueError(f"--{flag.replace('_', '-')} applies to random-walk problems only")
        return _cmd_structure_problems(args)
    if args.stratify:
        return _cmd_stratified(args)
    args.n, args.objects = args.n or N_PROBLEMS, args.objects or (1, 3)
    args.length, args.seed = args.length or (1, 4), 0 if args.seed is None else args.seed
    per = " per cell" if args.stratify_reference else ""
    placed = ", goals on the table locations" if args.on_locations else ""
    print(f"problems: {args.n} problems{per}, objects {args.objects[0]}-{args.objects[1]}, length "
          f"{args.length[0]}-{args.length[1]}{placed}, seed {args.seed} -> {args.out}", file=sys.stderr)
    paths = generate_problems(Path(args.out), args.n, objects=args.objects, length=args.length, seed=args.seed,
                              overwrite=args.overwrite, stratify=args.stratify_reference,
                              on_locations=args.on_locations)
    print(f"wrote {len(paths)} problems to {args.out}")
    return 0


def _cmd_stratified(args: argparse.Namespace) -> int:
    """`problems --stratify`: --n problems per cell of objects x shortest-plan length, and per off-location cell."""
    from symlearn.planning.stratified import OBJECTS, PER_CELL, generate_stratified

    given = [f for f, v in (("--length", args.length), ("--on-locations", args.on_locations or None),
                            ("--stratify-reference", args.stratify_reference or None)) if v is not None]
    if given:
        raise ValueError(f"--stratify draws walks of every length and keeps off-location goals in their own "
                         f"cells; {', '.join(given)} do not apply")
    n, objects, seed = args.n or PER_CELL, args.objects or OBJECTS, 0 if args.seed is None else args.seed
    exclude = tuple(Path(x) for x in (args.exclude or "").split(",") if x.strip())
    print(f"problems: {n} problems per cell of objects {objects[0]}-{objects[1]} x shortest-plan length, "
          f"seed {seed}" + (f", none of {', '.join(map(str, exclude))}" if exclude else "") + f" -> {args.out}",
          file=sys.stderr)
    paths, cells = generate_stratified(Path(args.out), n, objects=objects, seed=seed, overwrite=args.overwrite,
                                       exclude=exclude, progress=lambda line: print(line, file=sys.stderr, flush=True))
    print("cells (objects, shortest-plan length: problems written/asked):")
    for c in cells:
        print("  " + c.line())
    print(f"wrote {len(paths)} problems to {args.out}")
    return 0


def _cmd_annotate(args: argparse.Namespace) -> int:
    """`problems --annotate --out DIR`: record the shortest plan in every problem file of DIR that lacks it."""
    from symlearn.planning.problem_generation import add_shortest_plans

    given = [f for f, v in (("--n", args.n), ("--objects", args.objects), ("--length", args.length),
                            ("--seed", args.seed), ("--suite", args.suite), ("--goal", args.goal)) if v is not None]
    given += [f for f, v in (("--stratify", args.stratify), ("--stratify-reference", args.stratify_reference),
                             ("--on-locations", args.on_locations), ("--overwrite", args.overwrite)) if v]
    if given:
        raise ValueError(f"--annotate adds shortest plans to the problems in --out; {', '.join(given)} do not apply")
    counts = add_shortest_plans(Path(args.out))
    print(f"{args.out}: {counts['annotated']} problems annotated, {counts['kept']} already were; shortest plans "
          f"known for {counts['known']}, undecided for {counts['undecided']}")
    return 0


def _cmd_structure_problems(args: argparse.Namespace) -> int:
    """`problems --suite structures` (named tasks) or `problems --goal FILE` (one problem from a goal file)."""
    from symlearn.planning.structure_suite import generate_structures, write_goal_problem

    if args.length is not None:
        raise ValueError("--length applies to random-walk problems only; --suite and --goal problems carry "
                         "their own reference plans")
    if args.goal:
        given = [f for f, v in (("--n", args.n), ("--objects", args.objects), ("--seed", args.seed)) if v is not None]
        if given:
            raise ValueError(f"--goal makes one problem from its file; {', '.join(given)} do not apply")
        path = write_goal_problem(Path(args.goal), Path(args.out), overwrite=args.overwrite)
        print(f"wrote {path}")
        return 0
    n, objects, seed = args.n or 20, args.objects or (1, 5), 0 if args.seed is None else args.seed
    print(f"problems: suite {args.suite}, {n} problems, objects {objects[0]}-{objects[1]}, seed {seed} -> {args.out}",
          file=sys.stderr)
    paths = generate_structures(Path(args.out), n, objects=objects, seed=seed, suite=args.suite,
                                overwrite=args.overwrite)
    print(f"wrote {len(paths)} problems to {args.out}")
    return 0


def note_rule_loading(run: Path, planners: list[str]) -> None:
    """Say on stderr which big rule files the planners read first: rules of 1-5-object scenes take 390 MB and 20 s
    on 2 cores, a silence a user could take for a hang."""
    from pddl_export.outcome_rules import OUTCOMES_FILE
    from pddl_export.rules_io import PDDL_DIR, RULES_FILE
    from symlearn.planning.planners import OUTCOME_RULES_PLANNER, planner_spec

    if not any(planner_spec(p).needs_rules for p in planners):
        return
    files = [RULES_FILE] + ([OUTCOMES_FILE] if OUTCOME_RULES_PLANNER in planners else [])
    paths = [run / PDDL_DIR / f for f in files if (run / PDDL_DIR / f).is_file()]
    megabytes = sum(p.stat().st_size for p in paths) / 1e6
    if megabytes >= 50:
        print(f"loading {' and '.join(str(p) for p in paths)} ({megabytes:.0f} MB)", file=sys.stderr)


def cmd_plan(args: argparse.Namespace) -> int:
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.planning.single import plan_problem

    set_threads(args.threads)
    note_rule_loading(Path(args.run), [args.planner])
    cfg = ExecutionConfig(closed_loop=args.closed_loop, max_replans=args.max_replans, timeout_s=args.timeout)
    done = plan_problem(Path(args.run), Path(args.problem), args.planner, cfg,
                        record=Path(args.record) if args.record else None, record_size=args.record_size,
                        risk_weight=args.risk_weight)
    problem, row = done.problem, done.row
    if done.gif is not None:
        print(f"wrote {done.gif} ({done.frames} frames) and {done.filmstrip}")
    if done.write_dir.exists():
        print(f"wrote {done.write_dir / 'problem.pddl'}")
    print(f"{problem.name} [{args.planner}{', closed loop' if row.closed_loop else ''}]: found {row.found} "
          f"({row.status}), length {row.plan_length} (generator {row.generator_length}), "
          f"time {row.planning_time_s:.3f} s, expansions {row.expansions}, success {row.success}, "
          f"symbolic match {row.symbolic_match}, max distance {row.max_distance_m} m, replans {row.replans}, "
          f"failure {row.failure_stage}")
    if row.status == "error":  # the planner could not run: not an answer about the problem
        print(f"symlearn plan: error: {args.planner} could not plan {problem.name}: {row.message}", file=sys.stderr)
        return 1
    return 0


def cmd_benchmark(args: argparse.Namespace) -> int:
    from symlearn.cluster import check_engine
    from symlearn.planning.benchmark import benchmark, format_goal_placement, format_table
    from symlearn.planning.benchmark_plots import format_grid, format_shortest_grid, write_plots

    from symlearn.outputs import distinct_outputs, folder_output

    check_engine(args.engine, args.address)  # before any work: a missing Ray is refused in one line
    if args.workers > 1 and args.engine != "ray":
        raise ValueError(f"--workers {args.workers}: the local engine runs rows one after another; add --engine ray")
    outputs = {"--out": Path(args.out), "--record": args.record, "--plots": args.plots}
    distinct_outputs({k: Path(v) for k, v in outputs.items() if v})  # --out and its row log: benchmark() checks
    if args.plots:
        folder_output(Path(args.plots), "--plots")
    set_threads(args.threads)
    note_rule_loading(Path(args.run), list(args.planners))
    res = benchmark(Path(args.run), args.problems, args.planners, Path(args.out), closed_loop=args.closed_loop,
                    timeout_s=args.timeout, max_replans=args.max_replans, show_progress=not args.quiet,
                    record_dir=Path(args.record) if args.record else None, risk_weight=args.risk_weight,
                    engine=args.engine, workers=args.workers, address=args.address)
    print(format_table(res))
    print(format_goal_placement(res))
    print()
    print(format_shortest_grid(res["shortest_grid"]))
    print()
    print("secondary view: by reference (generator) plan length")
    print(format_grid(res["grid"]))
    print(f"wrote {args.out}")
    if args.plots:
        for path in write_plots(res["grid"], Path(args.plots), res["shortest_grid"]):
            print(f"wrote {path}")
    return 0


def _size(text: str) -> tuple[int, int]:
    """'320x240' -> (320, 240), for argparse."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size {text!r} is not WIDTHxHEIGHT, e.g. 320x240") from None
    if not (16 <= w <= 4096 and 16 <= h <= 4096):
        raise argparse.ArgumentTypeError(f"size {text!r} must be between 16x16 and 4096x4096")
    return w, h


def add_train_transition_command(sub) -> None:
    """Add `train-transition` to the CLI's sub-parsers."""
    t = sub.add_parser("train-transition", help="train the symbolic transition model m(z) on a run's codes")
    t.add_argument("--run", required=True, help="run directory with the trained effect model (best.pt)")
    t.add_argument("--data", required=True, help="the data set to encode")
    t.add_argument("--extra-data", nargs="+", default=[], metavar="DIR",
                   help="more data sets whose train and val splits join m(z)'s (their test splits are reported apart)")
    t.add_argument("--preset", default="paper", choices=["paper", "quick"])
    t.add_argument("--epochs", type=int)
    t.add_argument("--copy-prior", type=float, help="logit bias toward keeping each input bit (preset's if unset)")
    t.add_argument("--attention-rounds", type=positive_int,
                   help="self-attention rounds over the scene (the paper and the presets: 1)")
    t.add_argument("--modes", type=positive_int,
                   help="whole-scene outcomes of a mixture m(z), which astar-outcomes follows (the paper: 1; "
                   "docs/DESIGN.md, 'Outcome modes')")
    t.add_argument("--location-bits", type=int, nargs="?", const=DEFAULT_LOCATION_BITS, choices=LOCATION_BITS,
                   metavar="N", help="codes end with N bits read from each crop's geometry: the nearest table "
                   "location, then whether (4), which way (5) or which way and how far (6) the object stands off "
                   "it; 7 (without N): whether, then its height in 5 cm layers; 9: which way and how far, then "
                   "the height (docs/DESIGN.md, 'Location bits')")
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--threads", type=thread_count, help=THREADS_HELP)
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(func=cmd_train_transition)


def add_problems_command(sub) -> None:
    """Add `problems` to the CLI's sub-parsers."""
    p = sub.add_parser("problems", help="generate planning problems (initial scene, goal scene) in the simulator")
    p.add_argument("--out", required=True, help="directory for the problem JSON files")
    p.add_argument("--n", type=positive_int, help="number of problems (default 20)")
    p.add_argument("--objects", type=int_range,
                   help="objects per scene, e.g. 1-3 or 4-5 (default 1-3; 1-5 with --suite)")
    p.add_argument("--length", type=int_range, help="generator actions per random-walk problem, e.g. 1-4 (default 1-4)")
    p.add_argument("--seed", type=non_negative_int, help="base seed (default 0)")
    p.add_argument("--stratify", action="store_true",
                   help="--n problems (default 10) per cell of object count x shortest-plan length (1-2, 3-4, 5-6, "
                        "7-8, 9-12 actions) within --objects (default 1-5), plus an off-location cell per object "
                        "count, drawn from random walks, structure tasks and walks aimed at deep states, named by "
                        "cell (k3_opt5-6_0007, k3_off_0001; docs/PROBLEMS.md)")
    p.add_argument("--exclude", help="with --stratify: problem sets (A,B) none of whose problems may be drawn "
                                     "again, e.g. the dev set when making the test set")
    p.add_argument("--stratify-reference", action="store_true",
                   help="--n random-walk problems per cell of object count x reference (walk) length bucket (1-2, "
                        "3-4, 5-6, 7-8 actions) within --objects and --length, named by cell (k3_len5-6_0007): "
                        "the older depth sets")
    p.add_argument("--annotate", action="store_true",
                   help="record the shortest plan (optimal_length) in every problem file of --out that lacks it, "
                        "e.g. sets made before it existed; nothing else changes")
    p.add_argument("--on-locations", action="store_true",
                   help="random walks only: redraw a walk whose goal leaves an object more than 5 cm from every table "
                        "location (a stick across two places), so every goal is one place-and-level symbols can name")
    kind = p.add_mutually_exclusive_group()
    kind.add_argument("--suite", choices=["structures"],
                      help="named structure tasks (towers, cubes on the stick, ...; docs/PROBLEMS.md) instead of "
                           "random walks")
    kind.add_argument("--goal", help="a goal file (docs/PROBLEMS.md): write one problem, OUT/<file stem>.json")
    p.add_argument("--overwrite", action="store_true",
                   help="remove the problem files already in --out first (without it, a folder holding problems "
                        "of other settings is refused; one of the same settings is completed)")
    p.set_defaults(func=cmd_problems)


def _add_execution_flags(c: argparse.ArgumentParser) -> None:
    """The execution flags `plan` and `benchmark` share."""
    c.add_argument("--closed-loop", action="store_true", help="replan when the scene departs from the prediction")
    c.add_argument("--max-replans", type=non_negative_int, default=3)
    c.add_argument("--timeout", type=timeout_seconds, default=30.0,
                   help=f"seconds per planner call, finite and in (0, {MAX_TIMEOUT_S:g}]")
    # search-time inference runs the networks on small batches, many times slower on 2 threads than on 1 when
    # another busy process shares the cores (docs/BENCHMARKS.md), so one thread unless asked for more
    c.add_argument("--threads", type=thread_count, default=1, help="torch CPU threads for the networks (default 1)")
    c.add_argument("--risk-weight", type=positive_finite_float, default=1.0,
                   help="astar-likely, astar-outcomes and rules-outcomes only: each action costs 1 + W * (-log "
                        "P(its predicted next state)) (rules-outcomes: W times a second outcome's extra -log P) "
                        "(default 1)")


def add_plan_command(sub) -> None:
    """Add `plan` to the CLI's sub-parsers."""
    c = sub.add_parser("plan", help="plan one problem with the learned symbols and execute it",
                       epilog=planners_help(), formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("--run", required=True, help="run directory with best.pt and transition.pt")
    c.add_argument("--problem", required=True, help="problem JSON file")
    c.add_argument("--planner", default=DEFAULT_PLANNER,
                   help=f"one planner of the list below (default {DEFAULT_PLANNER})")
    c.add_argument("--record", help="save the executed plan as this animated GIF (and a filmstrip .png beside it)")
    c.add_argument("--record-size", type=_size, default=(320, 240), help="recorded frame size WxH (default 320x240)")
    _add_execution_flags(c)
    c.set_defaults(func=cmd_plan)


def add_benchmark_command(sub) -> None:
    """Add `benchmark` to the CLI's sub-parsers."""
    c = sub.add_parser("benchmark", help="plan and execute every problem of a directory with several planners",
                       epilog=planners_help(), formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("--run", required=True, help="run directory with best.pt and transition.pt")
    c.add_argument("--problems", required=True,
                   help="folder of problem JSON files; several as A,B,C, or a folder whose subfolders are problem "
                        "sets (rows then carry the set's folder name)")
    c.add_argument("--planners", type=planner_list, default=[DEFAULT_PLANNER],
                   help=f"comma-separated planners of the list below (default {DEFAULT_PLANNER})")
    c.add_argument("--out", required=True, help="benchmark JSON file")
    c.add_argument("--plots", help="folder for the plots: success and executed / shortest plan length by objects x "
                                   "shortest-plan length, success and planning time by objects x reference length")
    c.add_argument("--quiet", action="store_true")
    c.add_argument("--record", help="directory for GIFs of failed plans (<problem>_<planner>.gif)")
    _add_execution_flags(c)
    add_engine_flags(c, "problem-planner pair")
    c.add_argument("--workers", type=positive_int, default=1,
                   help="with --engine ray: pairs in flight at once, and a local Ray's CPUs (default 1)")
    c.set_defaults(func=cmd_benchmark)


def add_planning_commands(sub) -> None:
    """Add train-transition, problems, plan and benchmark to the CLI's sub-parsers."""
    add_train_transition_command(sub)
    add_problems_command(sub)
    add_plan_command(sub)
    add_benchmark_command(sub)
