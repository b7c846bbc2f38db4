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
import re
import signal
import subprocess
import tempfile
import time
import warnings
from dataclasses import dataclass
from typing import Any

from pddl_export.pddl_writer import action_id_from_name
from search.processes import (DeadlineExceeded, forget_inherited, kill_group, planner_guard, register_group,
                              temp_dir, unregister_group, within)
from search.result import PlanResult, PlanStatus, failed, one_line
from search.up_problem import parsed_domain, predicted_states, problem_on_domain, with_only_actions


@dataclass(frozen=True)
class PlannerSpec:
    """How one planner name maps onto a unified-planning engine."""

    engine: str  # name in unified-planning's engine factory
    optimal: bool  # guarantees a shortest plan (unit costs)
    native_timeout: bool  # the engine enforces the timeout itself (a killed subprocess)
    params: tuple[tuple[str, str], ...] = ()  # engine parameters, e.g. a Fast Downward search string

    def __post_init__(self) -> None:
        if not self.engine:
            raise ValueError("engine must be a non-empty engine name")


PLANNERS: dict[str, PlannerSpec] = {
    "fast-downward": PlannerSpec("fast-downward", optimal=False, native_timeout=True),
    "fast-downward-opt": PlannerSpec("fast-downward-opt", optimal=True, native_timeout=True),
    # blind A*: optimal, and unlike fast-downward-opt's LM-cut it takes conditional effects and axioms
    "fast-downward-blind": PlannerSpec("fast-downward", optimal=True, native_timeout=True,
                                       params=(("fast_downward_search_config", "astar(blind())"),)),
    "symk": PlannerSpec("symk", optimal=False, native_timeout=True),
    "symk-opt": PlannerSpec("symk-opt", optimal=True, native_timeout=True),
    "pyperplan": PlannerSpec("pyperplan", optimal=False, native_timeout=False),
}

_EXPANDED_RE = re.compile(r"Expanded (\d+) state", re.IGNORECASE)


def _status_from_up(status: Any) -> PlanStatus:
    """The one adapter from unified-planning's PlanGenerationResultStatus to PlanStatus."""
    from unified_planning.engines import PlanGenerationResultStatus as S

    return {
        S.SOLVED_SATISFICING: PlanStatus.SOLVED,
        S.SOLVED_OPTIMALLY: PlanStatus.SOLVED,
        S.UNSOLVABLE_PROVEN: PlanStatus.UNSOLVABLE,
        S.UNSOLVABLE_INCOMPLETELY: PlanStatus.UNSOLVABLE,
        S.TIMEOUT: PlanStatus.TIMEOUT,
    }.get(status, PlanStatus.ERROR)


def _compile_steps(compile_conditional_effects: bool):
    """(compilation kind name, whether the problem needs it) in the order docs/DESIGN.md gives."""
    return [
        ("QUANTIFIERS_REMOVING", lambda p, k: k.has_existential_conditions() or k.has_universal_conditions()
         or k.has_forall_effects()),
        ("CONDITIONAL_EFFECTS_REMOVING", lambda p, k: compile_conditional_effects and k.has_conditional_effects()),
        ("GROUNDING", lambda p, k: any(a.parameters for a in p.actions)),
        ("DISJUNCTIVE_CONDITIONS_REMOVING", lambda p, k: k.has_disjunctive_conditions()),
        ("NEGATIVE_CONDITIONS_REMOVING", lambda p, k: k.has_negative_conditions()),
    ]


_FEW_ACTIONS = 1000  # above this many actions, plans are validated on the problem cut to the plan's actions


def _engine_class(planner: str, spec: PlannerSpec, t0: float) -> Any:
    """unified-planning's engine class for the spec, or a failed PlanResult (not installed)."""
    try:
        from unified_planning.shortcuts import get_environment
    except ImportError as e:
        return failed(planner, PlanStatus.ERROR, t0, f"unified-planning is not installed: {e}")
    env = get_environment()
    env.credits_stream = None
    if spec.engine not in env.factory.engines:
        return failed(planner, PlanStatus.ERROR, t0, f"engine {spec.engine!r} is not installed")
    return env.factory.engine(spec.engine)


def _read_problem(domain_text: str, problem_text: str, planner: str, t0: float, domain: Any, prebuilt: Any) -> Any:
    """The problem to solve (prebuilt, built on the cached domain, or parsed from both texts) or a failed PlanResult."""
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import get_environment

    original = prebuilt if prebuilt is not None else problem_on_domain(domain, problem_text) if domain is not None else None
    if original is None:
        try:
            original = PDDLReader(get_environment()).parse_problem_string(domain_text, problem_text)
        except Exception as e:  # noqa: BLE001 - any parser failure is reported, not raised
            return failed(planner, PlanStatus.ERROR, t0, f"PDDL parse failed: {type(e).__name__}: {e}")
    return original


