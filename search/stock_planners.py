"""Stock planners on PDDL files, run as a planning user outside the project would, as a PlanResult.

Fast Downward runs through its own driver, `fast-downward.py` from the up-fast-downward wheel,
with its own translator (`python -m fast_downward.translate`) and search binary; pyperplan runs
through its command line (`python -m pyperplan`). Nothing of the project's encoding is involved:
any (domain.pddl, problem.pddl) pair goes in, the ground plan the planner wrote comes out
(PlanResult.steps, e.g. "(pick-release b1 l0 l3)"), and, with `action_ids` (a map from the ground
steps to the robot's action ids, such as a lifted domain's plan_decoder), the plan as action ids.

Each call runs one process (an argument list, with sys.executable) in its own process group,
in a symlearn-stock-* folder that holds the planner's files (output.sas, sas_plan, the copies
pyperplan needs); the wall-clock limit covers the whole call, translation or grounding
included. At the limit the group is killed and the folder removed, and both go on a kill of
this process, SIGKILL included (search.processes and its watchdog). The address space is capped at
MEMORY_LIMIT_MB (search.processes): through the driver's own --overall-memory-limit for
Fast Downward, on the process for pyperplan; the driver also gets its own --overall-time-limit
(CPU time, a second past the call's limit), so it stops even with nobody left to kill it.

    >>> r = solve_files("domain.pddl", "p01.pddl", "fd-lama-first", timeout_s=10)  # doctest: +SKIP
    >>> r.status, r.steps, r.extra["fd_translate_time_s"], r.extra["fd_search_time_s"]  # doctest: +SKIP
    (<PlanStatus.SOLVED: 'solved'>, ('(pick-release b1 l0 l3)',), 0.012, 0.0003)

Fast Downward's times come from its log: `fd_translate_time_s` (the translator's own wall
clock), `fd_search_time_s` (search only), `fd_total_time_s` (the search component: reading
the task + search) and `fd_driver_time_s` (the driver's "Planner time"), next to
`planner_time_s` (the process, wall clock, as this module measured it). The translator's task
statistics come along: variables, derived variables, facts, operators, axioms, mutex groups, and
`translator_uncovered_facts`, the facts its invariant synthesis put in no group (0 when it found the
one-value-per-object structure of every predicate).
"""
from __future__ import annotations

import importlib.util
import math
import re
import shutil
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from search.processes import MEMORY_LIMIT_MB, external_signal, limit_memory, planner_guard, run_group, temp_dir
from search.result import PlanResult, PlanStatus, failed
from search.sas_task import KEEP_OPTIONS

MAX_INPUT_BYTES = 64 << 20  # a domain or problem file larger than this is refused before any work
MAX_PLAN_BYTES = 16 << 20  # a plan file larger than this is an ERROR (bounded read)

# astar with a merge-and-shrink abstraction: optimal, takes conditional effects (lmcut and ipdb do not);
# the bare merge_and_shrink() is a usage error in this build, so its options are spelled out
MERGE_AND_SHRINK = (
    "astar(merge_and_shrink(shrink_strategy=shrink_bisimulation(greedy=false),merge_strategy=merge_sccs("
    "order_of_sccs=topological,merge_selector=score_based_filtering(scoring_functions=[goal_relevance(),"
    "dfp(),total_order()])),label_reduction=exact(before_shrinking=true,before_merging=false),"
    "max_states=50000,threshold_before_merge=1))")


@dataclass(frozen=True)
class StockPlanner:
    """One configuration of a stock planner's command line."""

    tool: str  # "fast-downward" (its driver script) or "pyperplan" (python -m pyperplan)
    before_files: tuple[str, ...]  # options before the input files (Fast Downward: driver options, e.g. --alias)
    after_files: tuple[str, ...] = ()  # options after them (Fast Downward: component options, e.g. --search)
    optimal: bool = False  # guarantees a cheapest plan (action costs, else length)


