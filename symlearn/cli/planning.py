"""Planning sub-commands of the `symlearn` CLI: train-transition, problems, plan, benchmark.

symlearn.cli.main's build_parser calls `add_planning_commands(sub)`; each command maps its flags onto
a config and calls one library function, returning an exit code. Errors are raised as
ValueError / RuntimeError with one-line messages, which the main CLI prints.

    symlearn train-transition --run runs/paper --data data/paper --preset paper
    symlearn problems --out problems/dev --n 10 --objects 1-5 --seed 1000
    symlearn problems --kind walks --out problems/p13 --n 50 --objects 1-3 --length 1-4 --seed 0
    symlearn problems --kind structures --out problems/structures --n 22 --objects 1-5 --seed 0
    symlearn problems --kind annotate --out problems/p13
    symlearn problems --out problems/goals examples/goals/fig6_composite.json
    symlearn plan --run runs/paper --problem problems/p13/problem_0000.json --planner astar
    symlearn benchmark --run runs/paper --problems problems/p13 --planners astar,astar-ucs --out bench.json
    symlearn benchmark --run runs/paper --problems problems/grid --planners astar --out g.json --ray --workers 8
    symlearn plots bench.json --out plots/

Every lever that is not a flag is a key of --config FILE.toml (symlearn.config_file; docs/CONFIG.md).
`problems` records its settings in OUT/problems.manifest: the same command again completes an
interrupted set, other settings are refused unless --overwrite. `benchmark` appends every finished
row to OUT.rows.jsonl: the same command again after a kill resumes there (other settings are refused).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from symlearn.cli.args import (THREADS_HELP, add_config_flag, add_preset_flag, add_ray_flag, config_from_file,
                               int_range, non_negative_int, planner_list, positive_int, ray_engine, set_threads, thread_count)
from symlearn.config_file import MAX_TIMEOUT_S, RECIPE, TIMEOUT_S
from symlearn.planning.planner_catalogue import DEFAULT_PLANNER, planners_help

if TYPE_CHECKING:  # the configs' modules load torch: imported where a command runs
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.symbolic.transition_model import TransitionConfig


def timeout_seconds(text: str) -> float:
    """argparse type: a finite number of seconds in (0, MAX_TIMEOUT_S], the bound of [execution] timeout_s too
    (config_file.TIMEOUT_S); inf, nan, 0 and negatives are refused."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"timeout {text!r} is not a number of seconds") from None
    if not TIMEOUT_S.holds(v):
        raise argparse.ArgumentTypeError(f"timeout {text!r} must be a finite number of seconds in (0, {MAX_TIMEOUT_S:g}]")
    return v


def transition_config(args: argparse.Namespace) -> TransitionConfig:
    """The --preset's TransitionConfig with --config's [transition] table over it."""
    from symlearn.symbolic.transition_model import TransitionConfig

    return config_from_file(args, "transition", lambda v: TransitionConfig.from_preset(args.preset, **v))


def cmd_train_transition(args: argparse.Namespace) -> int:
    from symlearn.symbolic.transition_training import train_transition

    cfg = transition_config(args)
    set_threads(args.threads)
    located = f", {cfg.location_bits} location bits" if cfg.location_bits else ""
    modes = f", {cfg.modes} outcome modes" if cfg.modes > 1 else ""
    print(f"train-transition: preset {cfg.preset}, {cfg.attention_rounds} attention round(s){located}{modes}, "
          f"{cfg.epochs} epochs, seed {args.seed}, run {args.run}, "
          f"data {' + '.join(args.data)}", file=sys.stderr)
    m = train_transition(Path(args.run), Path(args.data[0]), cfg, seed=args.seed, show_progress=not args.quiet,
                         extra_data=tuple(Path(d) for d in args.data[1:]))
    test = m["test"]
    out = {"run": args.run, "best_val_loss": m["best_val_loss"],
           "test": {k: test[k] for k in ("bit_accuracy", "object_accuracy", "scene_accuracy")},
           "rollout_scene_accuracy": {n: r["scene_accuracy"] for n, r in test["rollout"].items()}}
    if m["extra_test"]:
        out["extra_test_rollout_scene_accuracy"] = {d: {n: r["scene_accuracy"] for n, r in t["rollout"].items()}
                                                    for d, t in m["extra_test"].items()}
    print(json.dumps(out, indent=2))
    return 0


