"""Fast Downward and SymK search components on a directly written SAS+ task, as a PlanResult.

`solve_sas` feeds the task of pddl_export.sas_writer on standard input to the
`downward` search binary shipped in the up-fast-downward or up-symk wheel (the planners that
unified-planning calls, minus their translator, which takes seconds to minutes on the
learned domain) with an argument list, a wall-clock limit and an address-space limit.
SymK is a fork of Fast Downward with symbolic (BDD) search and reads the same format.
The plan is read back, replayed with the rules (it must reach the goal, else the encoding
is wrong and the result is an ERROR) and reported with the planner's own times:
`fd_search_time_s` (search only) and `fd_total_time_s` (reading the task + search), next to
`planner_time_s` (the process, wall clock) and `sas_write_time_s`. "symk-sas-topk" runs symk-sas, then
SymK's top-k search for the TOP_K shortest loopless plans: the best is the result's plan, the others
(each replayed with the rules the same way) its `alternatives`, shortest first.

    >>> r = solve_sas(SASEncoder(rules), [3, 7], [5, None], "fast-downward-sas", 10)  # doctest: +SKIP
    >>> r.status, r.plan, r.extra["fd_search_time_s"]                                 # doctest: +SKIP
    (<PlanStatus.SOLVED: 'solved'>, (4, 30), 0.00021)
"""
from __future__ import annotations

import importlib.util
import math
import re
import signal
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from pddl_export.files import atomic_write_text
from pddl_export.pddl_writer import action_id_from_name
from pddl_export.rules import apply_rules
from pddl_export.sas_writer import Negation, SASEncoder, TaskTimeoutError, TaskTooLargeError
from search.processes import external_signal, planner_guard, run_group, temp_dir
from search.result import PlanResult, PlanStatus, failed
from pddl_export.symbolic import SymbolicGoal


@dataclass(frozen=True)
class SASPlanner:
    """A search configuration of one Fast Downward-family binary."""

    package: str  # the Python package that ships the binary
    search: str  # the --search argument
    optimal: bool  # guarantees a shortest plan (unit costs)
    negation: Negation = Negation.AXIOMS  # the task form its heuristics accept (see pddl_export.sas_writer)
    top_k: int = 1  # plans asked for: more than one comes back as PlanResult.alternatives (SymK only)


TOP_K = 5  # plans symk-sas-topk asks for: the best, and up to four to fall back on
TOP_K_SLACK = 2  # its further plans are at most this many actions longer than the best


def top_k_search(k: int, bound: int) -> str:
    """SymK's top-k search for the k shortest loopless plans shorter than `bound` (written to plan.1 .. plan.k).

    simple=true: no plan visits a state twice, so an alternative is not the best plan with a wasted step.
    """
    return f"symk_bd(simple=true, bound={bound}, plan_selection=top_k(num_plans={k}))"


SAS_PLANNERS = {
    # eager greedy search with FF and preferred operators; on the 100 problems of docs/BENCHMARKS.md its plans
    # (1.64 actions) succeed as often as optimal ones, where lazy greedy's (2.07) crossed more rules_vs_net states
    "fast-downward-sas": SASPlanner("up_fast_downward", "let(hff, ff(), eager_greedy([hff], preferred=[hff]))", False),
    "fast-downward-sas-opt": SASPlanner("up_fast_downward", "astar(blind())", True),
    "symk-sas": SASPlanner("up_symk", "sym_bd()", True),  # symbolic bidirectional uniform-cost search
    # symk-sas first (SymK's top-k search never ends on a task without plans, even under a bound), then the
    # top-k search bounded by the best plan's length + TOP_K_SLACK for the further plans (see _more_plans)
    "symk-sas-topk": SASPlanner("up_symk", "sym_bd()", True, top_k=TOP_K),
    # optimal A* with a merge-and-shrink abstraction (bisimulation, DFP merging): the strong admissible heuristic
    # that takes conditional effects; it refuses axioms, so the task tracks "z does not hold X" in effects
    "fast-downward-sas-ms": SASPlanner(
        "up_fast_downward",
        "astar(merge_and_shrink(shrink_strategy=shrink_bisimulation(greedy=false), merge_strategy=merge_sccs("
        "order_of_sccs=topological, merge_selector=score_based_filtering(scoring_functions=[goal_relevance(), "
        "dfp(), total_order()])), label_reduction=exact(before_shrinking=true, before_merging=false), "
        "max_states=50000, threshold_before_merge=1))", True, Negation.EFFECTS),
    # LAMA's first iteration: lazy greedy search with FF and landmark-sum heuristics and preferred operators
    "fast-downward-sas-lama": SASPlanner(
        "up_fast_downward",
        "let(hlm, landmark_sum(lm_factory=lm_reasonable_orders_hps(lm_rhw()), pref=false), let(hff, ff(), "
        "lazy_greedy([hff, hlm], preferred=[hff, hlm], reopen_closed=false)))", False, Negation.EFFECTS),
}
_BINARY_DIRS = {"up_fast_downward": "downward", "up_symk": "symk"}
MEMORY_LIMIT_MB = 4096