STOCK_PLANNERS: dict[str, StockPlanner] = {
    # LAMA's first iteration: lazy greedy search with FF and landmarks, the usual satisficing baseline
    "fd-lama-first": StockPlanner("fast-downward", ("--alias", "lama-first")),
    # optimal A* with LM-cut: STRIPS with negative preconditions and action costs; refuses axioms and
    # conditional effects (exit 34)
    "fd-lmcut": StockPlanner("fast-downward", (), ("--search", "astar(lmcut())"), optimal=True),
    "fd-ms": StockPlanner("fast-downward", (), ("--search", MERGE_AND_SHRINK), optimal=True),
    "fd-blind": StockPlanner("fast-downward", (), ("--search", "astar(blind())"), optimal=True),
    # pyperplan: STRIPS with typing only (no negative preconditions, no conditional effects, no costs)
    "pyperplan": StockPlanner("pyperplan", ("-s", "gbf", "-H", "hff")),
    "pyperplan-opt": StockPlanner("pyperplan", ("-s", "astar", "-H", "lmcut"), optimal=True),
}

# Fast Downward's exit codes (driver/returncodes.py); 0-3 mean a plan was written
_FD_EXIT = {
    10: (PlanStatus.UNSOLVABLE, "the translator proved the task unsolvable"),
    11: (PlanStatus.UNSOLVABLE, "no plan exists (search space exhausted)"),
    12: (PlanStatus.UNSOLVABLE, "search space exhausted by an incomplete search (no proof)"),
    13: (PlanStatus.UNSOLVABLE, "no plan within the cost bound"),
    20: (PlanStatus.ERROR, "the translator ran out of memory"),
    21: (PlanStatus.TIMEOUT, "the translator ran out of time"),
    22: (PlanStatus.ERROR, "the search ran out of memory"),
    23: (PlanStatus.TIMEOUT, "the search ran out of time"),
    24: (PlanStatus.ERROR, "the search ran out of memory and time"),
    30: (PlanStatus.ERROR, "the translator failed"),
    31: (PlanStatus.ERROR, "the translator rejected the input"),
    32: (PlanStatus.ERROR, "the search failed"),
    33: (PlanStatus.ERROR, "the search rejected its input"),
    34: (PlanStatus.ERROR, "the search does not support this task"),
    35: (PlanStatus.ERROR, "the driver failed"),
    36: (PlanStatus.ERROR, "the driver rejected its input"),
    37: (PlanStatus.ERROR, "the driver does not support this"),
}

_FD_TIMES = {"fd_search_time_s": re.compile(r"\] Search time: ([0-9.eE+-]+)s"),
             "fd_total_time_s": re.compile(r"\] Total time: ([0-9.eE+-]+)s"),
             "fd_driver_time_s": re.compile(r"^INFO +Planner time: ([0-9.eE+-]+)s", re.M),
             "fd_translate_time_s": re.compile(r"^Done! \[[0-9.eE+-]+s CPU, ([0-9.eE+-]+)s wall-clock\]", re.M)}
_FD_STATS = re.compile(r"^Translator (variables|derived variables|facts|operators|axioms|mutex groups): (\d+)$", re.M)
_FD_UNCOVERED = re.compile(r"^(\d+) uncovered facts$", re.M)  # facts in no invariant group (binary variables)
_FD_EXPANDED = re.compile(r"Expanded (\d+) state")
_COST = re.compile(r"^;\s*cost\s*=\s*([0-9.eE+-]+)", re.M)
_PP_TIMES = {"pyperplan_search_time_s": re.compile(r"INFO +Search time: ([0-9.eE+-]+)")}
_PP_EXPANDED = re.compile(r"(\d+) Nodes expanded")
_PP_STAMP = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}) INFO +(Parsing Domain|Grounding end)", re.M)
_BYTES_REPR = re.compile(r"""^b(["'])(.*)\1$""")
# translator progress lines, left out of an error's reason
_NOISE = re.compile(r"^(INFO |\[t=|->|Parsing(\.\.\.| domain| problem)$|.*wall-clock\]$|.*exit code: -?\d+$"
                    r"|Driver aborting)")


def fast_downward_driver() -> Path | None:
    """The stock `fast-downward.py` driver script of the up-fast-downward wheel, or None if it is not installed."""
    spec = importlib.util.find_spec("up_fast_downward")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(list(spec.submodule_search_locations)[0]) / "downward" / "fast-downward.py"
    return path if path.is_file() else None


def _input_error(path: Path, what: str) -> str | None:
    """Why the input file cannot be planned on (one line naming it), or None."""
    if not path.exists():
        return f"{what} file not found: {path}"
    if not path.is_file():
        return f"{what} is not a file: {path}"
    size = path.stat().st_size
    if size > MAX_INPUT_BYTES:
        return f"{what} file is too large ({size} bytes; at most {MAX_INPUT_BYTES}): {path}"
    return None