@dataclass(frozen=True)
class _Compiled:
    """The problem the engine gets, its kind, and the compilations that led to it (in order)."""

    problem: Any
    kind: Any
    chain: tuple[Any, ...]
    names: tuple[str, ...]


def _compile(original: Any, pkind: Any, planner: str, spec: PlannerSpec, engine_cls: Any,
             compile_conditional_effects: bool, deadline: float, t0: float) -> _Compiled | PlanResult:
    """Add the length metric for optimal planners and apply the compilers the engine needs (docs/DESIGN.md order)."""
    from unified_planning.engines import CompilationKind
    from unified_planning.shortcuts import Compiler, MinimizeSequentialPlanLength

    problem, chain, names = original, [], []
    try:
        if spec.optimal:  # ask for a shortest plan explicitly, so the status says SOLVED_OPTIMALLY
            with_metric = original.clone()
            with_metric.add_quality_metric(MinimizeSequentialPlanLength())
            metric_kind = with_metric.kind
            if engine_cls.supports(metric_kind):
                problem, pkind = with_metric, metric_kind
        for kind_name, needed in _compile_steps(compile_conditional_effects):
            if engine_cls.supports(pkind):
                break
            if not needed(problem, pkind):
                continue
            kind = CompilationKind[kind_name]
            with Compiler(problem_kind=pkind, compilation_kind=kind) as compiler:
                compiled = compiler.compile(problem, kind)
            chain.append(compiled)
            names.append(kind_name.lower())
            problem = compiled.problem
            pkind = problem.kind
            if time.perf_counter() > deadline:
                return failed(planner, PlanStatus.TIMEOUT, t0, f"time limit reached while compiling ({kind_name.lower()})")
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"compilation failed: {type(e).__name__}: {e}")
    return _Compiled(problem, pkind, tuple(chain), tuple(names))


def _unsolved(res: Any, status: PlanStatus, planner: str, timeout_s: float, t0: float, extra: dict) -> PlanResult:
    """The failed result for a planner answer other than SOLVED, with the reason in words."""
    from unified_planning.engines import PlanGenerationResultStatus

    why = {PlanStatus.UNSOLVABLE: "no plan exists" if res.status == PlanGenerationResultStatus.UNSOLVABLE_PROVEN
           else "search space exhausted (no proof of unsolvability)",
           PlanStatus.TIMEOUT: f"{planner} hit the {timeout_s:g} s time limit"}.get(
               status, f"{planner} ended with {res.status.name}")
    return failed(planner, status, t0, why, **extra)


def _validated_plan(original: Any, plan: Any, chain: tuple[Any, ...], planner: str, t0: float,
                    expansions: int | None, extra: dict) -> PlanResult:
    """Map the plan back through the compilations, validate it on the original problem and replay it."""
    from unified_planning.engines import ValidationResultStatus
    from unified_planning.shortcuts import PlanValidator

    try:
        t2 = time.perf_counter()
        for compiled in reversed(chain):
            plan = plan.replace_action_instances(compiled.map_back_action_instance)
        # A sequential plan's validity depends on the initial state, the goal and the actions it uses,
        # so a large grounded problem is validated with only those (the validator and the simulator
        # recompute the problem kind, a walk over every action, several times).
        checked = original if len(original.actions) <= _FEW_ACTIONS else with_only_actions(original, plan)
        with PlanValidator(problem_kind=checked.kind, plan_kind=plan.kind) as validator:
            check = validator.validate(checked, plan)
        extra["validate_time_s"] = time.perf_counter() - t2
        if check.status != ValidationResultStatus.VALID:
            reason = getattr(check, "reason", None) or getattr(check, "inapplicable_action", None) or ""
            return failed(planner, PlanStatus.ERROR, t0, f"plan failed validation on the original problem {reason}", **extra)
        ids = tuple(action_id_from_name(ai.action.name) for ai in plan.actions)
        states, note = predicted_states(checked, plan)
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"plan mapping/validation failed: {type(e).__name__}: {e}", **extra)
    if note:
        extra["note"] = note
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=ids, predicted_states=states,
                      expansions=expansions, planning_time_s=time.perf_counter() - t0, extra=extra)


