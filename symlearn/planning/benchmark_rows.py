"""A benchmark's rows and problems: the row schema, the resumable row log OUT.rows.jsonl (one finished row a line,
its first line the settings it resumes under), and the problem sets with the key and name each problem's rows carry.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from pddl_export.bounded_json import (AnyJson, Bool, Int, JsonFileError, Map, MiB, Num, Obj, Opt, Str, Tuple, check,
                                      loads_bounded, read_bounded_bytes)
from pddl_export.files import finite_or_null
from symlearn.planning.execution import ProblemRun
from symlearn.problems.problem import Problem, load_problems
from symlearn.provenance import atomic_write_text


ROWS_FORMAT = "symlearn-benchmark-rows"
ROWS_VERSION = 1
ROWS_FILE_BYTES = 512 * MiB  # a row is about 1-2 KB; a benchmark of 100k rows fits
_TEXT = Str(100_000)
# One finished row as ProblemRun.to_json writes it (non-finite numbers as null); ProblemRun refuses the rest.
ROW_SCHEMA = Obj(
    required={"problem": Str(1000), "planner": Str(200), "found": Bool(), "status": Str(100),
              "plan_length": Opt(Int(0)), "planning_time_s": Opt(Num()), "expansions": Opt(Int(0)),
              "success": Bool(), "symbolic_match": Bool(), "max_distance_m": Opt(Num()), "closed_loop": Bool(),
              "replans": Int(0), "failure_stage": Opt(Str(100)), "generator_length": Int(0)},
    optional={"message": _TEXT, "n_objects": Int(0), "timings": Map(Opt(AnyJson()), 1000), "task": Str(1000),
              "failure_cause": Opt(Str(100)), "attribution": Map(AnyJson(), 1000), "goal_off_locations": Opt(Int(0)),
              "optimal_length": Opt(Int(0)), "executed_length": Opt(Int(0))},
    extra=False)
# A line of the log after the first: the row's key (problem key, planner, closed loop) and the row.
ROW_ENTRY_SCHEMA = Obj(required={"key": Tuple((Str(1000), Str(200), Bool())), "row": ROW_SCHEMA}, extra=False)


def rows_path(out_file: Path) -> Path:
    """The JSON-lines log of finished rows beside a benchmark's output: OUT.rows.jsonl."""
    out_file = Path(out_file)
    return out_file.with_name(out_file.name + ".rows.jsonl")


class RowLog:
    """Finished rows, one JSON line each, appended and fsynced as they finish; its first line holds the settings.

    Reopening a log of the same settings returns the rows already finished (a torn last line, from a
    kill during a write, is cut off); a log of other settings is refused, so runs are never mixed.
    """

    def __init__(self, path: Path, settings: dict) -> None:
        self.path, self.settings = Path(path), finite_or_null(settings)
        self.done: dict[tuple, dict] = {}
        self._file = None

    def open(self) -> dict[tuple, dict]:
        """Read (or create) the log; returns key -> finished row JSON.

        Every line is read with the bounded reader and checked against the row schema (and as a ProblemRun)
        here, before any row runs: a wrong-shaped line is refused naming the file and the line.
        """
        if not self.path.exists():
            atomic_write_text(self.path, _line({"format": ROWS_FORMAT, "version": ROWS_VERSION,
                                                "settings": self.settings}))
        data = read_bounded_bytes(self.path, ROWS_FILE_BYTES, "benchmark row log")
        whole = data[:data.rfind(b"\n") + 1]
        lines = whole.splitlines()
        fix = "delete it to start over"
        try:
            head = loads_bounded(lines[0], f"{self.path}: line 1")
        except (JsonFileError, IndexError) as e:
            raise ValueError(f"{self.path}: not a benchmark row log ({e}); {fix}") from None
        if not isinstance(head, dict) or head.get("format") != ROWS_FORMAT:
            raise ValueError(f"{self.path}: not a benchmark row log; {fix}")
        if head.get("settings") != self.settings:
            old = head.get("settings") if isinstance(head.get("settings"), dict) else {}
            diff = sorted(k for k in set(self.settings) | set(old) if old.get(k) != self.settings.get(k))
            raise ValueError(f"{self.path} holds a partial benchmark with other settings (differing: "
                             f"{', '.join(diff)}); re-run with the same settings to resume, or delete it")
        done = {}
        for n, text in enumerate(lines[1:], 2):
            where = f"{self.path}: line {n}"
            try:
                entry = loads_bounded(text, where)
                check(entry, ROW_ENTRY_SCHEMA, where)
                ProblemRun(**entry["row"])  # the refusals of the row itself (unknown failure stage, ...)
            except (TypeError, ValueError) as e:
                msg = str(e).splitlines()[0] if str(e) else type(e).__name__
                raise ValueError(f"{msg if msg.startswith(where) else f'{where}: {msg}'}; {fix}") from None
            done[tuple(entry["key"])] = entry["row"]
        if len(whole) != len(data):
            with open(self.path, "r+b") as f:  # a row torn by a kill: cut it off
                f.truncate(len(whole))
        self.done = done
        self._file = open(self.path, "a", encoding="utf-8")
        return self.done

    def append(self, key: tuple, row: dict) -> None:
        """Record one finished row durably (flush and fsync before returning)."""
        self._file.write(_line({"key": list(key), "row": row}))
        self._file.flush()
        os.fsync(self._file.fileno())
        self.done[key] = row

    def close(self) -> None:
        """Close the log file (it stays on disk)."""
        if self._file is not None:
            self._file.close()
            self._file = None


def _line(obj) -> str:
    return json.dumps(finite_or_null(obj), allow_nan=False, separators=(",", ":")) + "\n"


@dataclass(frozen=True)
class SetProblem:
    """A problem of one of a benchmark's sets, with its unique row key and the name its rows show."""

    key: str  # the file name, prefixed "<set folder>/" when the benchmark runs several sets
    label: str  # the problem's name, prefixed the same way
    path: Path
    problem: Problem


def problem_sets(problems: str | Path | Sequence[str | Path]) -> list[Path]:
    """The problem folders to run: a list, a comma-separated string, a folder of problem files, or a folder
    whose subfolders hold problem sets (each one set, in name order). Two sets of one folder name are refused."""
    items = [Path(x) for x in (str(problems).split(",") if isinstance(problems, (str, Path)) else problems)
             if str(x).strip()]
    if len(items) == 1 and items[0].is_dir() and not any(items[0].glob("*.json")):
        items = sorted(d for d in items[0].iterdir() if d.is_dir() and any(d.glob("*.json"))) or items
    if not items:
        raise ValueError("no problem folders given")
    names = [p.name for p in items]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"problem sets {', '.join(twice)} are named twice; their rows would share keys")
    return items


def load_sets(sets: Sequence[Path]) -> list[SetProblem]:
    """Every problem of every set; with several sets the keys and names carry the set's folder name."""
    if len(sets) == 1:
        return [SetProblem(path.name, pr.name, path, pr) for path, pr in load_problems(sets[0])]
    return [SetProblem(f"{d.name}/{path.name}", f"{d.name}/{pr.name}", path, pr)
            for d in sets for path, pr in load_problems(d)]