def _reason(out: str, err: str, translator: bool = False) -> str:
    """The planner's own one-line account of a failure.

    For Fast Downward's translator, the error lines of its log (it prints them on standard output,
    its warnings on standard error); else, and where the log has none, the error output: a Python
    exception's last line, or its first lines.
    """
    if translator:
        section = out.split("Running translator.", 1)[-1].split("translate exit code", 1)[0]
        kept = [ln.strip() for ln in section.splitlines() if ln.strip() and not _NOISE.match(ln.strip())]
        if kept:
            return " ".join(kept[-2:])
    lines = []
    for ln in err.splitlines():
        m = _BYTES_REPR.match(ln.strip())  # the driver prints a component's captured stderr as a bytes literal
        lines += (m.group(2).split("\\n") if m else [ln])
    lines = [ln.strip() for ln in lines if ln.strip() and not re.match(r"^\d{4}-\d\d-\d\d .* (INFO|DEBUG) ", ln)]
    if any(ln.startswith("Traceback") for ln in lines):
        return lines[-1]  # a Python exception: its last line says what
    return " ".join([ln for ln in lines if not ln.startswith("Warning")][:3] or lines[:2])


def _read_plan(folder: Path, name: str) -> tuple[list[str], float | None] | str | None:
    """The ground steps and cost of the complete plan file `name` (or its best numbered one, `name.N`) in folder.

    None if there is none (a file without its closing "; cost" line was cut short by a kill); a str
    saying why if the file is over MAX_PLAN_BYTES.
    """
    path = folder / name
    if not path.is_file():
        numbered = [f for f in folder.glob(f"{name}.*") if f.suffix[1:].isdigit()]
        if not numbered:
            return None
        path = max(numbered, key=lambda f: int(f.suffix[1:]))  # an anytime search's last plan is its best
    size = path.stat().st_size
    if size > MAX_PLAN_BYTES:
        return f"the plan file is too large ({size} bytes; at most {MAX_PLAN_BYTES})"
    text = path.read_text(errors="replace")
    steps = [" ".join(ln.split()) for ln in text.splitlines() if ln.strip().startswith("(")]
    cost = _COST.search(text)
    if cost is None and name == "sas_plan":
        return None
    return steps, (float(cost.group(1)) if cost else None)


def _fd_log(out: str, extra: dict) -> int | None:
    """Put Fast Downward's own times and the translator's task sizes into extra; the expanded states or None."""
    for key, rx in _FD_TIMES.items():
        found = rx.findall(out)
        if found:
            extra[key] = float(found[-1])
    for name, n in _FD_STATS.findall(out):
        extra["translator_" + name.replace(" ", "_")] = int(n)
    uncovered = _FD_UNCOVERED.findall(out)
    if uncovered:
        extra["translator_uncovered_facts"] = int(uncovered[-1])
    expanded = _FD_EXPANDED.findall(out)
    return int(expanded[-1]) if expanded else None


def _pp_log(out: str, extra: dict) -> int | None:
    """Put pyperplan's search time and parse + ground time (from its log's time stamps) into extra."""
    for key, rx in _PP_TIMES.items():
        found = rx.findall(out)
        if found:
            extra[key] = float(found[-1])
    stamps = dict((what, ts) for ts, what in _PP_STAMP.findall(out))
    if len(stamps) == 2:
        from datetime import datetime

        t = {k: datetime.strptime(v, "%Y-%m-%d %H:%M:%S,%f") for k, v in stamps.items()}
        extra["pyperplan_ground_time_s"] = max((t["Grounding end"] - t["Parsing Domain"]).total_seconds(), 0.0)
    expanded = _PP_EXPANDED.findall(out)
    return int(expanded[-1]) if expanded else None


def _phase(out: str) -> str:
    """Which part of Fast Downward's run a kill stopped, from its log."""
    if "Running search" in out:
        return "search"
    return "translation" if "Running translator" in out else "start-up"