PROBLEM_KINDS = {
    "stratified": "--n problems (default 10) per cell of object count x shortest-plan length (1-2, 3-4, 5-6, 7-8, "
                  "9-12 actions) within --objects (default 1-5), plus an off-location cell per object count, named by "
                  "cell (k3_opt5-6_0007, k3_off_0001); the default",
    "walks": "--n random walks of --length generator actions (default 1-4) within --objects (default 1-3)",
    "located-walks": "walks, redrawn while the goal leaves an object more than 5 cm from every table location",
    "reference": "--n walks per cell of object count x walk length (1-2, 3-4, 5-6, 7-8): the older depth sets",
    "structures": "named structure tasks (towers, cubes on the stick, ...) within --objects (default 1-5)",
    "annotate": "record the shortest plan in every problem of --out that lacks it (sets made before it existed)",
}


def cmd_problems(args: argparse.Namespace) -> int:
    """`problems`: a set of the --kind asked for, or one problem per goal file."""
    kind = args.kind or ("goal" if args.goals else "stratified")
    if args.goals and kind != "goal":
        raise ValueError(f"goal files make one problem each; --kind {kind} does not apply")
    not_for = {"goal": ("--n", "--objects", "--length", "--seed", "--exclude"),
               "annotate": ("--n", "--objects", "--length", "--seed", "--exclude", "--overwrite"),
               "stratified": ("--length",), "structures": ("--length", "--exclude")}
    given = {"--n": args.n, "--objects": args.objects, "--length": args.length, "--seed": args.seed,
             "--exclude": args.exclude, "--overwrite": args.overwrite or None}
    wrong = [f for f in not_for.get(kind, ("--exclude",)) if given[f] is not None]
    if wrong:
        raise ValueError(f"{', '.join(wrong)} do{'es' if len(wrong) == 1 else ''} not apply to "
                         + ("goal files" if kind == "goal" else f"--kind {kind}"))
    if kind == "annotate":
        return _cmd_annotate(args)
    if kind in ("goal", "structures"):
        return _cmd_structure_problems(args)
    if kind == "stratified":
        return _cmd_stratified(args)
    return _cmd_walks(args, reference=kind == "reference", on_locations=kind == "located-walks")


def _cmd_walks(args: argparse.Namespace, reference: bool, on_locations: bool) -> int:
    """`problems --kind walks|located-walks|reference`: random-walk problems."""
    from symlearn.problems.problem_generation import N_PROBLEMS, ProblemConfig, generate_problems

    n, objects = args.n or N_PROBLEMS, args.objects or (1, 3)
    length, seed = args.length or (1, 4), args.seed or 0
    ProblemConfig(objects=objects, length=length)  # --objects, --length out of bounds: one line, before any work
    per = " per cell" if reference else ""
    placed = ", goals on the table locations" if on_locations else ""
    print(f"problems: {n} problems{per}, objects {objects[0]}-{objects[1]}, length {length[0]}-{length[1]}{placed}, "
          f"seed {seed} -> {args.out}", file=sys.stderr)
    paths = generate_problems(Path(args.out), n, objects=objects, length=length, seed=seed, overwrite=args.overwrite,
                              stratify=reference, on_locations=on_locations)
    print(f"wrote {len(paths)} problems to {args.out}")
    return 0


def _cmd_stratified(args: argparse.Namespace) -> int:
    """`problems` (--kind stratified): --n problems per cell of objects x shortest-plan length, and per
    off-location cell."""
    from symlearn.problems.stratified import OBJECTS, PER_CELL, generate_stratified

    n, objects, seed = args.n or PER_CELL, args.objects or OBJECTS, args.seed or 0
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
    """`problems --kind annotate --out DIR`: record the shortest plan in every problem file of DIR that lacks it."""
    from symlearn.problems.problem_generation import add_shortest_plans

    counts = add_shortest_plans(Path(args.out))
    print(f"{args.out}: {counts['annotated']} problems annotated, {counts['kept']} already were; shortest plans "
          f"known for {counts['known']}, undecided for {counts['undecided']}")
    return 0


def _cmd_structure_problems(args: argparse.Namespace) -> int:
    """`problems --kind structures` (named tasks) or `problems GOAL.json ...` (one problem per goal file)."""
    from symlearn.problems.structure_suite import generate_structures, write_goal_problem

    if args.goals:
        for goal in args.goals:
            print(f"wrote {write_goal_problem(Path(goal), Path(args.out), overwrite=args.overwrite)}")
        return 0
    n, objects, seed = args.n or 20, args.objects or (1, 5), args.seed or 0
    print(f"problems: structure tasks, {n} problems, objects {objects[0]}-{objects[1]}, seed {seed} -> {args.out}",
          file=sys.stderr)
    paths = generate_structures(Path(args.out), n, objects=objects, seed=seed, suite="structures",
                                overwrite=args.overwrite)
    print(f"wrote {len(paths)} problems to {args.out}")
    return 0


