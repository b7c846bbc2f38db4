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
library's TOML parser), the bounded reader (pddl_export.bounded_json: a regular file only, opened without
blocking), and the dataclasses' type hints (a float must be finite); then each table is built into its config over
the class's defaults (table_config), so that the dataclass's own checks (`__post_init__`: ranges, a zero that
would divide, an unknown preset) refuse a value while the file is read, naming the key. The checks a flag and a key
share (Bound, TIMEOUT_S) live here, where the command line and the configs both reach them without torch.
"""
from __future__ import annotations

import dataclasses
import importlib
import math
import numbers
import tomllib
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, TypeVar

from pddl_export.bounded_json import JsonFileError, read_bounded_bytes

MAX_CONFIG_BYTES = 1 << 20  # a settings file is a few hundred bytes; anything near a megabyte is not one
T = TypeVar("T")

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
    "planner": "symlearn.planning.planner_catalogue:PlannerConfig",
    "learned_loop": "symlearn.planning.learned_loop:LearnedLoopConfig",
})
# fields a file may not set: what the command line or the stage itself decides (the preset names the base config)
NOT_SETTABLE = frozenset({"preset"})
# the recipe's name in every stage's preset table that has one (TRAIN_PRESETS, TRANSITION_PRESETS,
# EXECUTION_PRESETS, the pipeline's PRESETS): what the commands, the library and the pipeline use by default
RECIPE = "recommended"

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
        raw = read_bounded_bytes(path, MAX_CONFIG_BYTES, "settings file")
    except JsonFileError as e:  # missing, a FIFO or device (refused without blocking), too large, unreadable
        why = str(e).removeprefix(f"{path}: ")
        raise ConfigFileError(f"{path}: cannot read the settings file ({why})") from None
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise ConfigFileError(f"{path}: not a TOML file ({str(e).splitlines()[0]})") from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise ConfigFileError(f"{path}: not a TOML file (nested too deeply)") from None
    settings: Settings = {}
    for table, values in doc.items():
        if table not in TABLES:
            raise ConfigFileError(f"{path}: unknown table [{table}]; tables: {', '.join(TABLES)}")
        if not isinstance(values, dict):
            raise ConfigFileError(f"{path}: {table} must be a table, [{table}]")
        settings[table] = _checked(table_class(table), values, f"{path}: [{table}]")
        built(path, table, settings[table], lambda v, t=table: table_config(t, v))  # the config's own checks
    return settings


def table_config(table: str, values: Mapping[str, Any]) -> Any:
    """The config a table's checked values make over its class's defaults: through `from_preset` (its default
    preset) where the class has one, as the commands build TrainConfig and TransitionConfig (model fields routed to
    the model, the dynamics head switched on), else replace_nested. ValueError: what the dataclass refuses."""
    cls = table_class(table)
    if hasattr(cls, "from_preset"):
        return cls.from_preset(cls().preset, **flat_overrides(values))
    return replace_nested(cls(), values)


def built(path: Path | str | None, table: str, values: Mapping[str, Any], make: Callable[[Mapping[str, Any]], T]) -> T:
    """make(values): a table's values made into its config. A ValueError of the config's own checks becomes a
    one-line ConfigFileError naming the file, the table and the key: the first key whose value alone (over the
    same base) is refused, else the table (values refused only together, such as d_model and n_heads)."""
    try:
        return make(values)
    except _REFUSALS as e:
        if not values or isinstance(e, ConfigFileError):  # nothing of the file's in it: the refusal as it came
            raise
        whole = _first_line(e)
    for keys, value in _leaves(values):
        try:
            make(_nested(keys, value))
        except _REFUSALS as e:
            raise ConfigFileError(f"{path}: [{'.'.join((table, *keys[:-1]))}] {keys[-1]}: {_first_line(e)}") from None
    raise ConfigFileError(f"{path}: [{table}]: {whole}") from None


_REFUSALS = (ValueError, TypeError, RuntimeError)  # what a config's checks raise (CollectError is a RuntimeError)


def _first_line(e: Exception) -> str:
    return (str(e).strip().splitlines() or [type(e).__name__])[0]


def _leaves(values: Mapping[str, Any], keys: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Any]]:
    """Every (key path, value) of a table, sub-tables walked."""
    out = []
    for k, v in values.items():
        out += _leaves(v, (*keys, k)) if isinstance(v, dict) else [((*keys, k), v)]
    return out


def _nested(keys: tuple[str, ...], value: Any) -> dict[str, Any]:
    """{'model': {'n_heads': 0}} from (('model', 'n_heads'), 0)."""
    return {keys[0]: _nested(keys[1:], value) if len(keys) > 1 else value}


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
        if not math.isfinite(value):  # TOML has inf and nan; no setting takes them
            raise ConfigFileError(f"{where} must be a finite number, not {value!r}")
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


# ------------------------------------------------------------------------------------------------ bounds
# What a number setting may hold, shared by the configs' own checks (`__post_init__`) and the flags that set the same
# field, so that a flag and a key are refused alike.

MAX_TIMEOUT_S = 86_400.0  # one day: larger values are typos, and every planner process needs a finite limit


@dataclass(frozen=True)
class Bound:
    """A finite number in lo..hi (an end excluded where lo_open / hi_open), an integer where `integer`; a tuple
    field's every item (and at least one)."""

    lo: float = -math.inf
    hi: float = math.inf
    integer: bool = False
    lo_open: bool = False
    hi_open: bool = False

    def holds(self, v: Any) -> bool:
        """Whether v (a number, not a boolean) lies within the bound."""
        kind = numbers.Integral if self.integer else numbers.Real
        if isinstance(v, bool) or not isinstance(v, kind) or not math.isfinite(v):
            return False
        above = self.lo < v if self.lo_open else self.lo <= v
        return above and (v < self.hi if self.hi_open else v <= self.hi)

    def describe(self) -> str:
        """'an integer >= 1', 'a finite number in (0, 86400]'."""
        what = "an integer" if self.integer else "a finite number"
        if math.isinf(self.lo) and math.isinf(self.hi):
            return what
        if math.isinf(self.hi):
            return f"{what} {'>' if self.lo_open else '>='} {self.lo:g}"
        return f"{what} in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}{')' if self.hi_open else ']'}"


TIMEOUT_S = Bound(0.0, MAX_TIMEOUT_S, lo_open=True)  # ExecutionConfig.timeout_s and --timeout


def preset(presets: Mapping[str, T], name: str, what: str = "preset", **overrides: Any) -> T:
    """The config `presets[name]` with field overrides; an unknown name is refused in one line that lists the known
    ones ("unknown {what} 'x'; known: a, b"). Every config dataclass's from_preset goes through here."""
    if name not in presets:
        raise ValueError(f"unknown {what} {name!r}; known: {', '.join(presets)}")
    return dataclasses.replace(presets[name], **overrides)


def check_bounds(cfg: Any, bounds: Mapping[str, Bound]) -> None:
    """Refuse (ValueError, one line naming the field) a field of cfg outside its Bound; a tuple field's items each,
    and an empty tuple."""
    for name, bound in bounds.items():
        v = getattr(cfg, name)
        items = v if isinstance(v, (tuple, list)) else (v,)
        if not items or not all(bound.holds(x) for x in items):
            each = "a non-empty list, each item " if isinstance(v, (tuple, list)) else ""
            raise ValueError(f"{name}={v!r} must be {each}{bound.describe()}")