def _command(spec: StockPlanner, inputs: Sequence[Path], tmp: Path, memory_mb: int, left_s: float,
             translate_options: Sequence[str] = ()) -> list[str] | str:
    """The argument list of the run on `inputs` (a domain and a problem file, or Fast Downward's translated task:
    one SAS+ file, searched on alone), or a str saying why it cannot run.

    Fast Downward's driver gets limits of its own (a memory limit, and a CPU-time limit a second past the
    call's wall-clock limit of left_s): were this process and its watchdog both gone, it still stops. Its
    translator writes tmp/output.sas; `translate_options` are passed on to it.
    """
    if spec.tool == "fast-downward":
        driver = fast_downward_driver()
        if driver is None:
            return "Fast Downward's driver was not found (pip install up-fast-downward)"
        limits = ["--overall-time-limit", f"{math.ceil(left_s) + 1}s"]
        limits += ["--overall-memory-limit", f"{memory_mb}M"] if memory_mb else []
        sas = ["--sas-file", str(tmp / "output.sas")] if len(inputs) == 2 else []
        after = [*spec.after_files, *(["--translate-options", *translate_options] if translate_options else [])]
        return [sys.executable, str(driver), "--plan-file", str(tmp / "sas_plan"), *sas, *limits, *spec.before_files,
                *map(str, inputs), *after]
    if len(inputs) != 2 or translate_options:
        return "pyperplan plans on PDDL files alone (no translated task, no translator options)"
    if importlib.util.find_spec("pyperplan") is None:
        return "pyperplan is not installed (pip install pyperplan)"
    return [sys.executable, "-m", "pyperplan", "-l", "info", *spec.before_files, *map(str, inputs)]


def _finish(planner: str, spec: StockPlanner, code: int | None, out: str, err: str, plan_name: str, tmp: Path,
            action_ids: Callable[[Sequence[str]], Sequence[int]] | None, t0: float, extra: dict) -> PlanResult:
    """The PlanResult of a finished run, from its exit code, log and plan file."""
    fd = spec.tool == "fast-downward"
    expansions = _fd_log(out, extra) if fd else _pp_log(out, extra)
    read = _read_plan(tmp, plan_name) if code in (0, 1, 2, 3) else None
    if isinstance(read, str):
        return failed(planner, PlanStatus.ERROR, t0, f"{planner}: {read}", **extra)
    if read is None:
        if fd:
            status, why = _FD_EXIT.get(code, (PlanStatus.ERROR, f"exited with code {code}"))
        elif code == 0 and "No solution could be found" in out:
            status, why = PlanStatus.UNSOLVABLE, "no plan exists (search space exhausted)"
        else:
            status, why = PlanStatus.ERROR, f"exited with code {code}"
        if code is not None and code < 0:
            why = f"was killed by signal {-code}"
        if status is PlanStatus.ERROR:
            reason = _reason(out, err, translator=fd and code in (30, 31))
            why = f"{planner}: {why}" + (f": {reason}" if reason else "")
        return failed(planner, status, t0, why, **extra)
    steps, cost = read
    if cost is not None:
        extra["plan_cost"] = cost
    extra["optimal"] = spec.optimal
    ids: tuple[int, ...] = ()
    if action_ids is not None:
        try:
            ids = tuple(action_ids(steps))
        except (ValueError, KeyError) as e:
            return failed(planner, PlanStatus.ERROR, t0, f"{planner} returned a step that maps to no action: {e}",
                          **extra)
    try:
        return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=ids, predicted_states=(),
                          expansions=expansions, planning_time_s=time.perf_counter() - t0, extra=extra,
                          steps=tuple(steps))
    except (TypeError, ValueError) as e:  # e.g. action_ids gave an id outside 0..35
        return failed(planner, PlanStatus.ERROR, t0, f"{planner}'s plan does not map to action ids: {e}", **extra)


