"""Solve exported PDDL with classical planners through unified-planning, as a PlanResult.

    >>> from search.classical import solve_pddl
    >>> r = solve_pddl(domain_text, problem_text, planner="fast-downward", timeout_s=10)  # doctest: +SKIP
    >>> r.status, r.plan, r.extra["planner_time_s"]                                      # doctest: +SKIP
    (<PlanStatus.SOLVED: 'solved'>, (3, 22), 0.41)

The whole call (parse, compile, plan, map back, validate, simulate) runs in a worker process
that leads its own process group, with the planner subprocesses unified-planning starts kept
in that group and its temporary files in a symlearn-up-* folder (search.processes). The caller
kills the whole group if no answer came within timeout_s + grace_s (a TIMEOUT), and on a kill
of the caller; the planner itself gets the time left of timeout_s. Pyperplan has no time limit
of its own: a run that ends after timeout_s is reported as TIMEOUT. With cache_domain, the
domain is parsed in the caller (once, cached) under the same time limit.

When the chosen engine does not accept the problem as written, unified-planning compilers
are applied in the order given in docs/DESIGN.md ("Encoding learned rules for the planners":
quantifiers removing, grounding, disjunctive- and negative-conditions removing), each only
when needed. Conditional effects
are compiled away only on request (compile_conditional_effects=True): that compiler makes
2^(number of conditional effects) actions per action, so for pyperplan and
fast-downward-opt the grounded STRIPS form of pddl_export.pddl_writer is the scalable route.
Plans of the compiled problem are mapped back (map_back_action_instance, in reverse order),
validated on the original problem with unified-planning's PlanValidator, converted to
action ids by name (`pick-P-release-R[-sN]` -> P * 6 + R) and replayed with the
SequentialSimulator to report the predicted symbolic states (objects `o<i>`, predicates
`code-<bits>`). Building and reading the problems is search.up_problem's job.
"""
from __future__ import annotations

import math
import multiprocessing as mp
import os
import signal
import subprocess
import tempfile
import time
from typing import Any

from search.processes import (DeadlineExceeded, external_signal, forget_inherited, kill_group, planner_guard,
                              register_group, temp_dir, unregister_group, within)
from search.result import PlanResult, PlanStatus, failed, one_line
from search.up_problem import parsed_domain
from search.up_solve import PLANNERS, solve_here


