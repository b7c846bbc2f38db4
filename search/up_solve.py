"""The planning work of one unified-planning call, run inside search.classical's worker process.

Engine choice, the compilers a problem needs (docs/DESIGN.md, "Encoding learned rules for the
planners"), the planner call with the time left, mapping a compiled plan back, validating it on
the original problem and replaying it to the predicted symbolic states. search.classical runs
`solve_here` in a process group of its own and enforces the time limit from outside.
"""
from __future__ import annotations

import re
import time
import warnings
from dataclasses import dataclass
from typing import Any

from pddl_export.pddl_writer import action_id_from_name, names_action_id
from search.result import PlanResult, PlanStatus, failed
from search.up_problem import predicted_states, problem_on_domain, with_only_actions

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
        steps = tuple("(" + " ".join([ai.action.name, *(str(p) for p in ai.actual_parameters)]) + ")"
                      for ai in plan.actions)
        if all(names_action_id(ai.action.name) for ai in plan.actions):
            ids = tuple(action_id_from_name(ai.action.name) for ai in plan.actions)
            states, note = predicted_states(checked, plan)
        else:  # a domain whose actions are not named by their action ids (the learned relational domain): steps
            ids, states, note = (), (), ""
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"plan mapping/validation failed: {type(e).__name__}: {e}", **extra)
    if note:
        extra["note"] = note
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=ids, predicted_states=states,
                      expansions=expansions, planning_time_s=time.perf_counter() - t0, extra=extra, steps=steps)


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


def solve_here(domain_text: str, problem_text: str, planner: str, timeout_s: float,
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