def _solve_in(tmp: Path, inputs: Sequence[Path], planner: str, timeout_s: float, t0: float,
              action_ids: Callable[[Sequence[str]], Sequence[int]] | None, memory_mb: int,
              translate_options: Sequence[str] = ()) -> PlanResult:
    """Run the planner on the input files (_command) with tmp as its working folder (inside planner_guard and
    temp_dir)."""
    spec = STOCK_PLANNERS[planner]
    if spec.tool == "pyperplan" and len(inputs) == 2 and inputs[1].parent != tmp:  # it writes PROBLEM.soln beside
        # the problem: it works on copies in the run's folder
        inputs = [Path(shutil.copyfile(f, tmp / name)) for f, name in zip(inputs, ("domain.pddl", "problem.pddl"))]
    left = timeout_s - (time.perf_counter() - t0)
    args = _command(spec, inputs, tmp, memory_mb, left, translate_options)
    if isinstance(args, str):
        return failed(planner, PlanStatus.ERROR, t0, args)
    if left <= 0:
        return failed(planner, PlanStatus.TIMEOUT, t0, f"time limit of {timeout_s:g} s reached before planning")
    limit = None if spec.tool == "fast-downward" or not memory_mb else (lambda pid: limit_memory(pid, memory_mb))
    t1 = time.perf_counter()
    try:
        code, out, err, timed_out = run_group(args, "", left, cwd=tmp, after_start=limit)
    except OSError as e:
        return failed(planner, PlanStatus.ERROR, t0, f"could not run {planner}: {e}")
    extra = {"planner_time_s": time.perf_counter() - t1}
    if timed_out:
        where = _phase(out) if spec.tool == "fast-downward" else "parsing, grounding or search"
        return failed(planner, PlanStatus.TIMEOUT, t0, f"{planner} hit the {timeout_s:g} s time limit during "
                      f"{where} (process group killed)", phase=where, **extra)
    killed = external_signal(code)
    if killed is not None:  # not a result: the benchmark must not record it (search.processes)
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} was killed by {signal.Signals(killed).name} (not by "
                      "its time limit)", killed_by_signal=killed, **extra)
    plan_name = "sas_plan" if spec.tool == "fast-downward" else inputs[1].name + ".soln"
    return _finish(planner, spec, code, out, err, plan_name, tmp, action_ids, t0, extra)


def _check(planner: str, timeout_s: float, t0: float) -> PlanResult | None:
    """ValueError for a bad time limit; an ERROR result for an unknown planner; else None."""
    if not (isinstance(timeout_s, (int, float)) and not isinstance(timeout_s, bool) and math.isfinite(timeout_s)
            and timeout_s > 0):
        raise ValueError(f"timeout_s must be a positive number, got {timeout_s!r}")
    if planner not in STOCK_PLANNERS:
        return failed(str(planner) or "unknown", PlanStatus.ERROR, t0,
                      f"unknown planner {planner!r}; known: {', '.join(STOCK_PLANNERS)}")
    return None


def solve_files(domain: Path | str, problem: Path | str, planner: str, timeout_s: float, *,
                action_ids: Callable[[Sequence[str]], Sequence[int]] | None = None, memory_mb: int = MEMORY_LIMIT_MB) -> PlanResult:
    """Plan on a domain and a problem file with a stock planner (STOCK_PLANNERS); failures come back as a status.

    SOLVED carries the ground steps (PlanResult.steps) and, with action_ids (ground steps -> action ids,
    ValueError or KeyError for a step it does not know), the plan as action ids; without it the plan
    is empty. UNSOLVABLE, TIMEOUT (the whole call past timeout_s) and ERROR (a missing or oversized
    file, an unknown planner, a planner that refuses the task: its own one-line reason) have no plan.
    ValueError for a bad timeout_s. The files are only read.
    """
    t0 = time.perf_counter()
    refused = _check(planner, timeout_s, t0)
    if refused is not None:
        return refused
    domain, problem = Path(domain).resolve(), Path(problem).resolve()
    bad = _input_error(domain, "domain") or _input_error(problem, "problem")
    if bad:
        return failed(planner, PlanStatus.ERROR, t0, bad)
    with planner_guard(), temp_dir("symlearn-stock-") as tmp:
        return _solve_in(tmp, [domain, problem], planner, timeout_s, t0, action_ids, memory_mb)


def solve_texts(domain_text: str, problem_text: str, planner: str, timeout_s: float, *,
                action_ids: Callable[[Sequence[str]], Sequence[int]] | None = None, memory_mb: int = MEMORY_LIMIT_MB) -> PlanResult:
    """solve_files on PDDL texts: they are written as domain.pddl and problem.pddl into the run's own folder."""
    return _solve_texts(domain_text, problem_text, planner, timeout_s, action_ids, memory_mb)[0]


def _solve_texts(domain_text: str, problem_text: str, planner: str, timeout_s: float,
                 action_ids: Callable[[Sequence[str]], Sequence[int]] | None = None, memory_mb: int = MEMORY_LIMIT_MB,
                 translate_options: Sequence[str] = ()) -> tuple[PlanResult, str | None]:
    """solve_texts, and the translator's output where it finished and wrote one (else None)."""
    t0 = time.perf_counter()
    refused = _check(planner, timeout_s, t0)
    if refused is not None:
        return refused, None
    for what, text in (("domain", domain_text), ("problem", problem_text)):
        if not isinstance(text, str) or len(text) > MAX_INPUT_BYTES:
            return failed(planner, PlanStatus.ERROR, t0, f"the {what} text must be a str of at most "
                          f"{MAX_INPUT_BYTES} characters"), None
    with planner_guard(), temp_dir("symlearn-stock-") as tmp:
        (tmp / "domain.pddl").write_text(domain_text)
        (tmp / "problem.pddl").write_text(problem_text)
        res = _solve_in(tmp, [tmp / "domain.pddl", tmp / "problem.pddl"], planner, timeout_s, t0, action_ids,
                        memory_mb, translate_options)
        return res, _translated(tmp / "output.sas", res)