def _plan(problem: Any, planner: str, spec: PlannerSpec, timeout_s: float, deadline: float, t0: float,
          extra: dict) -> Any:
    """Run the engine on the compiled problem with the time left: (its result, seconds) or a failed PlanResult."""
    from unified_planning.shortcuts import OneshotPlanner

    remaining = deadline - time.perf_counter()
    if remaining <= 0:
        return failed(planner, PlanStatus.TIMEOUT, t0, "time limit reached before planning", **extra)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with OneshotPlanner(name=spec.engine, params=dict(spec.params)) as engine:
                t1 = time.perf_counter()
                res = engine.solve(problem, timeout=remaining if spec.native_timeout else None)
                return res, time.perf_counter() - t1
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} failed: {type(e).__name__}: {e}", **extra)


def _solve_here(domain_text: str, problem_text: str, planner: str, timeout_s: float,
                compile_conditional_effects: bool, domain: Any = None, prebuilt: Any = None) -> PlanResult:
    """The whole pipeline in this process (read, compile, plan, validate); never raises (ERROR instead)."""
    t0 = time.perf_counter()
    deadline = t0 + timeout_s
    spec = PLANNERS[planner]
    engine_cls = _engine_class(planner, spec, t0)
    if isinstance(engine_cls, PlanResult):
        return engine_cls
    original = _read_problem(domain_text, problem_text, planner, t0, domain, prebuilt)
    if isinstance(original, PlanResult):
        return original
    t_parse = time.perf_counter() - t0
    pkind = original.kind  # computed once per problem: it walks every action (11 s for 64,000 of them)
    if (pkind.has_conditional_effects() and not compile_conditional_effects
            and not engine_cls.supported_kind().has_conditional_effects()):
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} does not support CONDITIONAL_EFFECTS; use the "
                      "grounded STRIPS form (pddl_export.pddl_writer.strips_pddl) or compile_conditional_effects=True",
                      engine=spec.engine, parse_time_s=t_parse)
    comp = _compile(original, pkind, planner, spec, engine_cls, compile_conditional_effects, deadline, t0)
    if isinstance(comp, PlanResult):
        return comp
    extra: dict[str, Any] = {
        "engine": spec.engine, "parse_time_s": t_parse, "compile_time_s": time.perf_counter() - t0 - t_parse,
        "compilers": ",".join(comp.names), "n_actions": len(comp.problem.actions)}
    if not engine_cls.supports(comp.kind):
        missing = sorted(set(comp.kind.features) - set(engine_cls.supported_kind().features))
        hint = ("; use the grounded STRIPS form (pddl_export.pddl_writer.strips_pddl)"
                if "CONDITIONAL_EFFECTS" in missing else "")
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} does not support {', '.join(missing)}{hint}", **extra)
    ran = _plan(comp.problem, planner, spec, timeout_s, deadline, t0, extra)
    if isinstance(ran, PlanResult):
        return ran
    res, planner_time = ran
    from unified_planning.engines import PlanGenerationResultStatus

    extra.update(planner_time_s=planner_time, up_status=res.status.name,
                 optimal=res.status == PlanGenerationResultStatus.SOLVED_OPTIMALLY)
    found = _EXPANDED_RE.findall(" ".join(m.message for m in (res.log_messages or [])))
    expansions = int(found[-1]) if found else None
    status = _status_from_up(res.status)
    if not spec.native_timeout and time.perf_counter() > deadline:
        return failed(planner, PlanStatus.TIMEOUT, t0, f"{planner} ran past the {timeout_s:g} s limit "
                      f"({planner_time:.3f} s; it has no time limit of its own)", **extra)
    if status is not PlanStatus.SOLVED:
        return _unsolved(res, status, planner, timeout_s, t0, extra)
    if res.plan is None:
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} reported {res.status.name} without a plan", **extra)
    return _validated_plan(original, res.plan, comp.chain, planner, t0, expansions, extra)


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
        result = _solve_here(*args).to_json()
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
    """_solve_here(*args) in a child process group: (its JSON answer, None if it died, or "late"; its exit code).

    The group (the worker and the planner it started) is killed when the answer is in, at wait_s,
    and on a kill of this process; its temporary files live in a symlearn-up-* folder removed on return.
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
        return failed(name, PlanStatus.ERROR, t0, f"planner process died (exit code {exitcode})", total_time_s=total)
    if "error" in answer:
        return failed(name, PlanStatus.ERROR, t0, answer["error"], total_time_s=total)
    inner = PlanResult.from_json(answer)
    extra = dict(inner.extra)
    extra["total_time_s"] = total
    extra.setdefault("planner_time_s", 0.0)
    return PlanResult(planner=inner.planner, status=inner.status, plan=inner.plan,
                      predicted_states=inner.predicted_states, expansions=inner.expansions,
                      planning_time_s=total, message=inner.message, extra=extra)
