"""Argument types shared by the `symlearn` sub-commands (argparse `type=` callables)."""
from __future__ import annotations

import argparse
import functools
import importlib
import os
from typing import Any, Callable, Mapping, Sequence, TypeVar

from symlearn.config_file import built, read_config_file

T = TypeVar("T")



def int_range(text: str) -> tuple[int, int]:
    """'1-3' -> (1, 3); '4' -> (4, 4); anything else is an argparse error naming the text."""
    try:
        lo, _, hi = text.partition("-")
        lo_i, hi_i = int(lo), int(hi or lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"range {text!r} must look like 1-3 or 4") from None
    if lo_i > hi_i:
        raise argparse.ArgumentTypeError(f"range {text!r} is empty")
    return lo_i, hi_i


def planner_list(text: str) -> list[str]:
    """'astar, astar-ucs' -> ['astar', 'astar-ucs']; an empty list is an argparse error."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give at least one planner, e.g. astar,astar-ucs")
    return names


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None


def positive_int(text: str) -> int:
    """'3' -> 3; zero, negatives and non-integers are argparse errors naming the text."""
    value = _integer(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} must be a positive integer")
    return value


def max_threads() -> int:
    """The most CPU threads --threads accepts: 4 per core (more only waits for the cores, and a huge count
    overflows torch's int, or makes each small network call spawn hundreds of idle threads)."""
    return 4 * (os.cpu_count() or 1)


def thread_count(text: str) -> int:
    """'2' -> 2, for --threads: an integer in 1..max_threads(); anything else is an argparse error naming the text."""
    value = positive_int(text)
    if value > max_threads():
        raise argparse.ArgumentTypeError(f"{text!r} is more threads than this machine can use "
                                         f"(at most {max_threads()}: 4 per core)")
    return value


def non_negative_int(text: str) -> int:
    """'0' -> 0; negatives and non-integers are argparse errors naming the text."""
    value = _integer(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a non-negative integer")
    return value


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose refusals are one line, 'PROG: error: MESSAGE (see PROG --help)', exit code 2."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def add_ray_flag(c: argparse.ArgumentParser, unit: str) -> None:
    """--ray [ADDRESS], for the commands whose `unit`s (shards, rows) can run as Ray tasks: on a local Ray without
    an address, else on the cluster at ADDRESS (head IP:6379, or auto)."""
    c.add_argument("--ray", nargs="?", const="", metavar="ADDRESS",
                   help=f"run each {unit} as a Ray task (pip install symlearn[ray]; docs/SCALING.md): on a local Ray, "
                        "or on the cluster at ADDRESS (head IP:6379, or auto)")


def ray_engine(args: argparse.Namespace) -> tuple[str, str | None]:
    """(engine, address) from --ray: ("local", None) without it, ("ray", None) for a local Ray, ("ray", ADDRESS)."""
    return ("local", None) if args.ray is None else ("ray", args.ray or None)


class PresetNames(Sequence[str]):
    """The names of a preset table, for argparse's `choices`: read from the table itself (the one place presets are
    defined, beside their config class) when first asked, so that building the parser, `symlearn --help` and a
    refused flag need not import the table's module (the learning configs load torch).

    `table` is "module:NAME", e.g. "symlearn.learning.training:TRAIN_PRESETS".
    """

    def __init__(self, table: str) -> None:
        self.table = table

    @functools.cached_property
    def names(self) -> tuple[str, ...]:
        """The table's keys, in its order."""
        module, _, name = self.table.partition(":")
        return tuple(getattr(importlib.import_module(module), name))

    def __getitem__(self, i: int) -> str:
        return self.names[i]

    def __len__(self) -> int:
        return len(self.names)

    def __contains__(self, value: object) -> bool:
        return value in self.names


def add_preset_flag(c: argparse.ArgumentParser, table: str, default: str, help: str) -> None:
    """--preset NAME, its choices the names of the preset table `table` ("module:NAME", PresetNames); `help` may say
    %(choices)s."""
    c.add_argument("--preset", default=default, choices=PresetNames(table), metavar="NAME", help=help)


def config_from_file(args: argparse.Namespace, table: str, make: Callable[[Mapping[str, Any]], T]) -> T:
    """make(values) with `values` the --config file's table `table` ({} without a file or that table): the config a
    command runs with; what the config refuses is named by file, table and key (config_file.built)."""
    return built(args.config, table, read_config_file(args.config).get(table, {}), make)


def add_config_flag(c: argparse.ArgumentParser, tables: str) -> None:
    """--config FILE.toml: the levers that are not flags (symlearn.config_file); `tables` says which it reads."""
    c.add_argument("--config", metavar="FILE.toml",
                   help=f"settings file (docs/CONFIG.md): {tables}; flags given here win over it")


THREADS_HELP = ("torch CPU threads (default: torch's, one per core); use 1 per process when other jobs share the "
                "cores: OpenMP threads that wait for busy cores slow the networks several-fold")


def set_threads(n: int | None) -> None:
    """torch.set_num_threads(n) when a --threads value was given (at most max_threads())."""
    if n:
        if not 1 <= n <= max_threads():
            raise ValueError(f"--threads {n} must be between 1 and {max_threads()} (4 per core)")
        import torch

        torch.set_num_threads(n)
