"""One settings object end to end (issue 58, item 1): the library's, the command line's and the pipeline's defaults
are one and the same, and each stage's presets are defined once, beside its config class, and named by the
pipeline's presets.

tests/pipeline_preset_configs.json holds every pipeline preset's stage configs as the code before the presets were
named (commit a196d4b) built them: the named presets must give each stage exactly those configs, so that
`symlearn pipeline --preset X` runs (and resumes) as it did.
"""
from __future__ import annotations

import dataclasses
import inspect
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PINNED = Path(__file__).resolve().parent / "pipeline_preset_configs.json"


def _parse(*argv: str):
    from symlearn.cli.main import build_parser

    return build_parser().parse_args(list(argv))


def _flag(command: str, dest: str):
    """The argparse action of `symlearn COMMAND`'s flag `dest`."""
    from symlearn.cli.main import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command").choices[command]
    return next(a for a in sub._actions if a.dest == dest)


def _stage_configs(preset: str) -> dict:
    from symlearn.pipeline import config_json, stage_configs
    from symlearn.pipeline_presets import PipelineSettings

    configs = stage_configs(PipelineSettings(out=Path("unused"), preset=preset))
    return {name: config_json(c) for name, c in configs.items()}


def _risk_weight_apart(configs: dict) -> dict:
    """risk_weight moved from the execution config to the planner config (issue 58, the planner registry): it is
    compared as the benchmark stage's own value, wherever it lives."""
    out = json.loads(json.dumps(configs))
    bench = out["benchmark"]
    weights = [part.pop("risk_weight") for part in (bench.get("execution", {}), bench.get("planner", {}))
               if "risk_weight" in part]
    if bench.get("planner") == {}:
        bench.pop("planner")
    assert len(weights) == 1  # in one place, never two
    bench["risk_weight"] = weights[0]
    return out


def test_every_pipeline_preset_gives_each_stage_the_configs_it_gave_before():
    import torch

    from symlearn.pipeline_presets import PRESETS

    pinned = json.loads(PINNED.read_text())
    assert set(PRESETS) == set(pinned) == {"recommended", "demo", "paper"}
    for preset, want in pinned.items():
        want = _risk_weight_apart(want)
        want["train"]["bf16"] = torch.cuda.is_available()  # the pipeline trains in bf16 on a GPU only
        got = _risk_weight_apart(_stage_configs(preset))
        assert list(got) == list(want), preset  # the same stages, in the same order
        for stage in want:
            assert got[stage] == want[stage], (preset, stage)


def test_pipeline_presets_name_the_stage_presets_defined_beside_their_configs():
    from symlearn.config_file import RECIPE
    from symlearn.export.lifted_export import LIFTED_PRESETS, LiftedConfig
    from symlearn.learning.training import TRAIN_PRESETS
    from symlearn.pipeline import stage_configs
    from symlearn.pipeline_presets import PRESETS, PipelinePreset, PipelineSettings
    from symlearn.planning.execution import EXECUTION_PRESETS
    from symlearn.symbolic.transition_model import TRANSITION_PRESETS

    # the pipeline's preset holds stage preset names and its own choices and sizes, no field of a stage config
    fields = {f.name for f in dataclasses.fields(PipelinePreset)}
    assert fields == {"train", "transition", "execution", "lifted", "stratified", "planners", "extra_objects",
                      "samples", "extra_samples", "epochs", "transition_epochs", "min_count", "problem_objects",
                      "problems"}
    for name, p in PRESETS.items():
        assert p.train in TRAIN_PRESETS and p.transition in TRANSITION_PRESETS and p.execution in EXECUTION_PRESETS
        assert p.lifted is None or p.lifted in LIFTED_PRESETS
        configs = stage_configs(PipelineSettings(out=Path("unused"), preset=name))
        assert configs["benchmark"].execution == EXECUTION_PRESETS[p.execution]  # the named preset, whole
        if p.lifted:
            assert configs["export-pddl"].lifted == LIFTED_PRESETS[p.lifted]
    assert (PRESETS["recommended"].execution, PRESETS["recommended"].lifted) == (RECIPE, "fast")
    assert (PRESETS["demo"].lifted, LIFTED_PRESETS["small"]) == ("small", LiftedConfig(min_count=3))
    assert EXECUTION_PRESETS["paper"].closed_loop is False and EXECUTION_PRESETS["paper"].timeout_s == 30.0


def test_cli_choices_are_the_preset_tables():
    from symlearn.export.lifted_export import LIFTED_PRESETS
    from symlearn.learning.training import TRAIN_PRESETS
    from symlearn.pipeline_presets import PRESETS
    from symlearn.symbolic.transition_model import TRANSITION_PRESETS

    for (command, table) in (("train", TRAIN_PRESETS), ("train-transition", TRANSITION_PRESETS),
                             ("export-pddl", LIFTED_PRESETS), ("pipeline", PRESETS)):
        assert list(_flag(command, "preset").choices) == list(table), command
    import symlearn.cli.args as args
    import symlearn.planning.execution as execution

    assert not hasattr(args, "TRAIN_PRESET_NAMES") and not hasattr(execution, "RECOMMENDED_EXECUTION")


