"""Running a benchmark's rows: every (problem, planner, loop) row the row log lacks, in order in this process
(run_rows) or one Ray task per (problem, planner) pair (run_rows_ray), each row logged as it finishes; a planner
killed by a signal stops the run without a row, so the same command again redoes it.
"""
from __future__ import annotations

import dataclasses
import json
import signal
from pathlib import Path
from typing import Callable

from pddl_export.files import finite_or_null
from search.processes import PlannerInterrupted
from symlearn.planning.benchmark_rows import RowLog, SetProblem
from symlearn.planning.execution import ExecutionConfig, ProblemRun, run_problem
from symlearn.planning.planners import PlannerConfig, make_planners
from symlearn.planning.recording import PlanRecorder


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
    from symlearn.planning.run_folder import Run

    held = next((f.rules for f in fns.values() if getattr(f, "rules", None) is not None), None)
    if held is not None:
        return held
    run = Run(run_dir)
    if not run.rules_file.is_file():
        return None
    try:
        return run.rules()[0]  # loaded and checked against the run's transition.pt
    except ValueError:
        return None


def _loops(execution: ExecutionConfig) -> list[bool]:
    """The loops each (problem, planner) pair runs: open loop, and closed loop too where execution.closed_loop."""
    return [False, True] if execution.closed_loop else [False]


def run_rows(run_dir: Path, problems: list[SetProblem], fns: dict, log: RowLog, execution: ExecutionConfig,
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


def _planner_config(settings: dict) -> PlannerConfig:
    """The planner config a benchmark's settings hold (the defaults where no planner weighs risk)."""
    return PlannerConfig(**{k: settings[k] for k in dataclasses.asdict(PlannerConfig()) if k in settings})


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
        fns = make_planners(list(planners), Path(run_dir), config=_planner_config(json.loads(settings_json)))
        encoder, transition = planning_models(Path(run_dir))
        _worker_state.update(settings=settings_json, fns=fns, encoder=encoder, transition=transition,
                             rules=_current_rules(Path(run_dir), fns), sim=TabletopSimulator())
    w, rows = _worker_state, []
    try:
        _run_pair(w["sim"], w["encoder"], w["transition"], w["rules"], p, name, _not_killed(w["fns"][name], name),
                  loops, execution, Path(record_dir) if record_dir else None,
                  lambda key, row: rows.append((key, row)))
    except PlannerInterrupted as e:  # no row for it: the driver logs the rows before it, then stops (run_rows_ray)
        rows.append((INTERRUPTED, {"signum": e.signum, "message": str(e)}))
    return rows


def run_rows_ray(run_dir: Path, problems: list[SetProblem], planners: list[str], settings: dict, log: RowLog,
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