def note_rule_loading(run: Path, planners: list[str]) -> None:
    """Say on stderr which big rule files the planners read first: rules of 1-5-object scenes take 390 MB and 20 s
    on 2 cores, a silence a user could take for a hang."""
    from symlearn.planning.planner_catalogue import OUTCOMES, RULES, planner_entry

    files = sorted({f for p in planners for f in planner_entry(p).needs if f in (RULES, OUTCOMES)}, key=len)
    paths = [run / f for f in files if (run / f).is_file()]
    megabytes = sum(p.stat().st_size for p in paths) / 1e6
    if megabytes >= 50:
        print(f"loading {' and '.join(str(p) for p in paths)} ({megabytes:.0f} MB)", file=sys.stderr)


def execution_config(args: argparse.Namespace) -> ExecutionConfig:
    """The recipe's execution (ExecutionConfig(): closed loop, 10 s a call) with --config's
    [execution] table and --timeout over it."""
    from symlearn.config_file import replace_nested
    from symlearn.planning.execution import ExecutionConfig

    cfg = config_from_file(args, "execution", lambda v: replace_nested(ExecutionConfig(), v))
    return cfg if args.timeout is None else dataclasses.replace(cfg, timeout_s=args.timeout)


def planner_config(args: argparse.Namespace):
    """The planners' settings (PlannerConfig): --config's [planner] table over the defaults."""
    from symlearn.config_file import replace_nested
    from symlearn.planning.planner_catalogue import PlannerConfig

    return config_from_file(args, "planner", lambda v: replace_nested(PlannerConfig(), v))


def cmd_plan(args: argparse.Namespace) -> int:
    from symlearn.planning.plan_one import plan_problem

    cfg, planners = execution_config(args), planner_config(args)
    set_threads(args.threads)
    note_rule_loading(Path(args.run), [args.planner])
    done = plan_problem(Path(args.run), Path(args.problem), args.planner, cfg,
                        record=Path(args.record) if args.record else None, record_size=args.record_size,
                        planner_config=planners)
    problem, row = done.problem, done.row
    if done.gif is not None:
        print(f"wrote {done.gif} ({done.frames} frames) and {done.filmstrip}")
    if done.write_dir is not None:  # kept beside the recording; without one they went to a removed work folder
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
    from symlearn.planning.benchmark import benchmark
    from symlearn.planning.benchmark_summary import format_goal_placement, format_table
    from symlearn.planning.benchmark_plots import format_grid, format_shortest_grid

    cfg, planners = execution_config(args), planner_config(args)
    engine, address = ray_engine(args)
    check_engine(engine, address)  # before any work: a missing Ray is refused in one line
    if args.workers > 1 and engine != "ray":
        raise ValueError(f"--workers {args.workers}: this machine's rows run one after another; add --ray")
    # search-time inference runs the networks on small batches, many times slower on 2 threads than on 1 when
    # another busy process shares the cores (docs/BENCHMARKS.md): one thread a planning call, here and in Ray tasks
    set_threads(1)
    note_rule_loading(Path(args.run), list(args.planners))
    res = benchmark(Path(args.run), args.problems, args.planners, Path(args.out), execution=cfg, show_progress=True,
                    engine=engine, workers=args.workers, address=address, planner_config=planners)
    print(format_table(res))
    print(format_goal_placement(res))
    print()
    print(format_shortest_grid(res["shortest_grid"]))
    print()
    print("secondary view: by reference (generator) plan length")
    print(format_grid(res["grid"]))
    print(f"wrote {args.out} (plots: symlearn plots {args.out} --out DIR)")
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
    t.add_argument("--data", required=True, nargs="+", metavar="DIR",
                   help="the data sets to encode: the first is the main set, the others' train and val splits join "
                        "m(z)'s (their test splits are reported apart)")
    add_preset_flag(t, "symlearn.symbolic.transition_model:TRANSITION_PRESETS", RECIPE,
                    "one of %(choices)s (symlearn/symbolic/transition_model.py, TRANSITION_PRESETS): recommended "
                    "(default): the quick network on codes ending with 9 location bits, which the lifted domain "
                    "reads; quick: learned codes only; paper: the paper's layers")
    add_config_flag(t, "[transition] (TransitionConfig: epochs, copy_prior, attention_rounds, modes, "
                       "location_bits, ...; docs/DESIGN.md)")
    t.add_argument("--seed", type=non_negative_int, default=0)
    t.add_argument("--threads", type=thread_count, help=THREADS_HELP)
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(func=cmd_train_transition)


