"""Benchmarking planners on folders of problems: plan with the learned symbols, execute, score (`symlearn benchmark`).

Planners are named entries of the one registry, symlearn.planning.planners.PLANNERS (the
learned-net A* variants and the planners on the exported rules); `benchmark` builds the named
ones for the run and refuses unknown names and unusable outputs before any work. This module holds the entry:
the outputs' checks, the settings a run resumes under, and the result; the rows and their log are
symlearn.planning.benchmark_rows, running them (here or as Ray tasks) symlearn.planning.benchmark_runner, and the
summaries symlearn.planning.benchmark_summary. Beside the per-planner summary, the
result holds `shortest_grid` (objects x shortest-plan length of the problems, with off-location goals in
their own column: success, executed / shortest plan length, failure causes per cell), `grid` (objects x
reference-length bucket, the older view), `failure_causes` and `tasks` (structure-suite tasks);
symlearn.planning.benchmark_plots renders them.

    >>> res = benchmark(Path("runs/paper"), Path("problems/p13"), ["astar", "astar-ucs"],
    ...                 Path("runs/paper/bench.json"), closed_loop=True, timeout_s=30)  # doctest: +SKIP
    >>> print(benchmark_summary.format_table(res))                                      # doctest: +SKIP
"""
from __future__ import annotations

import contextlib
import dataclasses
import time
from pathlib import Path
from typing import Sequence

from pddl_export.bounded_json import JsonFileError, MiB, read_json_file
from pddl_export.files import finite_or_null
from pddl_export.rules_io import PDDL_DIR, RULES_FILE
from symlearn.folder_lock import locked
from symlearn.planning.benchmark_rows import ROWS_FORMAT, RowLog, SetProblem, load_sets, problem_sets, rows_path
from symlearn.planning.benchmark_runner import run_rows, run_rows_ray
from symlearn.planning.benchmark_summary import (summarize_rows, summary_failure_causes, summary_goal_placement,
                                                 summary_grid, summary_shortest_grid, summary_tasks)
from symlearn.planning.execution import ExecutionConfig
from symlearn.planning.planners import RISK_PLANNERS, PlannerConfig, make_planners
from symlearn.provenance import atomic_write_json, sha256_bytes, sha256_file, versions


def _settings(run_dir: Path, sets: list[Path], problems: list[SetProblem], planners: list[str],
              execution: ExecutionConfig, planner: PlannerConfig = PlannerConfig()) -> dict:
    """What a benchmark's result depends on: a partial run resumes only under the very same settings, the whole
    execution config among them, and the planner config's risk_weight where a planner weighs risk (it changes no
    other result; a Ray task builds its planners from these settings: benchmark_runner._planner_config)."""
    from symlearn.planning.planners import planner_entry
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    rules = run_dir / PDDL_DIR / RULES_FILE
    needs_rules = any(planner_entry(n).needs_rules for n in planners)
    folders = [str(d.resolve()) for d in sets]
    out = {"run": str(run_dir.resolve()), "problems": folders[0] if len(folders) == 1 else folders,
           "planners": list(planners), **dataclasses.asdict(execution),
           "transition_sha256": sha256_file(run_dir / TRANSITION_FILE)[:16],
           "rules_sha256": sha256_file(rules)[:16] if needs_rules else None,
           "problems_sha256": sha256_bytes(b"".join(sha256_bytes(p.path.read_bytes()).encode()
                                                    for p in problems))[:16]}
    if any(p in RISK_PLANNERS for p in planners):  # only then does the weight change a result
        out.update(dataclasses.asdict(planner))
    if any(planner_entry(n).needs_lifted for n in planners):  # a re-export changes what they plan on
        from symlearn.export.lifted_export import LIFTED_FILE
        out["lifted_sha256"] = sha256_file(run_dir / PDDL_DIR / LIFTED_FILE)[:16]
    return out


def benchmark(run_dir: Path, problems_dir: str | Path | Sequence[Path], planners: list[str], out_file: Path,
              closed_loop: bool | None = None, timeout_s: float | None = None, max_replans: int | None = None,
              show_progress: bool = True, record_dir: Path | None = None,
              engine: str = "local", workers: int = 1, address: str | None = None,
              execution: ExecutionConfig | None = None, planner_config: PlannerConfig = PlannerConfig()) -> dict:
    """Plan and execute every problem with every planner (closed loop too if asked); write out_file.

    execution: how every row is executed (by default ExecutionConfig(), the recipe's: closed loop, 10 s a planner
    call, as `symlearn benchmark` and the recommended pipeline); each row
    runs with it whole, its closed_loop False for the open-loop rows and True for the closed-loop ones, which run
    too where execution.closed_loop. The loose closed_loop, timeout_s and max_replans, where given,
    replace those fields of it (the older form of the call). The whole config is part of the settings a partial
    run resumes under, and of the result ("execution").

    problems_dir is one problem folder or several (see problem_sets): with several, each row's key and
    problem name start with its set's folder name. Each finished row is appended to OUT.rows.jsonl at
    once; a run interrupted (killed) and started again with the same settings resumes there, and its
    final JSON equals an uninterrupted run's (its timings aside). The log is removed once out_file is
    written. With record_dir, each failed open-loop run is saved as record_dir/<problem>_<planner>.gif.
    RUN is only read (symlearn.planning.run_folder.Run): the planners keep no task file, and everything written
    lies beside out_file or in record_dir.
    planner_config: the planners' settings (PlannerConfig: risk_weight, recorded when one of the RISK_PLANNERS plans).
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
    loose = dict(closed_loop=closed_loop, timeout_s=timeout_s, max_replans=max_replans)
    execution = dataclasses.replace(execution or ExecutionConfig(), **{k: v for k, v in loose.items() if v is not None})
    run_dir, out_file = Path(run_dir), Path(out_file)
    check_outputs(out_file, record_dir)  # before any row runs
    created = not out_file.parent.exists()
    out_file.parent.mkdir(parents=True, exist_ok=True)
    try:
        with locked(lock_path(out_file), out_file):  # a second benchmark on this --out is refused at once
            # refuses unknown names (and missing or stale rules) first
            fns = make_planners(list(planners), run_dir, config=planner_config)
            sets = problem_sets(problems_dir)
            problems = load_sets(sets)
            settings = _settings(run_dir, sets, problems, list(planners), execution, planner_config)
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
            run_rows_ray(run_dir, problems, list(fns), settings, log, execution, show_progress,
                          Path(record_dir) if record_dir else None, workers, address)
        rows = run_rows(run_dir, problems, fns, log, execution, show_progress and engine != "ray", record_dir)
    finally:
        log.close()
    result = {"run": str(run_dir), "problems": str(sets[0]) if len(sets) == 1 else [str(d) for d in sets],
              "n_problems": len(problems), "planners": list(planners), "closed_loop": execution.closed_loop,
              "timeout_s": execution.timeout_s, "max_replans": execution.max_replans,
              **{k: settings[k] for k in dataclasses.asdict(PlannerConfig()) if k in settings},
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