def test_an_unknown_preset_is_refused_in_one_line_naming_the_known_ones(capsys):
    from symlearn.cli.main import main

    with pytest.raises(SystemExit) as info:
        main(["train-transition", "--run", "r", "--data", "d", "--preset", "fast"])
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1
    assert "invalid choice: 'fast' (choose from 'paper', 'quick', 'recommended')" in err


def test_the_parser_and_its_refusals_need_no_torch():
    """The preset flags read their tables only when a name is checked or --help lists them (cli.args.PresetNames):
    building the parser for a command that runs no network loads neither torch nor numpy."""
    code = ("import sys\nfrom symlearn.cli.main import build_parser\n"
            "a = build_parser().parse_args(['train', '--data', 'd', '--out', 'o'])\n"
            "print(a.preset, 'torch' in sys.modules, 'numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120,
                         env={"PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["recommended", "False", "False"]


def test_library_cli_and_pipeline_defaults_are_equal():
    import torch

    from symlearn.cli.main import collect_config, lifted_config, train_config
    from symlearn.cli.planning import execution_config, transition_config
    from symlearn.config_file import RECIPE
    from symlearn.export.lifted_export import LIFTED_PRESETS, LiftedConfig
    from symlearn.learning.training import TrainConfig
    from symlearn.pipeline import stage_configs
    from symlearn.pipeline_presets import DEFAULT_PRESET, PipelineSettings
    from symlearn.planning.execution import EXECUTION_PRESETS, ExecutionConfig, run_problem
    from symlearn.sim.collect import CollectConfig
    from symlearn.symbolic.symbols import FREQUENT_MIN_COUNT, analyse_symbols
    from symlearn.symbolic.transition_model import TransitionConfig
    from symlearn.symbolic.transition_training import train_transition

    assert _parse("pipeline", "--out", "x").preset == DEFAULT_PRESET == RECIPE
    pipe = stage_configs(PipelineSettings(out=Path("unused")))
    # execution: the recipe's, closed loop and 10 s a planner call, wherever it is asked for
    ex = ExecutionConfig()
    assert (ex.closed_loop, ex.timeout_s) == (True, 10.0)
    for command in (("plan", "--run", "r", "--problem", "p.json"),
                    ("benchmark", "--run", "r", "--problems", "d", "--out", "o.json")):
        assert execution_config(_parse(*command)) == ex
    assert pipe["benchmark"].execution == ex == EXECUTION_PRESETS[RECIPE]
    assert inspect.signature(run_problem).parameters["config"].default == ex
    assert f"ExecutionConfig's, {ex.timeout_s:g})" in _flag("plan", "timeout").help
    # the effect model: the recipe's preset (the pipeline trains in bf16 on a GPU only)
    train = train_config(_parse("train", "--data", "d", "--out", "o"))
    assert train == TrainConfig.from_preset() == TrainConfig.from_preset(RECIPE)
    assert dataclasses.replace(pipe["train"], bf16=train.bf16) == train
    assert pipe["train"].bf16 == (torch.cuda.is_available() or train.bf16)
    # m(z) and its seed
    transition = transition_config(_parse("train-transition", "--run", "r", "--data", "d"))
    assert transition == TransitionConfig.from_preset() == pipe["train-transition"].transition
    seed_default = inspect.signature(train_transition).parameters["seed"].default
    assert _parse("train-transition", "--run", "r", "--data", "d").seed == seed_default == pipe["train-transition"].seed
    # the lifted domain
    args = _parse("export-pddl", "--run", "r", "--data", "d")
    assert lifted_config(args) == LIFTED_PRESETS[args.preset] == LiftedConfig() == pipe["export-pddl"].lifted
    # collection
    assert collect_config(_parse("collect", "--out", "d")) == CollectConfig() == pipe["collect"]
    assert f"default {CollectConfig().n})" in _flag("collect", "n").help
    # symbols: the flag left unset is the library's default, the pipeline's too
    assert _parse("symbols", "--run", "r", "--data", "d").min_count is None
    assert inspect.signature(analyse_symbols).parameters["min_count"].default == FREQUENT_MIN_COUNT
    assert pipe["symbols"].min_count == FREQUENT_MIN_COUNT
    assert f"FREQUENT_MIN_COUNT, {FREQUENT_MIN_COUNT})" in _flag("symbols", "min_count").help
    # the pipeline's own flags
    assert _parse("pipeline", "--out", "x").workers == PipelineSettings(out=Path("x")).workers
