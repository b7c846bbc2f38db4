"""Settings files: `--config FILE.toml` for every lever that is not a command-line flag.

A file's tables are named after the stages' frozen config dataclasses (TABLES), and its keys are their fields;
a nested dataclass field is a sub-table (`[train.model]`, `[collect.exploration]`). One file can hold the whole
recipe: each sub-command reads the tables of its own stage and checks the others too, so a typo anywhere is
refused at once, in one line naming the file, the table and the key, before any work starts.

    [train]
    stability_weight = 0.1
    [train.model]
    action_per_object = true
    [execution]
    timeout_s = 30.0

The values become the config the stage runs with, which every stage already saves beside its output (config.json,
the checkpoint, pipeline.json), so the file needs no copy of its own. Reading is pure: tomllib (the standard
library's TOML parser), a bounded read, and the dataclasses' type hints; the dataclasses' own checks then judge
the values (a negative weight, an unknown preset).
"""
from __future__ import annotations

import dataclasses
import importlib
import tomllib
import types
import typing
from pathlib import Path
from typing import Any, Mapping

MAX_CONFIG_BYTES = 1 << 20  # a settings file is a few hundred bytes; anything near a megabyte is not one

# table -> "module:Class" of the frozen config dataclass whose fields it sets (imported only when the file has it:
# the learning configs load torch)
TABLES: Mapping[str, str] = types.MappingProxyType({
    "collect": "symlearn.sim.collect:CollectConfig",
    "train": "symlearn.learning.training:TrainConfig",
    "transition": "symlearn.symbolic.transition_model:TransitionConfig",
    "export": "symlearn.export.rules_export:ExportConfig",
    "lifted": "symlearn.export.lifted_export:LiftedConfig",
    "problems": "symlearn.problems.problem_generation:ProblemConfig",
    "execution": "symlearn.planning.execution:ExecutionConfig",
})
# fields a file may not set: what the command line or the stage itself decides (the preset names the base config)
NOT_SETTABLE = frozenset({"preset"})

Settings = dict[str, dict[str, Any]]


class ConfigFileError(ValueError):
    """A settings file that cannot be read, or holds a table, key or value no config has: one line, naming it."""


def table_class(table: str) -> type:
    """The config dataclass a table sets."""
    module, _, name = TABLES[table].partition(":")
    return getattr(importlib.import_module(module), name)


def read_config_file(path: Path | str | None) -> Settings:
    """The checked settings of a TOML file: {table: {field: value}}, nested dataclasses as nested dicts, lists as
    tuples; {} for None. Unknown tables and keys, wrong types and unreadable files raise ConfigFileError."""
    if path is None:
        return {}
    path = Path(path)
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_CONFIG_BYTES + 1)
    except OSError as e:
        raise ConfigFileError(f"{path}: cannot read the settings file ({e.strerror or e})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigFileError(f"{path}: larger than {MAX_CONFIG_BYTES} bytes; a settings file is a few lines")
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise ConfigFileError(f"{path}: not a TOML file ({e})") from None
    settings: Settings = {}
    for table, values in doc.items():
        if table not in TABLES:
            raise ConfigFileError(f"{path}: unknown table [{table}]; tables: {', '.join(TABLES)}")
        if not isinstance(values, dict):
            raise ConfigFileError(f"{path}: {table} must be a table, [{table}]")
        settings[table] = _checked(table_class(table), values, f"{path}: [{table}]")
    return settings


def _checked(cls: type, values: dict, where: str) -> dict[str, Any]:
    """values checked against cls's fields and type hints (nested dataclasses recursively)."""
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls) if f.init and f.name not in NOT_SETTABLE]
    out: dict[str, Any] = {}
    for key, value in values.items():
        if key not in names:
            raise ConfigFileError(f"{where} has no setting {key!r}; settings: {', '.join(names)}")
        out[key] = _value(hints[key], value, f"{where} {key}")
    return out


def _value(hint: Any, value: Any, where: str) -> Any:
    """value as the type `hint` asks for (a TOML list as a tuple, an integer as a float), or ConfigFileError."""
    args = typing.get_args(hint)
    if dataclasses.is_dataclass(hint):
        if not isinstance(value, dict):
            raise ConfigFileError(f"{where} must be a table of {hint.__name__}'s settings")
        return _checked(hint, value, where)
    if typing.get_origin(hint) in (typing.Union, types.UnionType):  # `int | None`: TOML has no None
        kinds = [a for a in args if a is not type(None)]
        if len(kinds) == 1:
            return _value(kinds[0], value, where)
    if typing.get_origin(hint) is tuple:
        if not isinstance(value, list):
            raise ConfigFileError(f"{where} must be a list, e.g. [1, 3]")
        kinds = [args[0]] * len(value) if len(args) == 2 and args[1] is Ellipsis else list(args)
        if len(kinds) != len(value):
            raise ConfigFileError(f"{where} must be a list of {len(kinds)} values")
        return tuple(_value(k, v, where) for k, v in zip(kinds, value))
    if hint is bool and isinstance(value, bool):
        return value
    if hint is int and isinstance(value, int) and not isinstance(value, bool):
        return value
    if hint is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if hint is str and isinstance(value, str):
        return value
    name = getattr(hint, "__name__", str(hint))
    if name not in ("bool", "int", "float", "str"):
        raise ConfigFileError(f"{where} cannot be set from a file")
    raise ConfigFileError(f"{where} must be {'a' if name != 'int' else 'an'} {name}, not {value!r}")


def replace_nested(cfg: Any, values: Mapping[str, Any]) -> Any:
    """cfg with the checked values of its table (nested dataclasses replaced field by field); the dataclass's own
    checks run again on the result."""
    direct = {k: v for k, v in values.items() if not isinstance(v, dict)}
    nested = {k: replace_nested(getattr(cfg, k), v) for k, v in values.items() if isinstance(v, dict)}
    return dataclasses.replace(cfg, **direct, **nested) if direct or nested else cfg


def flat_overrides(values: Mapping[str, Any]) -> dict[str, Any]:
    """A table's values with one level of sub-tables merged in: the overrides of the `from_preset` constructors,
    which route the model's fields to the model config (TrainConfig.from_preset)."""
    out = {k: v for k, v in values.items() if not isinstance(v, dict)}
    for v in values.values():
        if isinstance(v, dict):
            out.update(v)
    return out
