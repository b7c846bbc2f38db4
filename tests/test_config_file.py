"""Settings files (--config FILE.toml): tables named after the stages' configs, keys their fields, every mistake
refused in one line naming the file, and the values reaching the config each stage saves with its output."""
from __future__ import annotations

import dataclasses
import json

import pytest

from conftest import cli
from symlearn.config_file import (MAX_CONFIG_BYTES, TABLES, ConfigFileError, flat_overrides, read_config_file,
                                  replace_nested, table_class)


def _write(tmp_path, text: str, name: str = "c.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_every_table_names_a_frozen_config_dataclass():
    for table in TABLES:
        cls = table_class(table)
        assert dataclasses.is_dataclass(cls) and cls.__dataclass_params__.frozen, table
        cls()  # its defaults make a valid config


def test_values_are_typed_as_the_fields_and_nested_tables_reach_nested_configs(tmp_path):
    from symlearn.learning.training import TrainConfig
    from symlearn.sim.collect import CollectConfig

    path = _write(tmp_path, "[collect]\nshard_size = 10\n[collect.exploration]\nk_values = [4, 5]\nk_probs = [0.5, 0.5]\n"
                            "[train]\nlr = 1\nbatch_size = 16\n[train.model]\nattention = false\nconv_channels = [8, 8, 8, 8]\n")
    got = read_config_file(path)
    assert got["train"] == {"lr": 1.0, "batch_size": 16, "model": {"attention": False, "conv_channels": (8, 8, 8, 8)}}
    assert isinstance(got["train"]["lr"], float)  # an integer where a float is asked
    collect = replace_nested(CollectConfig(), got["collect"])
    assert collect.shard_size == 10 and collect.exploration.k_values == (4, 5) and collect.n == CollectConfig().n
    train = TrainConfig.from_preset("quick", **flat_overrides(got["train"]))
    assert (train.lr, train.batch_size, train.model.attention, train.model.conv_channels) == (1.0, 16, False, (8,) * 4)
    assert train.model.crop == 32  # the rest stays the preset's
    assert read_config_file(None) == {}


@pytest.mark.parametrize("text, message", [
    ("[trian]\nlr = 1\n", "unknown table [trian]; tables: collect, train"),
    ("[train]\nlearning_rate = 1\n", "[train] has no setting 'learning_rate'; settings: model, epochs"),
    ("[train]\npreset = 'paper'\n", "[train] has no setting 'preset'"),  # the --preset flag names the base
    ("[train]\nbatch_size = 8.5\n", "[train] batch_size must be an int, not 8.5"),
    ("[train]\nbf16 = 1\n", "[train] bf16 must be a bool, not 1"),
    ("[train.model]\nconv_channels = 8\n", "[train] model conv_channels must be a list"),
    ("[problems]\nobjects = [1, 2, 3]\n", "[problems] objects must be a list of 2 values"),
    ("[train]\nmodel = 3\n", "[train] model must be a table of ModelConfig's settings"),
    ("train = 3\n", "train must be a table, [train]"),
    ("[train\n", "not a TOML file"),
])
def test_mistakes_are_refused_in_one_line_naming_the_file(tmp_path, text, message):
    path = _write(tmp_path, text)
    with pytest.raises(ConfigFileError) as info:
        read_config_file(path)
    assert str(info.value).startswith(f"{path}: ") and message in str(info.value) and "\n" not in str(info.value)


def test_unreadable_and_oversized_files_are_refused(tmp_path):
    with pytest.raises(ConfigFileError, match="cannot read the settings file"):
        read_config_file(tmp_path / "missing.toml")
    big = _write(tmp_path, "# " + "x" * MAX_CONFIG_BYTES + "\n")
    with pytest.raises(ConfigFileError, match="more than the 1048576 bytes a settings file may have"):
        read_config_file(big)


def test_a_bad_settings_file_stops_the_command_before_any_work(tmp_path, capsys):
    out = tmp_path / "data"
    path = _write(tmp_path, "[collect]\nshard_sise = 4\n")
    rc, printed = cli("collect", "--out", out, "--n", 12, "--config", path, "--quiet")
    err = capsys.readouterr().err.strip()
    assert rc == 2 and printed == "" and not out.exists()
    assert err == f"symlearn collect: error: {path}: [collect] has no setting 'shard_sise'; settings: n, seed, " \
                  "shard_size, exploration, sim"


def test_settings_reach_the_saved_config_and_flags_win(tiny_data, tmp_path):
    """[train] and [train.model] end in RUN/config.json, which is how a run records what it was trained with."""
    path = _write(tmp_path, "[train]\nbatch_size = 8\nbf16 = false\nepochs = 5\nrider_weight = 2.0\n"
                            "[train.model]\nbits = 6\n")
    run = tmp_path / "run"
    rc, _ = cli("train", "--data", tiny_data.path, "--out", run, "--preset", "quick", "--epochs", 1, "--config", path,
                "--quiet")
    assert rc == 0
    cfg = json.loads((run / "config.json").read_text())["train_config"]
    assert (cfg["batch_size"], cfg["bf16"], cfg["rider_weight"], cfg["model"]["bits"]) == (8, False, 2.0, 6)
    assert cfg["epochs"] == 1 and cfg["preset"] == "quick"  # the flag over the file


def test_the_presets_the_cli_lists_are_the_configs_presets():
    from symlearn.cli.main import build_parser
    from symlearn.learning.models import PRESETS
    from symlearn.learning.training import TRAIN_PRESETS, TrainConfig
    from symlearn.symbolic.transition_model import TRANSITION_PRESETS

    sub = next(a for a in build_parser()._actions if a.dest == "command").choices
    train, transition = (next(a for a in sub[c]._actions if a.dest == "preset") for c in ("train", "train-transition"))
    assert list(train.choices) == list(TRAIN_PRESETS) and list(transition.choices) == list(TRANSITION_PRESETS)
    assert set(TRAIN_PRESETS) == set(TRANSITION_PRESETS) == set(PRESETS)
    # the learned relational route's presets, written out in the CLI so that it loads without torch
    from symlearn.export.learned_export import EXPORT_PRESETS
    from symlearn.learning.relational_training import TRAIN_PRESETS as RELATIONAL_PRESETS

    relational, export = (next(a for a in sub[c]._actions if a.dest == "preset")
                          for c in ("train-relations", "export-learned"))
    assert set(relational.choices) == set(RELATIONAL_PRESETS) and set(export.choices) == set(EXPORT_PRESETS)
    rec = TrainConfig.from_preset("recommended")
    quick = TrainConfig.from_preset("quick")
    # the recipe: the stability loss, the action on the held object, rider scenes three times an epoch, float32
    assert (rec.stability_weight, rec.model.action_per_object, rec.rider_scene_repeat, rec.bf16) == (0.1, True, 3, False)
    assert dataclasses.replace(rec, preset="quick", stability_weight=0.0, rider_scene_repeat=1, bf16=True,
                               model=dataclasses.replace(rec.model, action_per_object=False)) == quick


def test_no_sub_command_has_more_than_eight_flags():
    """The surface a user holds: at most 8 flags a sub-command (train 10); every other lever is a settings key."""
    import argparse

    from symlearn.cli.main import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    counts = {name: sum(1 for a in p._actions if a.option_strings and a.help != argparse.SUPPRESS
                        and "-h" not in a.option_strings) for name, p in sub.choices.items()}
    assert all(n <= (10 if name == "train" else 8) for name, n in counts.items()), counts
    assert counts["train"] == 10 and counts["benchmark"] == 8, counts  # the two widest