_TIME_RE = {k: re.compile(rf"\] {k}: ([0-9.eE+-]+)s") for k in ("Search time", "Total time")}
_EXPANDED_RE = re.compile(r"Expanded (\d+) state")
_EXIT = {11: (PlanStatus.UNSOLVABLE, "no plan exists (search space exhausted)"),  # Fast Downward's exit codes
         12: (PlanStatus.UNSOLVABLE, "search space exhausted by an incomplete search (no proof)"),
         22: (PlanStatus.ERROR, "ran out of memory"),
         23: (PlanStatus.TIMEOUT, "ran out of time"),
         33: (PlanStatus.ERROR, "rejected the SAS+ input"),
         34: (PlanStatus.ERROR, "does not support this search on the task")}


def search_binary(package: str = "up_fast_downward") -> Path | None:
    """The `downward` search binary shipped in `package` (up_fast_downward or up_symk), or None."""
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations or package not in _BINARY_DIRS:
        return None
    root = Path(list(spec.submodule_search_locations)[0]) / _BINARY_DIRS[package]
    path = root / "builds" / "release" / "bin" / "downward"
    return path if path.is_file() else None


def _limit_memory(pid: int, mb: int) -> None:
    """Cap the address space of a started process (after the start, so Python can vfork)."""
    try:
        import resource

        resource.prlimit(pid, resource.RLIMIT_AS, (mb << 20, mb << 20))
    except (ImportError, AttributeError, OSError, ProcessLookupError):  # not Linux, or it already ended
        pass


def _read_log(log: str, extra: dict) -> int | None:
    """Put the planner's own search and total times into extra; the number of expanded states (None if absent)."""
    for key, name in (("Search time", "fd_search_time_s"), ("Total time", "fd_total_time_s")):
        found = _TIME_RE[key].findall(log)
        if found:
            extra[name] = float(found[-1])
    expanded = _EXPANDED_RE.findall(log)
    return int(expanded[-1]) if expanded else None


def _read_plans(folder: Path) -> list[list[str]]:
    """Operator names of each complete plan the binary wrote: `plan`, or `plan.1`, `plan.2`, ... for top-k.

    A file without its closing "; cost" line was cut short by a kill and is left out.
    """
    files = [folder / "plan"] if (folder / "plan").is_file() else sorted(
        (f for f in folder.glob("plan.*") if f.suffix[1:].isdigit()), key=lambda f: int(f.suffix[1:]))
    plans = []
    for f in files:
        lines = [ln.strip() for ln in f.read_text().splitlines()]
        if any(ln.startswith("; cost") for ln in lines):
            plans.append([ln[1:-1] for ln in lines if ln.startswith("(")])
    return plans