def add_problems_command(sub) -> None:
    """Add `problems` to the CLI's sub-parsers."""
    kinds = "; ".join(f"{k}: {v}" for k, v in PROBLEM_KINDS.items())
    p = sub.add_parser("problems", help="generate planning problems (initial scene, goal scene) in the simulator",
                       description=f"Kinds of problem set (--kind) -- {kinds}. docs/PROBLEMS.md has the details.")
    p.add_argument("goals", nargs="*", metavar="GOAL.json",
                   help="goal files (docs/PROBLEMS.md): write one problem each, OUT/<file stem>.json")
    p.add_argument("--out", required=True, help="directory for the problem JSON files")
    p.add_argument("--kind", choices=list(PROBLEM_KINDS), help="the kind of set (the description above)")
    p.add_argument("--n", type=positive_int, help="problems, per cell with stratified and reference")
    p.add_argument("--objects", type=int_range, help="objects per scene, e.g. 1-3 or 4-5")
    p.add_argument("--length", type=int_range, help="walks: generator actions per problem, e.g. 1-4")
    p.add_argument("--seed", type=non_negative_int, help="base seed (default 0)")
    p.add_argument("--exclude", help="stratified: problem sets (A,B) none of whose problems may be drawn again, e.g. "
                                     "the dev set when making the test set")
    p.add_argument("--overwrite", action="store_true",
                   help="remove the problem files already in --out first (without it, a folder holding problems "
                        "of other settings is refused; one of the same settings is completed)")
    p.set_defaults(func=cmd_problems)


def _add_execution_flags(c: argparse.ArgumentParser) -> None:
    """The execution flags `plan` and `benchmark` share."""
    c.add_argument("--timeout", type=timeout_seconds,
                   help=f"seconds per planner call, finite and in (0, {MAX_TIMEOUT_S:g}] (default: [execution] "
                        "timeout_s, else ExecutionConfig's, 10)")
    add_config_flag(c, "[execution] (ExecutionConfig: closed_loop, default true; max_replans; ...) and [planner] "
                       "(PlannerConfig: risk_weight, the weight W of astar-outcomes and rules-outcomes, an outcome "
                       "costing 1 + W * (-log P))")


def add_plan_command(sub) -> None:
    """Add `plan` to the CLI's sub-parsers."""
    c = sub.add_parser("plan", help="plan one problem with the learned symbols and execute it (closed loop)",
                       epilog=planners_help(), formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("--run", required=True, help="run directory with best.pt and transition.pt")
    c.add_argument("--problem", required=True, help="problem JSON file")
    c.add_argument("--planner", default=DEFAULT_PLANNER,
                   help=f"one planner of the list below (default {DEFAULT_PLANNER})")
    c.add_argument("--record", help="save the executed plan as this animated GIF (a filmstrip .png and the "
                   "planner's task files, NAME_tasks/, beside it)")
    c.add_argument("--record-size", type=_size, default=(320, 240), help="recorded frame size WxH (default 320x240)")
    _add_execution_flags(c)
    # search-time inference runs the networks on small batches, many times slower on 2 threads than on 1 when
    # another busy process shares the cores (docs/BENCHMARKS.md), so one thread unless asked for more
    c.add_argument("--threads", type=thread_count, default=1, help="torch CPU threads for the networks (default 1)")
    c.set_defaults(func=cmd_plan)


def add_benchmark_command(sub) -> None:
    """Add `benchmark` to the CLI's sub-parsers."""
    c = sub.add_parser("benchmark", help="plan and execute every problem of a directory with several planners "
                                         "(closed loop, one torch thread a call)",
                       epilog=planners_help(), formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("--run", required=True, help="run directory with best.pt and transition.pt")
    c.add_argument("--problems", required=True,
                   help="folder of problem JSON files; several as A,B,C, or a folder whose subfolders are problem "
                        "sets (rows then carry the set's folder name)")
    c.add_argument("--planners", type=planner_list, default=[DEFAULT_PLANNER],
                   help=f"comma-separated planners of the list below (default {DEFAULT_PLANNER})")
    c.add_argument("--out", required=True, help="benchmark JSON file (its plots: symlearn plots OUT --out DIR)")
    _add_execution_flags(c)
    add_ray_flag(c, "problem-planner pair")
    c.add_argument("--workers", type=positive_int, default=1,
                   help="with --ray: pairs in flight at once, and a local Ray's CPUs (default 1)")
    c.set_defaults(func=cmd_benchmark)


def add_planning_commands(sub) -> None:
    """Add train-transition, problems, plan and benchmark to the CLI's sub-parsers."""
    add_train_transition_command(sub)
    add_problems_command(sub)
    add_plan_command(sub)
    add_benchmark_command(sub)
