"""Benchmarking planners on folders of problems: plan with the learned symbols, execute, score.

Planners are named entries of the one registry, symlearn.planning.planners.PLANNERS (the
learned-net A* variants and the planners on the exported rules); `benchmark` builds the named
ones for the run and refuses unknown names before any work. Beside the per-planner summary, the
result holds `shortest_grid` (objects x shortest-plan length of the problems, with off-location goals in
their own column: success, executed / shortest plan length, failure causes per cell), `grid` (objects x
reference-length bucket, the older view), `failure_causes` and `tasks` (structure-suite tasks);
symlearn.planning.benchmark_plots renders them.

    >>> res = benchmark(Path("runs/paper"), Path("problems/p13"), ["astar", "astar-ucs"],
    ...                 Path("runs/paper/bench.json"), closed_loop=True, timeout_s=30)  # doctest: +SKIP
    >>> print(format_table(res))                                                        # doctest: +SKIP
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import signal
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from pddl_export.bounded_json import (AnyJson, Bool, Int, JsonFileError, Map, MiB, Num, Obj, Opt, Str, Tuple, check,
                                      loads_bounded, read_bounded_bytes, read_json_file)
from pddl_export.files import finite_or_null
from pddl_export.rules_io import PDDL_DIR, RULES_FILE
from search.processes import PlannerInterrupted
from symlearn.planning.execution import ExecutionConfig, ProblemRun, failure_causes, run_problem
from symlearn.planning.planners import RISK_PLANNERS, make_planners
from symlearn.problems.problem import RANDOM_WALK, Problem, load_problems
from symlearn.folder_lock import locked
from symlearn.planning.recording import PlanRecorder
from symlearn.provenance import atomic_write_json, atomic_write_text, sha256_bytes, sha256_file, versions


def _rate(rows: list[ProblemRun], key: str) -> float | None:
    return round(sum(bool(getattr(r, key)) for r in rows) / len(rows), 4) if rows else None


def summarize_rows(rows: list[ProblemRun]) -> dict:
    """Per-planner aggregates: success, found rate, median planning time, plan and generator lengths."""
    out = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        open_rows = [r for r in rows if r.planner == planner and not r.closed_loop]
        closed = [r for r in rows if r.planner == planner and r.closed_loop]
        base = open_rows or closed
        found = [r for r in base if r.found]
        stages: dict[str, int] = {}
        for r in base:
            if r.failure_stage is not None:
                stages[r.failure_stage.value] = stages.get(r.failure_stage.value, 0) + 1
        s = {"n_problems": len(base), "success_rate": _rate(open_rows, "success"), "found_rate": _rate(base, "found"),
             "symbolic_match_rate": _rate(open_rows, "symbolic_match"),
             "median_time_s": round(statistics.median(r.planning_time_s for r in base), 5) if base else None,
             # lengths over the problems the planner solved, so the two means compare like with like
             "mean_plan_length": round(statistics.mean(r.plan_length for r in found), 3) if found else None,
             "mean_generator_length": round(statistics.mean(r.generator_length for r in found), 3) if found else None,
             "failure_stages": stages}
        for key in ("planner_time_s", "pddl_write_time_s"):
            vals = [r.timings[key] for r in base if key in r.timings]
            if vals:
                s[f"median_{key}"] = round(statistics.median(vals), 5)
        s["median_time_s_by_objects"] = {
            str(k): round(statistics.median(r.planning_time_s for r in base if r.n_objects == k), 5)
            for k in sorted({r.n_objects for r in base})}
        s["success_rate_by_objects"] = {
            str(k): _rate([r for r in open_rows if r.n_objects == k], "success")
            for k in sorted({r.n_objects for r in open_rows})}
        if closed:
            s["success_rate_closed_loop"] = _rate(closed, "success")
            s["mean_replans_closed_loop"] = round(statistics.mean(r.replans for r in closed), 3)
        out[planner] = s
    return out


LENGTH_BUCKETS = ("1-2", "3-4", "5-6", "7-8", "9+", "?")  # reference (generator) plan lengths, in plot order
LOOPS = ("open", "closed")


def _pair_bucket(length, top: str) -> str:
    """"1-2", "3-4", "5-6", "7-8" for a length of 1-8, `top` above 8, "?" for 0 or unknown."""
    if not isinstance(length, int) or length <= 0:
        return "?"
    if length > 8:
        return top
    lo = length - (length + 1) % 2
    return f"{lo}-{lo + 1}"


def length_bucket(length: int | None) -> str:
    """The reference-length bucket of a problem: "1-2", "3-4", "5-6", "7-8", "9+", or "?" for 0 or unknown."""
    return _pair_bucket(length, "9+")


def _cell(rows: list[ProblemRun]) -> dict:
    """Success, found rate, median planning time and (over solved rows) mean plan and reference lengths."""
    solved = [r for r in rows if r.found]
    return {"n": len(rows), "success_rate": _rate(rows, "success"), "found_rate": _rate(rows, "found"),
            "median_time_s": round(statistics.median(r.planning_time_s for r in rows), 5),
            "mean_plan_length": round(statistics.mean(r.plan_length for r in solved), 3) if solved else None,
            "mean_reference_length": round(statistics.mean(r.generator_length for r in solved), 3) if solved else None}


def summary_grid(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> object count -> length bucket -> cell (_cell); only cells with rows."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        out[planner] = {}
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")]
            by_objects: dict = {}
            for k in sorted({r.n_objects for r in mine}):
                cells = {b: [r for r in mine if r.n_objects == k and length_bucket(r.generator_length) == b]
                         for b in LENGTH_BUCKETS}
                by_objects[str(k)] = {b: _cell(rs) for b, rs in cells.items() if rs}
            if by_objects:
                out[planner][loop] = by_objects
    return out


SHORTEST_BUCKETS = ("1-2", "3-4", "5-6", "7-8", "9-12", "off", "?")  # shortest-plan lengths, in plot order
OFF_LOCATIONS = "off"  # the column of goals with a judged object off the table locations


def shortest_bucket(row: ProblemRun) -> str:
    """A row's shortest-plan column: "1-2" ... "9-12", "off" (a goal off the locations), or "?" (undecided)."""
    return OFF_LOCATIONS if row.goal_off_locations else _pair_bucket(row.optimal_length, "9-12")