def _run_search(binary: Path, search: str, task_text: str, planner: str, timeout_s: float, spent_s: float,
                memory_mb: int, t0: float, extra: dict,
                partial_ok: bool = False) -> tuple[list[list[str]], int | None] | PlanResult:
    """Run the search binary on the task (standard input): its plans' operator names and expansions, or a failure.

    The binary runs in its own process group in a symlearn-fd-* folder for timeout_s - spent_s; the group
    is killed at the limit, and both the group and the folder go on a kill of this process
    (search.processes). With partial_ok, a search stopped by the limit returns the plans it had completed
    (extra["top_k_timed_out"]).
    """
    with planner_guard(), temp_dir("symlearn-fd-") as tmp:  # for the plan files
        args = [str(binary), "--search", search, "--internal-plan-file", str(tmp / "plan")]
        t1 = time.perf_counter()
        try:
            code, log, err, timed_out = run_group(
                args, task_text, max(timeout_s - spent_s, 1e-3), cwd=tmp,
                after_start=(lambda pid: _limit_memory(pid, memory_mb)) if memory_mb else None)
        except OSError as e:
            return failed(planner, PlanStatus.ERROR, t0, f"could not run {planner}: {e}", **extra)
        plans = _read_plans(tmp) if code == 0 or (timed_out and partial_ok) else []
        if timed_out and not plans:
            return failed(planner, PlanStatus.TIMEOUT, t0, f"{planner} hit the {timeout_s:g} s time limit "
                          "(process group killed)", planner_time_s=time.perf_counter() - t1, **extra)
        extra["planner_time_s"] = time.perf_counter() - t1
        if timed_out:
            extra["top_k_timed_out"] = True
        expansions = _read_log(log, extra)
        killed = external_signal(code)
        if killed is not None and not plans:  # not a result: the benchmark must not record it (search.processes)
            return failed(planner, PlanStatus.ERROR, t0, f"{planner} was killed by {signal.Signals(killed).name} "
                          "(not by its time limit)", killed_by_signal=killed, **extra)
        if not plans:
            status, why = _EXIT.get(code, (PlanStatus.ERROR, f"exited with code {code}"))
            why = why if status is PlanStatus.UNSOLVABLE else f"{planner} {why}"
            tail = (err.strip().splitlines() or [""])[-1]
            return failed(planner, status, t0, f"{why}{': ' + tail if status is PlanStatus.ERROR and tail else ''}",
                          **extra)
    return plans, expansions


def _more_plans(binary: Path, k: int, best: int, task_text: str, planner: str, timeout_s: float, memory_mb: int,
                t0: float, extra: dict) -> list[list[str]] | None:
    """The k shortest loopless plans at most TOP_K_SLACK longer than the best (of length `best`), in the time
    left; on a failure or time-out, only those completed, or None (the first search's plan stands alone)."""
    more, t2 = {}, time.perf_counter()
    ran = _run_search(binary, top_k_search(k, best + 1 + TOP_K_SLACK), task_text, planner, timeout_s,
                      t2 - t0, memory_mb, t0, more, partial_ok=True)
    extra["top_k_time_s"] = time.perf_counter() - t2
    extra["planner_time_s"] = extra.get("planner_time_s", 0.0) + extra["top_k_time_s"]  # both processes
    for key in ("fd_total_time_s", "fd_search_time_s"):
        if key in more:
            extra[key] = extra.get(key, 0.0) + more[key]
    if isinstance(ran, PlanResult):
        extra["top_k_timed_out"] = ran.status is PlanStatus.TIMEOUT
        return None
    extra["top_k_timed_out"] = bool(more.get("top_k_timed_out"))
    return ran[0]


def _replay(rules, init: Sequence[int], names: list[str]) -> tuple[tuple[int, ...], tuple[tuple[int, ...], ...]]:
    """A plan's action ids and the states the rules predict along it (ValueError on an unknown operator)."""
    plan = tuple(action_id_from_name(n) for n in names)
    states = [np.asarray([int(c) for c in init], np.int64)]
    for a in plan:
        states.append(apply_rules(rules, states[-1], a))
    return plan, tuple(tuple(int(c) for c in s) for s in states)