class _SameGroupPopen(subprocess.Popen):
    """Popen that keeps the planner in the worker's process group (unified-planning starts it in a new session)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["start_new_session"] = False
        super().__init__(*args, **kwargs)


def _enter_own_group(tmp: str) -> None:
    """In the worker: lead a new process group that keeps the planners, with temp files and cwd in tmp."""
    forget_inherited()
    os.setsid()
    # unified-planning stops a planner at its time limit with SIGTERM to the planner's group, which is
    # now this one: the worker outlives it (a handler, unlike SIG_IGN, is not inherited across exec)
    signal.signal(signal.SIGTERM, lambda signum, frame: None)
    subprocess.Popen = _SameGroupPopen  # type: ignore[misc] - this process only runs planner calls
    tempfile.tempdir = tmp
    os.environ["TMPDIR"] = tmp
    os.chdir(tmp)


def _worker(conn: Any, tmp: str, *args: Any) -> None:
    try:
        _enter_own_group(tmp)
        result = solve_here(*args).to_json()
    except BaseException as e:  # noqa: BLE001 - the parent must hear about anything
        result = {"error": one_line(f"{type(e).__name__}: {e}")}
    try:
        conn.send(result)
    finally:
        conn.close()


def _context() -> Any:
    methods = mp.get_all_start_methods()
    return mp.get_context("fork" if "fork" in methods else "spawn")


def _check_limits(timeout_s: float, grace_s: float) -> None:
    """ValueError unless timeout_s > 0 and grace_s >= 0 are finite numbers."""
    if not (isinstance(timeout_s, (int, float)) and math.isfinite(timeout_s) and timeout_s > 0):
        raise ValueError(f"timeout_s must be a positive number, got {timeout_s!r}")
    if not (math.isfinite(grace_s) and grace_s >= 0):
        raise ValueError(f"grace_s must be >= 0, got {grace_s!r}")


def _prepare(name: str, t0: float) -> PlanResult | None:
    """Load unified-planning (so a forked child starts with it): None, or a failed PlanResult."""
    if name not in PLANNERS:
        return failed(name or "unknown", PlanStatus.ERROR, t0, f"unknown planner {name!r}; known: {', '.join(PLANNERS)}",
                      total_time_s=time.perf_counter() - t0)
    try:
        import unified_planning.shortcuts  # noqa: F401
        from unified_planning.shortcuts import get_environment

        get_environment().credits_stream = None
    except ImportError as e:
        return failed(name, PlanStatus.ERROR, t0, f"unified-planning is not installed: {e}",
                      total_time_s=time.perf_counter() - t0)
    return None


def _run_guarded(args: tuple, wait_s: float) -> tuple[Any, int | None]:
    """solve_here(*args) in a child process group: (its JSON answer, None if it died, or "late"; its exit code).

    The group (the worker and the planner it started) is killed when the answer is in, at wait_s,
    and on a kill of this process (by search.processes' watchdog where this process cannot: SIGKILL);
    its temporary files live in a symlearn-up-* folder removed on return.
    """
    ctx = _context()
    answer: Any = None  # stays None if the child dies (or on an exception here); "late" at the deadline
    with planner_guard(), temp_dir("symlearn-up-") as tmp:
        recv, send = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_worker, args=(send, str(tmp), *args), daemon=True)
        proc.start()
        register_group(proc.pid)
        send.close()
        try:
            if recv.poll(max(wait_s, 0.0)):
                try:
                    answer = recv.recv()
                except EOFError:
                    answer = None
            else:
                answer = "late"
        finally:
            recv.close()
            kill_group(proc.pid)
            proc.join(5.0)
            unregister_group(proc.pid)
    return answer, proc.exitcode


def _cached_domain(name: str, domain_text: str, timeout_s: float, t0: float) -> Any:
    """The parsed domain (cached across calls), parsed within the call's time limit: the domain or a failed PlanResult."""
    try:
        return within(lambda: parsed_domain(domain_text), timeout_s - (time.perf_counter() - t0))
    except DeadlineExceeded:
        return failed(name, PlanStatus.TIMEOUT, t0, f"time limit of {timeout_s:g} s reached while parsing the domain",
                      total_time_s=time.perf_counter() - t0, planner_time_s=0.0)
    except Exception as e:  # noqa: BLE001
        return failed(name, PlanStatus.ERROR, t0, f"PDDL parse failed: {type(e).__name__}: {e}",
                      total_time_s=time.perf_counter() - t0)


def solve_pddl(
    domain_text: str,
    problem_text: str,
    planner: str,
    timeout_s: float,
    *,
    compile_conditional_effects: bool = False,
    grace_s: float = 0.5,
    cache_domain: bool = False,
    problem: Any = None,
) -> PlanResult:
    """Run one classical planner on PDDL text; every failure comes back as a status, never raised.

    Planners: "fast-downward" (satisficing, lama-first), "fast-downward-opt" (LM-cut; no conditional
    effects), "fast-downward-blind" (blind A*, optimal, takes conditional effects), "symk", "symk-opt",
    "pyperplan". The call takes at most about timeout_s + grace_s seconds (plus loading unified-planning
    once per process); past timeout_s it is a TIMEOUT. With cache_domain, the domain is parsed once in
    this process (parsed_domain; within the first call's time limit) and each call reads only the problem.
    With `problem` (a unified-planning Problem equal to the texts, e.g. search.up_problem.strips_problem),
    nothing is parsed.
    """
    t0 = time.perf_counter()
    _check_limits(timeout_s, grace_s)
    name = str(planner)
    refused = _prepare(name, t0)
    if refused is not None:
        return refused
    domain = _cached_domain(name, domain_text, timeout_s, t0) if cache_domain and problem is None else None
    if isinstance(domain, PlanResult):
        return domain
    left = timeout_s - (time.perf_counter() - t0)
    if left <= 0:
        return failed(name, PlanStatus.TIMEOUT, t0, f"time limit of {timeout_s:g} s reached before planning",
                      total_time_s=time.perf_counter() - t0, planner_time_s=0.0)
    answer, exitcode = _run_guarded((domain_text, problem_text, name, left, compile_conditional_effects,
                                     domain, problem), left + grace_s)
    total = time.perf_counter() - t0
    if answer == "late":
        return failed(name, PlanStatus.TIMEOUT, t0, f"{name} hit the {timeout_s:g} s time limit "
                      f"(no answer after {total:.2f} s; planner process group killed)",
                      total_time_s=total, planner_time_s=total)
    if answer is None:
        killed = external_signal(exitcode)
        if killed is not None:  # not a result: the benchmark must not record it (search.processes)
            return failed(name, PlanStatus.ERROR, t0, f"{name} was killed by {signal.Signals(killed).name} (not by "
                          "its time limit)", total_time_s=total, killed_by_signal=killed)
        return failed(name, PlanStatus.ERROR, t0, f"planner process died (exit code {exitcode})", total_time_s=total)
    if "error" in answer:
        return failed(name, PlanStatus.ERROR, t0, answer["error"], total_time_s=total)
    inner = PlanResult.from_json(answer)
    if total > timeout_s:  # an answer inside the grace period still came after the limit
        return failed(name, PlanStatus.TIMEOUT, t0, f"{name} hit the {timeout_s:g} s time limit (answered "
                      f"{inner.status.value} after {total:.2f} s)", total_time_s=total,
                      planner_time_s=inner.extra.get("planner_time_s", total))
    extra = dict(inner.extra)
    extra["total_time_s"] = total
    extra.setdefault("planner_time_s", 0.0)
    return PlanResult(planner=inner.planner, status=inner.status, plan=inner.plan,
                      predicted_states=inner.predicted_states, expansions=inner.expansions,
                      planning_time_s=total, message=inner.message, extra=extra, steps=inner.steps)