def _translated(path: Path, res: PlanResult) -> str | None:
    """The translator's output at path where the translator finished and wrote it, within MAX_INPUT_BYTES; else
    None. (Where the translator found the goal unreachable or true at once it writes a trivial stand-in task of one
    made-up variable, which search.sas_task.Translation never reuses for a goal of real atoms.)"""
    if res.status is PlanStatus.ERROR or (res.status is PlanStatus.TIMEOUT and res.extra.get("phase") != "search"):
        return None
    if not path.is_file() or path.stat().st_size > MAX_INPUT_BYTES:
        return None
    return path.read_text()


def solve_keeping_translation(domain_text: str, problem_text: str, planner: str, timeout_s: float, *,
                              memory_mb: int = MEMORY_LIMIT_MB) -> tuple[PlanResult, str | None]:
    """solve_texts with Fast Downward, its translator told to keep what a later call over the same objects from
    another state to another goal needs (search.sas_task.KEEP_OPTIONS), and the translated task (SAS+ text) where
    the translator finished, else None."""
    if STOCK_PLANNERS.get(planner, StockPlanner("", ())).tool != "fast-downward":
        return solve_texts(domain_text, problem_text, planner, timeout_s, memory_mb=memory_mb), None
    return _solve_texts(domain_text, problem_text, planner, timeout_s, None, memory_mb, KEEP_OPTIONS)


def solve_sas_text(sas_text: str, planner: str, timeout_s: float, *, memory_mb: int = MEMORY_LIMIT_MB) -> PlanResult:
    """Fast Downward's search alone (the planner's configuration, STOCK_PLANNERS) on a translated task, as
    search.sas_task.Translation.task_for writes it: the steps are ground operators as from the PDDL files."""
    t0 = time.perf_counter()
    refused = _check(planner, timeout_s, t0)
    if refused is not None:
        return refused
    if STOCK_PLANNERS[planner].tool != "fast-downward":
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} does not read a translated task (SAS+)")
    if not isinstance(sas_text, str) or len(sas_text) > MAX_INPUT_BYTES:
        return failed(planner, PlanStatus.ERROR, t0, f"the task text must be a str of at most {MAX_INPUT_BYTES} "
                      "characters")
    with planner_guard(), temp_dir("symlearn-stock-") as tmp:
        (tmp / "task.sas").write_text(sas_text)
        return _solve_in(tmp, [tmp / "task.sas"], planner, timeout_s, t0, None, memory_mb)


_RECORD_KEYS = ("fd_translate_time_s", "fd_search_time_s", "fd_total_time_s", "fd_driver_time_s", "planner_time_s",
                "translator_variables", "translator_derived_variables", "translator_uncovered_facts",
                "translator_operators", "translator_axioms")


def call_record(result: PlanResult) -> dict:
    """One stock call as a flat JSON record: status, plan length and cost, expansions, the whole call's time, Fast
    Downward's own clocks and task sizes where it reported them, and translate + search (what bench/stock_fd.py and
    the domain studies in experiments/ compare)."""
    extra = dict(result.extra)
    rec = {"status": result.status.value, "plan_length": len(result.steps) if result.found else None,
           "plan_cost": extra.get("plan_cost"), "expansions": result.expansions, "message": result.message,
           "call_time_s": round(result.planning_time_s, 4)}
    rec.update({k: extra[k] for k in _RECORD_KEYS if k in extra})
    if "fd_translate_time_s" in extra and "fd_total_time_s" in extra:
        rec["translate_plus_search_s"] = round(extra["fd_translate_time_s"] + extra["fd_total_time_s"], 4)
    return rec


__all__ = ["STOCK_PLANNERS", "StockPlanner", "call_record", "fast_downward_driver", "solve_files",
           "solve_keeping_translation", "solve_sas_text", "solve_texts"]
