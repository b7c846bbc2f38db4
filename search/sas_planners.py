"""Fast Downward and SymK search components on a directly written SAS+ task, as a PlanResult.

`solve_sas` feeds the task of pddl_export.sas_writer on standard input to the
`downward` search binary shipped in the up-fast-downward or up-symk wheel (the planners that
unified-planning calls, minus their translator, which takes seconds to minutes on the
learned domain) with an argument list, a wall-clock limit and an address-space limit.
SymK is a fork of Fast Downward with symbolic (BDD) search and reads the same format.
The plan is read back, replayed with the rules (it must reach the goal, else the encoding
is wrong and the result is an ERROR) and reported with the planner's own times:
`fd_search_time_s` (search only) and `fd_total_time_s` (reading the task + search), next to
`planner_time_s` (the process, wall clock) and `sas_write_time_s`.

    >>> r = solve_sas(SASEncoder(rules), [3, 7], [5, None], "fast-downward-sas", 10)  # doctest: +SKIP
    >>> r.status, r.plan, r.extra["fd_search_time_s"]                                 # doctest: +SKIP
    (<PlanStatus.SOLVED: 'solved'>, (4, 30), 0.00021)
"""
from __future__ import annotations

import importlib.util
import math
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from pddl_export.files import atomic_write_text
from pddl_export.pddl_writer import action_id_from_name
from pddl_export.rules import apply_rules
from pddl_export.sas_writer import Negation, SASEncoder, TaskTooLargeError
from search.processes import planner_guard, run_group, temp_dir
from search.result import PlanResult, PlanStatus, failed
from pddl_export.symbolic import SymbolicGoal


@dataclass(frozen=True)
class SASPlanner:
    """A search configuration of one Fast Downward-family binary."""

    package: str  # the Python package that ships the binary
    search: str  # the --search argument
    optimal: bool  # guarantees a shortest plan (unit costs)
    negation: Negation = Negation.AXIOMS  # the task form its heuristics accept (see pddl_export.sas_writer)


SAS_PLANNERS = {
    # eager greedy search with FF and preferred operators; on the 100 problems of docs/BENCHMARKS.md its plans
    # (1.64 actions) succeed as often as optimal ones, where lazy greedy's (2.07) crossed more rules_vs_net states
    "fast-downward-sas": SASPlanner("up_fast_downward", "let(hff, ff(), eager_greedy([hff], preferred=[hff]))", False),
    "fast-downward-sas-opt": SASPlanner("up_fast_downward", "astar(blind())", True),
    "symk-sas": SASPlanner("up_symk", "sym_bd()", True),  # symbolic bidirectional uniform-cost search
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


def _run_search(binary: Path, spec: SASPlanner, task_text: str, planner: str, timeout_s: float, write_s: float,
                memory_mb: int, t0: float, extra: dict) -> tuple[list[str], int | None] | PlanResult:
    """Run the search binary on the task (standard input): the plan's operator names and expansions, or a failure.

    The binary runs in its own process group in a symlearn-fd-* folder; the group is killed at the time
    limit, and both the group and the folder go on a kill of this process (search.processes).
    """
    with planner_guard(), temp_dir("symlearn-fd-") as tmp:  # for the plan file
        plan_path = tmp / "plan"
        args = [str(binary), "--search", spec.search, "--internal-plan-file", str(plan_path)]
        t1 = time.perf_counter()
        try:
            code, log, err, timed_out = run_group(
                args, task_text, max(timeout_s - write_s, 1e-3), cwd=tmp,
                after_start=(lambda pid: _limit_memory(pid, memory_mb)) if memory_mb else None)
        except OSError as e:
            return failed(planner, PlanStatus.ERROR, t0, f"could not run {planner}: {e}", **extra)
        if timed_out:
            return failed(planner, PlanStatus.TIMEOUT, t0, f"{planner} hit the {timeout_s:g} s time limit "
                          "(process group killed)", planner_time_s=time.perf_counter() - t1, **extra)
        extra["planner_time_s"] = time.perf_counter() - t1
        expansions = _read_log(log, extra)
        if code != 0 or not plan_path.is_file():
            status, why = _EXIT.get(code, (PlanStatus.ERROR, f"exited with code {code}"))
            why = why if status is PlanStatus.UNSOLVABLE else f"{planner} {why}"
            tail = (err.strip().splitlines() or [""])[-1]
            return failed(planner, status, t0, f"{why}{': ' + tail if status is PlanStatus.ERROR and tail else ''}",
                          **extra)
        names = [ln.strip()[1:-1] for ln in plan_path.read_text().splitlines() if ln.strip().startswith("(")]
    return names, expansions


def _replayed(encoder: SASEncoder, init: Sequence[int], goal: SymbolicGoal, names: list[str], planner: str,
              spec: SASPlanner, expansions: int | None, t0: float, extra: dict) -> PlanResult:
    """The plan as action ids, replayed with the rules; an ERROR if it names unknown operators or misses the goal."""
    try:
        plan = tuple(action_id_from_name(n) for n in names)
    except ValueError as e:
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} returned an unknown operator: {e}", **extra)
    states = [np.asarray([int(c) for c in init], np.int64)]
    for a in plan:
        states.append(apply_rules(encoder.rules, states[-1], a))
    if not goal.satisfied(states[-1])[0]:
        return failed(planner, PlanStatus.ERROR, t0, f"the plan does not reach the goal under the rules "
                      f"(the SAS+ encoding disagrees with apply_rules)", **extra)
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=plan,
                      predicted_states=tuple(tuple(int(c) for c in s) for s in states), expansions=expansions,
                      planning_time_s=time.perf_counter() - t0,
                      extra=dict(extra, optimal=spec.optimal))


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
        task = encoder.task(init, goal)
    except (ValueError, TaskTooLargeError) as e:
        return failed(planner, PlanStatus.ERROR, t0, str(e))
    goal_g = goal if isinstance(goal, SymbolicGoal) else SymbolicGoal(tuple(goal))
    write_s = time.perf_counter() - t0
    extra = {"sas_write_time_s": round(write_s, 6), "sas_variables": task.n_variables,
             "sas_operators": task.n_operators, "sas_effects": task.n_effects, "sas_axioms": task.n_axioms}
    if write_to is not None:
        atomic_write_text(Path(write_to), task.text)
    ran = _run_search(binary, spec, task.text, planner, timeout_s, write_s, memory_mb, t0, extra)
    if isinstance(ran, PlanResult):
        return ran
    names, expansions = ran
    return _replayed(encoder, init, goal_g, names, planner, spec, expansions, t0, extra)