def _shortest_cell(rows: list[ProblemRun]) -> dict:
    """_cell, plus the mean shortest length, executed / shortest length over the successes, and failure causes."""
    out = _cell(rows)
    known = [r for r in rows if r.optimal_length]
    ratios = [r.executed_length / r.optimal_length for r in known if r.success and r.executed_length is not None]
    out["mean_optimal_length"] = round(statistics.mean(r.optimal_length for r in known), 3) if known else None
    out["mean_length_ratio"] = round(statistics.mean(ratios), 3) if ratios else None
    out["failure_causes"] = failure_causes(rows)
    return out


def summary_shortest_grid(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> object count -> shortest-plan column (SHORTEST_BUCKETS) -> cell.

    A cell: n, success and found rates, median planning time, mean plan and reference lengths (solved rows),
    mean shortest length, mean executed / shortest length over its successes, and failure causes (counts).
    """
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")]
            for k in sorted({r.n_objects for r in mine}):
                cells = {b: [r for r in mine if r.n_objects == k and shortest_bucket(r) == b]
                         for b in SHORTEST_BUCKETS}
                out.setdefault(planner, {}).setdefault(loop, {})[str(k)] = {
                    b: _shortest_cell(rs) for b, rs in cells.items() if rs}
    return out


def summary_failure_causes(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> failure cause -> count (adding up to that planner's failed rows)."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        out[planner] = {loop: failure_causes([r for r in rows if r.planner == planner
                                              and r.closed_loop == (loop == "closed")])
                        for loop in LOOPS if any(r.planner == planner and r.closed_loop == (loop == "closed")
                                                 for r in rows)}
    return out


def summary_goal_placement(rows: list[ProblemRun]) -> dict:
    """planner -> "on_locations"/"off_locations" -> n, open and closed success, closed-loop failure causes.

    A goal with an object off the table locations (Problem.goal_off_locations) asks for a pose that symbols of
    place and level cannot name; success there and elsewhere are kept apart. Rows without the count are left out.
    """
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        mine = [r for r in rows if r.planner == planner and r.goal_off_locations is not None]
        for name, off in (("on_locations", False), ("off_locations", True)):
            part = [r for r in mine if (r.goal_off_locations > 0) == off]
            opened, closed = [r for r in part if not r.closed_loop], [r for r in part if r.closed_loop]
            if part:
                out.setdefault(planner, {})[name] = {
                    "n_problems": len(opened or closed), "success_rate": _rate(opened, "success"),
                    "success_rate_closed_loop": _rate(closed, "success"),
                    "closed_loop_failure_causes": failure_causes(closed) if closed else None}
    return out


def summary_tasks(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> structure-suite task -> cell; random-walk problems are left to the grid."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")
                    and r.task != RANDOM_WALK]
            for task in sorted({r.task for r in mine}):
                out.setdefault(planner, {}).setdefault(loop, {})[task] = _cell([r for r in mine if r.task == task])
    return out


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


def _settings(run_dir: Path, sets: list[Path], problems: list[SetProblem], planners: list[str],
              execution: ExecutionConfig) -> dict:
    """What a benchmark's result depends on: a partial run resumes only under the very same settings, the whole
    execution config among them (risk_weight only where a planner weighs risk: it changes no other result)."""
    from symlearn.planning.planners import planner_spec
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    rules = run_dir / PDDL_DIR / RULES_FILE
    needs_rules = any(planner_spec(n).needs_rules for n in planners)
    folders = [str(d.resolve()) for d in sets]
    out = {"run": str(run_dir.resolve()), "problems": folders[0] if len(folders) == 1 else folders,
           "planners": list(planners), **dataclasses.asdict(execution),
           "transition_sha256": sha256_file(run_dir / TRANSITION_FILE)[:16],
           "rules_sha256": sha256_file(rules)[:16] if needs_rules else None,
           "problems_sha256": sha256_bytes(b"".join(sha256_bytes(p.path.read_bytes()).encode()
                                                    for p in problems))[:16]}
    if not any(p in RISK_PLANNERS for p in planners):  # only then does the weight change a result
        del out["risk_weight"]
    if any(planner_spec(n).needs_lifted for n in planners):  # a re-export changes what they plan on
        from symlearn.export.lifted_export import LIFTED_FILE
        out["lifted_sha256"] = sha256_file(run_dir / PDDL_DIR / LIFTED_FILE)[:16]
    return out


class _first_call_kept:
    """The planner function, keeping the result of its first call (the initial plan) in store[key].

    Attributes (a rule planner's `rules`, `planning_model`) are the wrapped function's.
    """

    def __init__(self, fn, store: dict, key: tuple) -> None:
        self.fn, self.store, self.key = fn, store, key

    def __call__(self, transition, start, goal, timeout_s):
        res = self.fn(transition, start, goal, timeout_s)
        self.store.setdefault(self.key, res)
        return res

    def __getattr__(self, name: str):
        return getattr(self.fn, name)


class _not_killed:
    """The planner function, raising PlannerInterrupted instead of returning a result of a planner killed by a signal.

    A planner process killed from outside (search.processes.external_signal) has no result: its row
    must not be logged as one, so the benchmark stops there and the same command again redoes it.
    """

    def __init__(self, fn, name: str) -> None:
        self.fn, self.name = fn, name

    def __call__(self, transition, start, goal, timeout_s):
        res = self.fn(transition, start, goal, timeout_s)
        signum = res.extra.get("killed_by_signal")
        if signum:
            raise PlannerInterrupted(int(signum), f"{self.name} was killed by {signal.Signals(int(signum)).name} "
                                     "(not by its time limit); its row is not saved")
        return res

    def __getattr__(self, name: str):
        return getattr(self.fn, name)


def _current_rules(run_dir: Path, fns: dict):
    """The run's exported rules when they match its transition model (for the attribution of every planner), else None.

    A rule planner among `fns` already holds them (make_planners loaded and checked them); else they are read here.
    """
    from pddl_export.rules_io import load_rules
    from symlearn.planning.planners import check_rules_current

    held = next((f.rules for f in fns.values() if getattr(f, "rules", None) is not None), None)
    if held is not None:
        return held
    if not (run_dir / PDDL_DIR / RULES_FILE).is_file():
        return None
    try:
        rules, model_hash = load_rules(run_dir)
        check_rules_current(run_dir, model_hash)
    except ValueError:
        return None
    return rules


def _loops(execution: ExecutionConfig) -> list[bool]:
    """The loops each (problem, planner) pair runs: open loop, and closed loop too where execution.closed_loop."""
    return [False, True] if execution.closed_loop else [False]


def _run_rows(run_dir: Path, problems: list[SetProblem], fns: dict, log: RowLog, execution: ExecutionConfig,
              show_progress: bool, record_dir: Path | None = None) -> list[ProblemRun]:
    """Every (problem, planner, loop) row in order: finished ones from the log, the rest run and logged."""
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    loops = _loops(execution)
    todo = [(p, name, loop) for p in problems for name in fns for loop in loops if (p.key, name, loop) not in log.done]
    if todo:
        encoder, transition = planning_models(run_dir)
        rules = _current_rules(run_dir, fns)
        total = len(problems) * len(fns) * len(loops)

        def emit(key: tuple, row: dict) -> None:
            log.append(key, row)
            if show_progress:
                print(progress_line(len(log.done), total, key, row), flush=True)

        with TabletopSimulator() as sim:
            for p in problems:
                for name in fns:
                    pair_loops = [loop for loop in loops if (p.key, name, loop) not in log.done]
                    if pair_loops:
                        _run_pair(sim, encoder, transition, rules, p, name, _not_killed(fns[name], name), pair_loops,
                                  execution, record_dir, emit)
    elif show_progress:
        print(f"every row was already in {log.path}", flush=True)
    return [ProblemRun(**log.done[(p.key, name, loop)]) for p in problems for name in fns for loop in loops]


def progress_line(n_done: int, total: int, key: tuple, row: dict) -> str:
    """The line a benchmark prints as a row finishes: '[3/8] problem planner closed-loop: status len N success B'."""
    return (f"[{n_done}/{total}] {row['problem']} {key[1]}{' closed-loop' if key[2] else ''}: {row['status']} "
            f"len {row['plan_length']} success {row['success']}")


def _run_pair(sim, encoder, transition, rules, p: SetProblem, name: str, fn, loops: list[bool],
              execution: ExecutionConfig, record_dir: Path | None, emit: Callable[[tuple, dict], None]) -> None:
    """The rows of one (problem, planner) pair for `loops` in order, each handed to emit(row key, row JSON) as it
    finishes; each row runs with the whole `execution` config, its closed_loop set to the row's loop. Closed loop
    starts from the open loop's very plan when both run, so the two differ only by what execution does."""
    first_plans: dict[tuple, object] = {}  # (problem key, planner) -> the open loop's plan
    for loop in loops:
        cfg = dataclasses.replace(execution, closed_loop=loop)
        rec = None if record_dir is None or loop else PlanRecorder()
        planner = fn if loop else _first_call_kept(fn, first_plans, (p.key, name))
        row = run_problem(sim, encoder, transition, p.problem, name, planner, cfg, recorder=rec, rules=rules,
                          initial_plan=first_plans.pop((p.key, name), None) if loop else None)
        row = dataclasses.replace(row, problem=p.label)
        if rec is not None and not row.success:
            rec.save_gif(Path(record_dir) / f"{p.label.replace('/', '_')}_{name}.gif")
        emit((p.key, name, loop), finite_or_null(row.to_json()))


INTERRUPTED = "interrupted"  # _ray_pair's last entry when a planner was killed by a signal (its row is not one)
_worker_state: dict = {}  # in a Ray worker: the loaded models, planners and simulator of the last settings seen


def _ray_pair(settings_json: str, run_dir: str, planners: list[str], p: SetProblem, name: str,
              loops: list[bool], execution: ExecutionConfig, record_dir: str | None) -> list[tuple[tuple, dict]]:
    """One (problem, planner) pair as a Ray task, on one torch thread; a worker loads the run once per settings."""
    import torch

    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    torch.set_num_threads(1)
    if _worker_state.get("settings") != settings_json:
        old = _worker_state.pop("sim", None)
        if old is not None:
            old.close()
        _worker_state.clear()
        fns = make_planners(list(planners), Path(run_dir), risk_weight=execution.risk_weight)
        encoder, transition = planning_models(Path(run_dir))
        _worker_state.update(settings=settings_json, fns=fns, encoder=encoder, transition=transition,
                             rules=_current_rules(Path(run_dir), fns), sim=TabletopSimulator())
    w, rows = _worker_state, []
    try:
        _run_pair(w["sim"], w["encoder"], w["transition"], w["rules"], p, name, _not_killed(w["fns"][name], name),
                  loops, execution, Path(record_dir) if record_dir else None,
                  lambda key, row: rows.append((key, row)))
    except PlannerInterrupted as e:  # no row for it: the driver logs the rows before it, then stops (_run_rows_ray)
        rows.append((INTERRUPTED, {"signum": e.signum, "message": str(e)}))
    return rows


def _run_rows_ray(run_dir: Path, problems: list[SetProblem], planners: list[str], settings: dict, log: RowLog,
                  execution: ExecutionConfig, show_progress: bool, record_dir: Path | None, workers: int,
                  address: str | None) -> None:
    """The rows the log lacks, one Ray task per (problem, planner) pair, `workers` in flight; logged as they finish."""
    from symlearn.cluster import as_finished, ray_session

    loops = _loops(execution)
    total = len(problems) * len(planners) * len(loops)
    jobs = []
    for p in problems:
        for name in planners:
            todo = [loop for loop in loops if (p.key, name, loop) not in log.done]
            if todo:
                jobs.append(((p.key, name), (json.dumps(settings, sort_keys=True), str(run_dir.resolve()),
                                             list(planners), p, name, todo, execution,
                                             str(record_dir.resolve()) if record_dir else None)))
    if not jobs:
        if show_progress:
            print(f"every row was already in {log.path}", flush=True)
        return
    with ray_session(address, num_cpus=workers) as ray:
        for _, rows in as_finished(ray, _ray_pair, jobs, window=workers):
            for key, row in rows:
                if key == INTERRUPTED:
                    raise PlannerInterrupted(row["signum"], row["message"])
                log.append(key, row)
                if show_progress:
                    print(progress_line(len(log.done), total, tuple(key), row), flush=True)


def benchmark(run_dir: Path, problems_dir: str | Path | Sequence[Path], planners: list[str], out_file: Path,
              closed_loop: bool | None = None, timeout_s: float | None = None, max_replans: int | None = None,
              show_progress: bool = True, record_dir: Path | None = None, risk_weight: float | None = None,
              engine: str = "local", workers: int = 1, address: str | None = None,
              execution: ExecutionConfig | None = None) -> dict:
    """Plan and execute every problem with every planner (closed loop too if asked); write out_file.

    execution: how every row is executed (ExecutionConfig(): open loop, 30 s a planner call, by default); each row
    runs with it whole, its closed_loop False for the open-loop rows and True for the closed-loop ones, which run
    too where execution.closed_loop. The loose closed_loop, timeout_s, max_replans and risk_weight, where given,
    replace those fields of it (the older form of the call). The whole config is part of the settings a partial
    run resumes under, and of the result ("execution").

    problems_dir is one problem folder or several (see problem_sets): with several, each row's key and
    problem name start with its set's folder name. Each finished row is appended to OUT.rows.jsonl at
    once; a run interrupted (killed) and started again with the same settings resumes there, and its
    final JSON equals an uninterrupted run's (its timings aside). The log is removed once out_file is
    written. With record_dir, each failed open-loop run is saved as record_dir/<problem>_<planner>.gif.
    risk_weight is that of the RISK_PLANNERS (symlearn.planning.planners.PlannerContext), recorded when one plans.
    engine "ray" runs each (problem, planner) pair's rows as a Ray task on one torch thread, `workers` at once, on
    the cluster at `address` or a local Ray of `workers` CPUs (symlearn.cluster); rows are logged as they finish,
    and the result equals a local run's apart from timings. The local engine runs rows one after another.
    """
    from symlearn.cluster import check_engine

    if not planners:
        raise ValueError("no planners given")
    check_engine(engine, address)
    if not (isinstance(workers, int) and workers >= 1) or (workers > 1 and engine != "ray"):
        raise ValueError(f"workers={workers!r}: the local engine runs rows one after another; "
                         "more workers need the ray engine (--ray)")
    loose = dict(closed_loop=closed_loop, timeout_s=timeout_s, max_replans=max_replans, risk_weight=risk_weight)
    execution = dataclasses.replace(execution or ExecutionConfig(), **{k: v for k, v in loose.items() if v is not None})
    run_dir, out_file = Path(run_dir), Path(out_file)
    check_outputs(out_file, record_dir)  # before any row runs
    created = not out_file.parent.exists()
    out_file.parent.mkdir(parents=True, exist_ok=True)
    try:
        with locked(lock_path(out_file), out_file):  # a second benchmark on this --out is refused at once
            # refuses unknown names (and missing or stale rules) first
            fns = make_planners(list(planners), run_dir, risk_weight=execution.risk_weight)
            sets = problem_sets(problems_dir)
            problems = load_sets(sets)
            settings = _settings(run_dir, sets, problems, list(planners), execution)
            return _run_and_write(run_dir, sets, problems, list(planners), fns, out_file, settings, execution,
                                  show_progress, record_dir, time.perf_counter(), engine, workers, address)
    finally:
        if created:
            with contextlib.suppress(OSError):
                out_file.parent.rmdir()  # only if a refusal left it empty


def lock_path(out_file: Path) -> Path:
    """The lock file of a benchmark's output while it runs: OUT.lock (symlearn.folder_lock)."""
    out_file = Path(out_file)
    return out_file.with_name(out_file.name + ".lock")


MAX_RESULT_BYTES = 512 * MiB  # an existing --out larger than this is not read to check what it is


def is_benchmark_result(path: Path) -> bool:
    """Whether an existing file is a benchmark result (a JSON object with 'summary' and 'rows'), so --out may
    replace it; anything else (a run's eval.json, a checkpoint) is not."""
    try:
        doc = read_json_file(path, what="benchmark result", max_bytes=MAX_RESULT_BYTES)
    except JsonFileError:
        return False
    return isinstance(doc, dict) and isinstance(doc.get("summary"), dict) and isinstance(doc.get("rows"), list)


def check_outputs(out_file: Path, record_dir: Path | None = None) -> None:
    """Refuse, before any work, an --out that is a folder or another kind of file, a row log or lock that is not
    one, a --record that is a file, and two of them on one path (one-line ValueErrors)."""
    from symlearn.outputs import distinct_outputs, file_output, folder_output

    paths = {"--out": Path(out_file), "--out's row log": rows_path(out_file), "--out's lock": lock_path(out_file)}
    if record_dir is not None:
        paths["--record"] = Path(record_dir)
    distinct_outputs(paths)
    file_output(paths["--out"], "--out", kind="a benchmark result", is_own=is_benchmark_result)
    file_output(paths["--out's row log"], "--out's row log", kind="a benchmark row log",
                magic=(b'{"format":"' + ROWS_FORMAT.encode() + b'"',))
    lock = paths["--out's lock"]
    if lock.is_dir():
        raise ValueError(f"{lock} is a folder; it is where --out's lock goes")
    if record_dir is not None:
        folder_output(Path(record_dir), "--record")


def _run_and_write(run_dir: Path, sets: list[Path], problems: list[SetProblem], planners: list[str], fns: dict,
                   out_file: Path, settings: dict, execution: ExecutionConfig, show_progress: bool,
                   record_dir: Path | None, t0: float, engine: str, workers: int, address: str | None) -> dict:
    """Run (or resume) the rows through OUT.rows.jsonl (on `engine`), then write out_file and remove the log."""
    log = RowLog(rows_path(out_file), settings)
    try:
        log.open()
        if engine == "ray":
            _run_rows_ray(run_dir, problems, list(fns), settings, log, execution, show_progress,
                          Path(record_dir) if record_dir else None, workers, address)
        rows = _run_rows(run_dir, problems, fns, log, execution, show_progress and engine != "ray", record_dir)
    finally:
        log.close()
    result = {"run": str(run_dir), "problems": str(sets[0]) if len(sets) == 1 else [str(d) for d in sets],
              "n_problems": len(problems), "planners": list(planners), "closed_loop": execution.closed_loop,
              "timeout_s": execution.timeout_s, "max_replans": execution.max_replans,
              **({"risk_weight": execution.risk_weight} if "risk_weight" in settings else {}),
              "execution": dataclasses.asdict(execution),
              "transition_sha256": settings["transition_sha256"],
              "problems_sha256": settings["problems_sha256"],
              "versions": versions(), "wall_time_s": round(time.perf_counter() - t0, 2),
              "summary": summarize_rows(rows), "shortest_grid": summary_shortest_grid(rows), "grid": summary_grid(rows),
              "failure_causes": summary_failure_causes(rows), "tasks": summary_tasks(rows),
              "goal_placement": summary_goal_placement(rows),
              "rows": [r.to_json() for r in rows]}
    result = finite_or_null(result)
    atomic_write_json(out_file, result)
    log.path.unlink()
    return result


def format_goal_placement(result: dict) -> str:
    """One line per planner: success on goals every object of which rests on a table location, and on the rest."""
    lines = []
    for planner, parts in result.get("goal_placement", {}).items():
        cells = []
        for name, label in (("on_locations", "goals on the locations"), ("off_locations", "goals off them")):
            c = parts.get(name)
            if c:
                rates = "/".join("-" if v is None else f"{v:.3f}" for v in (c["success_rate"],
                                                                             c["success_rate_closed_loop"]))
                cells.append(f"{label} {rates} ({c['n_problems']})")
        lines.append(f"{planner}: success open/closed, " + "; ".join(cells))
    return "\n".join(lines)


def format_table(result: dict) -> str:
    """The benchmark summary as a text table, one row per planner."""
    cols = [("success_rate", "success"), ("success_rate_closed_loop", "closed"), ("found_rate", "found"),
            ("median_time_s", "med t (s)"), ("mean_plan_length", "plan len"), ("mean_generator_length", "gen len")]
    width = max([20, *(len(p) + 2 for p in result["summary"])])  # the longest planner name still lines up
    head = f"{'planner':<{width}}" + "".join(f"{label:>11}" for _, label in cols)
    lines = [head, "-" * len(head)]
    for planner, s in result["summary"].items():
        cells = []
        for key, _ in cols:
            v = s.get(key)
            cells.append(f"{'-':>11}" if v is None else f"{v:>11.3f}" if isinstance(v, float) else f"{v:>11}")
        lines.append(f"{planner:<{width}}" + "".join(cells))
    return "\n".join(lines)
