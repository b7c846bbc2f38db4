"""`symlearn train-relations` and `symlearn relations`: the learned relational model and its probe.

    symlearn train-relations --data data/paper_a data/k15 --out RUN --epochs 20 --threads 2
    symlearn relations --run RUN --data data/k15          # what each relation head was found to mean
    symlearn carrying --run RUN                           # Table I and its variants, predicted and executed
    symlearn export-learned --run RUN --data data/paper_a data/k15   # RUN/learned/domain.pddl
    symlearn benchmark-learned --run RUN --problems DIR --out FILE  # closed loop with stock Fast Downward
    symlearn export-learned-problems --run RUN --problems DIR --out OUT   # OUT/*.pddl for planners outside
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from symlearn.cli.args import (add_config_flag, config_from_file, non_negative_int, positive_int, set_threads,
                               thread_count)
from symlearn.outputs import folder_output

# the keys of symlearn.learning.relational_training.TRAIN_PRESETS, written here so that the CLI loads without torch
TRAIN_PRESET_NAMES = ("attention", "support", "support-post", "support-exclusive", "cover", "cover-carry",
                      "cover-carry-stable", "effect")


def cmd_train_relations(args: argparse.Namespace) -> int:
    from symlearn.learning.relational_training import RelationalTrainConfig, train_relations

    overrides = {k: v for k, v in dict(epochs=args.epochs, seed=args.seed).items() if v is not None}
    cfg = RelationalTrainConfig.from_preset(args.preset, **overrides)
    for d in args.data:
        if not (Path(d) / "manifest.json").is_file():
            raise ValueError(f"{d}: not a data set folder (no manifest.json); make one with symlearn collect")
    folder_output(Path(args.out), "--out")
    set_threads(args.threads)
    print(f"train-relations: {cfg.epochs} epochs, seed {cfg.seed} -> {args.out}", file=sys.stderr)
    out = train_relations([Path(d) for d in args.data], Path(args.out), cfg, show=not args.quiet,
                          init=Path(args.init) if args.init else None)
    print(json.dumps({"run": args.out, "best_val_loss": out["best_val"], "last_epoch": out["history"][-1]}, indent=2))
    return 0


def cmd_relations(args: argparse.Namespace) -> int:
    from symlearn.learning.relation_probe import format_probe, probe
    from pddl_export.files import atomic_write_json

    res = probe(Path(args.run), [Path(d) for d in args.data], args.split)
    print(format_probe(res))
    atomic_write_json(Path(args.run) / "relations_probe.json", res)
    print(f"wrote {Path(args.run) / 'relations_probe.json'}")
    return 0


def cmd_carrying(args: argparse.Namespace) -> int:
    from symlearn.learning.carrying import carrying
    from pddl_export.files import atomic_write_json

    res = carrying(Path(args.run))
    from symlearn.export.learned_export import operators_path

    if operators_path(Path(args.run)).is_file():  # the carrying goals, planned and executed
        from symlearn.planning.learned_benchmark import carry_goals

        relations = tuple(args.goal_relations or ())
        res["goals"] = carry_goals(Path(args.run), relations, relax_unreachable=bool(relations))
        for g in res["goals"]:
            print(f"goal {g['name']}: {'built' if g['success'] else 'not built'} with actions {g['actions']} "
                  f"({g['stop']})")
    for r in res["probes"]:
        print(f"{r['name']:<18} " + "  ".join(f"{o['type']}: {'ok' if o['right'] else 'WRONG'} "
                                              f"(pred {o['predicted_mm'][:2]}, truth {o['truth_mm'][:2]})"
                                              for o in r["objects"]))
    print(f"Table I objects right {res['table1_right']}; all {res['all_right']}; riders {res['riders_right']}")
    atomic_write_json(Path(args.run) / "carrying.json", res)
    return 0


def cmd_export_learned(args: argparse.Namespace) -> int:
    from symlearn.export.learned_export import LearnedExportConfig, export_learned

    given = {} if args.min_count is None else {"min_count": args.min_count}
    cfg = LearnedExportConfig.from_preset(args.preset, **given)
    set_threads(args.threads)
    rep = export_learned(Path(args.run), [Path(d) for d in args.data], cfg)
    print(json.dumps({k: rep[k] for k in ("operators", "min_count", "transitions")}))
    return 0


def loop_config(args: argparse.Namespace):
    """The learned route's loop settings (LearnedLoopConfig): --config's [learned_loop] table over the defaults, and
    the flags given over it (--goal-relations also plans a goal proved unreachable for its `at` atoms)."""
    from symlearn.config_file import replace_nested
    from symlearn.planning.learned_loop import LearnedLoopConfig

    flags = {k: v for k, v in dict(planner=args.planner, timeout_s=args.timeout).items() if v is not None}
    if args.goal_relations is not None:
        flags |= dict(goal_relations=tuple(args.goal_relations), relax_unreachable=bool(args.goal_relations))
    return config_from_file(args, "learned_loop", lambda v: replace_nested(LearnedLoopConfig(), {**v, **flags}))


def cmd_benchmark_learned(args: argparse.Namespace) -> int:
    from symlearn.planning.learned_benchmark import benchmark_learned

    cfg = loop_config(args)
    set_threads(args.threads)
    res = benchmark_learned(Path(args.run), Path(args.problems), Path(args.out), cfg)
    print(json.dumps(res["summary"], indent=1))
    return 0


def cmd_export_learned_problems(args: argparse.Namespace) -> int:
    from symlearn.planning.learned_problems import export_learned_problems

    set_threads(args.threads)
    man = export_learned_problems(Path(args.run), Path(args.problems), Path(args.out),
                                  tuple(args.goal_relations or ()), focus=args.focus,
                                  equality=not args.no_equality)
    believed = sum(r["goal_believed_reached"] for r in man["rows"])
    focused = sum("focus_file" in r for r in man["rows"])
    print(f"{len(man['rows'])} problems written to {args.out} (domain.pddl, NAME.pddl, problems.json"
          + (f", focus/NAME.pddl for {focused}" if args.focus else "")
          + f"); {believed} goals already hold in the initial state as read")
    return 0


def add_relations_commands(sub) -> None:
    """Add `train-relations` and `relations` to the CLI's sub-parsers."""
    t = sub.add_parser("train-relations", help="train the relational effect model: unary and relational bits "
                                               "over objects and table locations, learned by effect prediction")
    t.add_argument("--data", required=True, nargs="+", help="one or more data sets (symlearn collect)")
    t.add_argument("--out", required=True, help="run directory (resumed if it holds the same run)")
    t.add_argument("--preset", default="attention", choices=sorted(TRAIN_PRESET_NAMES),
                   help="attention: three free object-object heads; support: one rests-on head; support-post: "
                        "and its reading after the action; support-exclusive: and one object on each "
                        "cover: and at(o, l) for every cell whose pick lifts o; cover-carry: and an object seen "
                        "carrying two riders may hold both; cover-carry-stable: and unary codes kept across "
                        "the action (docs/RELATIONS.md; default attention)")
    t.add_argument("--epochs", type=positive_int, help="default 30")
    t.add_argument("--init", help="start a new run from the weights of this run's relations.pt (same preset)")
    t.add_argument("--seed", type=non_negative_int, help="default 0")
    t.add_argument("--threads", type=thread_count, help="CPU threads")
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(func=cmd_train_relations)

    r = sub.add_parser("relations", help="what each learned relation means: its bits against at/on read from "
                                         "the data set's recorded poses (analysis only)")
    r.add_argument("--run", required=True, help="a run of train-relations")
    r.add_argument("--data", required=True, nargs="+")
    r.add_argument("--split", default="val", choices=("train", "val", "test"))
    r.set_defaults(func=cmd_relations)

    c = sub.add_parser("carrying", help="Table I and carrying variants: the relational model's predictions "
                                        "against the simulator's")
    c.add_argument("--run", required=True)
    c.add_argument("--goal-relations", nargs="*", help="with RUN/learned/: object-object heads the goals keep (and "
                                                       "the relaxation benchmark-learned --help describes)")
    c.set_defaults(func=cmd_carrying)

    x = sub.add_parser("export-learned", help="operators over the learned predicates, found from data, as PDDL "
                                              "(RUN/learned/domain.pddl)")
    x.add_argument("--run", required=True)
    x.add_argument("--data", required=True, nargs="+")
    x.add_argument("--preset", default="intersection", choices=("intersection", "precise", "placed", "carry",
                                                                    "carry-two"),
                   help="intersection: preconditions every group member holds; precise: for a noisy rests-on head; "
                        "placed: and an operator per place for an effect naming other locations (a cover model); "
                        "carry: and each such operator judged on the data at its place, no deleted atom dropped from "
                        "a precondition (a carrying model); "
                        "carry-two: and a stick carrying two riders from 10 transitions "
                        "(learned_export.EXPORT_PRESETS; default intersection)")
    x.add_argument("--min-count", type=positive_int, help="drop a lifted effect seen fewer times (default "
                                                          "learned_export.MIN_COUNT)")
    x.add_argument("--threads", type=thread_count)
    x.set_defaults(func=cmd_export_learned)

    b = sub.add_parser("benchmark-learned", help="the learned route closed loop in simulation: observe, learned "
                                                 "state, stock Fast Downward, act, repeat")
    b.add_argument("--run", required=True)
    b.add_argument("--problems", required=True)
    b.add_argument("--out", required=True, help="result JSON file (resumed: finished problems are kept)")
    b.add_argument("--timeout", type=float, help="seconds per planner call (default: LearnedLoopConfig's, 10)")
    b.add_argument("--planner", help="the stock planner configuration of each call: fd-lmcut (LearnedLoopConfig's "
                                     "default), fd-lama-first, ... (search.stock_planners.STOCK_PLANNERS)")
    b.add_argument("--goal-relations", nargs="*", help="object-object heads the goal keeps, e.g. on; with any, a "
                   "goal proved unreachable or unsolved in 0.6 of the time limit is planned for its at atoms "
                   "(learned_loop.relaxed_goal) in the time left")
    add_config_flag(b, "[learned_loop] (LearnedLoopConfig: drop, the ablation's predicates, e.g. [\"on\", "
                       "\"clear\", \"on-table\"]; monitor; unary; shorten_s; focus; max_steps_factor)")
    b.add_argument("--threads", type=thread_count)
    b.set_defaults(func=cmd_benchmark_learned)

    q = sub.add_parser("export-learned-problems", help="a problem set read by the learned model, written as PDDL "
                       "problems of RUN/learned/domain.pddl (OUT/*.pddl, OUT/problems.json with shortest lengths)")
    q.add_argument("--run", required=True)
    q.add_argument("--problems", required=True, help="a folder of symlearn problems (symlearn problems)")
    q.add_argument("--out", required=True, help="a new folder (never written over)")
    q.add_argument("--goal-relations", nargs="*", help="object-object relations the goals keep beside at, e.g. on")
    q.add_argument("--focus", action="store_true", help="also write OUT/focus/NAME.pddl over the objects the goal "
                   "needs alone (the closed loop's first call): each of its plans is a plan of OUT/NAME.pddl")
    q.add_argument("--no-equality", action="store_true", help="write the domain in plain typed STRIPS, "
                   "(differ ?a ?b) and (same ?to l1) for (not (= ?a ?b)) and (= ?to l1), with those static facts in "
                   "each problem: for planners whose parser takes no = (stock pyperplan)")
    q.add_argument("--threads", type=thread_count)
    q.set_defaults(func=cmd_export_learned_problems)
