"""`symlearn pipeline`: every stage from collection to the report, resumable (logic in symlearn.pipeline, which
calls the library directly, never this command line).

    symlearn pipeline --out pipe                       # the recommended recipe at full scale
    symlearn pipeline --preset demo --out runs/demo    # the same recipe in minutes (make demo)
    symlearn pipeline --preset paper --out pipe --n 2000 --seed 0
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from symlearn.cli.args import add_config_flag, non_negative_int, positive_int
from symlearn.config_file import ConfigFileError, built, read_config_file
from symlearn.pipeline import run_pipeline, stage_configs
from symlearn.pipeline_presets import DEFAULT_PRESET, PRESETS, PipelineSettings

PRESETS_HELP = ("recommended (default): the recipe that plans best, at full scale (a paper-style data set and a "
                "1-5-object one, the stability-trained quick effect model, m(z) on 9 location bits, the lifted PDDL "
                "domain, problems by shortest-plan length, astar-outcomes and fast-downward-lifted closed loop); "
                "demo: the same recipe at a small scale, minutes on 2 cores (make demo); paper: the paper-faithful "
                "setup (its model sizes, learned codes only, the rules export, random-walk problems, open loop). "
                "symlearn/pipeline_presets.py names each stage's preset, defined beside its config class "
                "(docs/CONFIG.md)")


def cmd_pipeline(args: argparse.Namespace) -> int:
    s = PipelineSettings(preset=args.preset, out=Path(args.out), n=args.n, seed=args.seed, epochs=args.epochs,
                         problems=args.problems, workers=args.workers, overrides=read_config_file(args.config),
                         stop_after=args.stop_after)
    check_against_preset(s, args.config)
    run_pipeline(s, echo=lambda line: print(line, flush=True))
    print(f"wrote {s.out / 'pipeline.json'}; report at {s.out / 'run' / 'report.html'}")
    return 0


def check_against_preset(s: PipelineSettings, path: Path | str | None) -> None:
    """Refuse, in one line naming the settings file, the table and the key, a value that read_config_file accepted
    over a class's defaults but the preset's stage configs refuse (`[train.model] n_heads = 128` where the preset's
    d_model is 64): each table is tried alone over the preset (config_file.built finds the key); a refusal only the
    tables together make is named by the file."""
    try:
        stage_configs(s)
        return
    except (ValueError, TypeError) as e:
        together = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
    for table, values in s.overrides.items():
        built(path, table, values, lambda v, t=table: stage_configs(dataclasses.replace(s, overrides={t: v})))
    raise ConfigFileError(f"{path}: {together}" if path else together)


def add_pipeline_command(sub) -> None:
    """Add `pipeline` to the CLI's sub-parsers."""
    p = sub.add_parser("pipeline", help="run every stage (collect ... report) into one folder; resumes")
    p.add_argument("--preset", default=DEFAULT_PRESET, choices=list(PRESETS), help=PRESETS_HELP)
    p.add_argument("--out", required=True,
                   help="folder for data/, data_extra/, run/, problems/, logs/ and pipeline.json")
    # each value is checked here, before OUT is made, not first by the stage that uses it
    p.add_argument("--n", type=positive_int, help="samples of each collected set (preset's if unset)")
    p.add_argument("--seed", type=non_negative_int,
                   help="every stage's seed (if unset: a settings file's [collect], [train] or [export] seed for "
                        "its stage, else 0)")
    p.add_argument("--epochs", type=positive_int, help="effect model epochs (preset's if unset)")
    p.add_argument("--problems", type=positive_int,
                   help="planning problems to benchmark, per cell of objects x shortest-plan length with the "
                        "recommended and demo presets (preset's if unset)")
    p.add_argument("--workers", type=positive_int, default=1, help="collection worker processes")
    add_config_flag(p, "every table ([collect], [train], [transition], [lifted], [export], [problems], "
                       "[execution]), over the preset's values; recorded per stage in pipeline.json")
    p.add_argument("--stop-after", help=argparse.SUPPRESS)  # tests: simulate an interruption after a stage
    p.set_defaults(func=cmd_pipeline)