def _replayed(encoder: SASEncoder, init: Sequence[int], goal: SymbolicGoal, plans: list[list[str]], planner: str,
              spec: SASPlanner, expansions: int | None, t0: float, extra: dict) -> PlanResult:
    """The best plan as action ids, replayed with the rules; an ERROR if it names unknown operators or misses
    the goal. Further plans (top-k) become alternatives, shortest first; any that miss the goal are dropped."""
    try:
        plan, states = _replay(encoder.rules, init, plans[0])
    except ValueError as e:
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} returned an unknown operator: {e}", **extra)
    if not goal.satisfied(np.asarray(states[-1]))[0]:
        return failed(planner, PlanStatus.ERROR, t0, f"the plan does not reach the goal under the rules "
                      f"(the SAS+ encoding disagrees with apply_rules)", **extra)
    alternatives, dropped = {}, 0
    for names in plans[1:]:
        try:
            alt, alt_states = _replay(encoder.rules, init, names)
        except ValueError:
            dropped += 1
            continue
        if alt == plan or alt in alternatives or not goal.satisfied(np.asarray(alt_states[-1]))[0]:
            dropped += 1
            continue
        alternatives[alt] = alt_states
    if spec.top_k > 1:
        extra = dict(extra, top_k_plans=1 + len(alternatives), top_k_dropped=dropped)
    ordered = sorted(alternatives.items(), key=lambda kv: len(kv[0]))  # stable: the planner's order within a length
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=plan, predicted_states=states,
                      expansions=expansions, planning_time_s=time.perf_counter() - t0,
                      extra=dict(extra, optimal=spec.optimal), alternatives=tuple(ordered))


def solve_sas(encoder: SASEncoder, init: Sequence[int], goal: SymbolicGoal | Sequence[int | None], planner: str,
              timeout_s: float, *, memory_mb: int = MEMORY_LIMIT_MB, write_to: Path | None = None) -> PlanResult:
    """Plan from init to goal codes with a SAS+ planner (SAS_PLANNERS); failures come back as a status.

    ValueError for a bad timeout; unknown codes, an unknown planner, a missing binary, a crash,
    a time-out or a task too large are PlanResult statuses with a one-line message. With
    write_to, the task is also saved there (e.g. RUN/plans/task.sas).
    """
    t0 = time.perf_counter()
    if not (isinstance(timeout_s, (int, float)) and math.isfinite(timeout_s) and timeout_s > 0):
        raise ValueError(f"timeout_s must be a positive number, got {timeout_s!r}")
    if planner not in SAS_PLANNERS:
        return failed(planner or "unknown", PlanStatus.ERROR, t0,
                      f"unknown planner {planner!r}; known: {', '.join(SAS_PLANNERS)}")
    spec = SAS_PLANNERS[planner]
    binary = search_binary(spec.package)
    if binary is None:
        return failed(planner, PlanStatus.ERROR, t0, f"the search binary of {spec.package} was not found "
                      f"(pip install {spec.package.replace('_', '-')})")
    encoder = encoder.with_negation(spec.negation)
    try:
        task = encoder.task(init, goal, deadline=t0 + timeout_s)
    except TaskTimeoutError as e:
        return failed(planner, PlanStatus.TIMEOUT, t0, str(e))
    except (ValueError, TaskTooLargeError) as e:
        return failed(planner, PlanStatus.ERROR, t0, str(e))
    goal_g = goal if isinstance(goal, SymbolicGoal) else SymbolicGoal(tuple(goal))
    write_s = time.perf_counter() - t0
    extra = {"sas_write_time_s": round(write_s, 6), "sas_variables": task.n_variables,
             "sas_operators": task.n_operators, "sas_effects": task.n_effects, "sas_axioms": task.n_axioms}
    if write_to is not None:
        atomic_write_text(Path(write_to), task.text)
    ran = _run_search(binary, spec.search, task.text, planner, timeout_s, write_s, memory_mb, t0, extra)
    if isinstance(ran, PlanResult):
        return ran
    plans, expansions = ran
    if spec.top_k > 1:
        plans = _more_plans(binary, spec.top_k, len(plans[0]), task.text, planner, timeout_s, memory_mb, t0,
                            extra) or plans
    return _replayed(encoder, init, goal_g, plans, planner, spec, expansions, t0, extra)
