"""Solve exported PDDL with classical planners through unified-planning, as a PlanResult.

    >>> from search.classical import solve_pddl
    >>> r = solve_pddl(domain_text, problem_text, planner="fast-downward", timeout_s=10)  # doctest: +SKIP
    >>> r.status, r.plan, r.extra["planner_time_s"]                                      # doctest: +SKIP
    (<PlanStatus.SOLVED: 'solved'>, (3, 22), 0.41)

The whole call (parse, compile, plan, map back, validate, simulate) runs in a child process
that the caller kills if it does not answer within timeout_s + grace_s, so no planner can
hang the caller; the planner itself gets the time left of timeout_s. Pyperplan has no time
limit of its own: a run that ends after timeout_s is reported as TIMEOUT. Fast Downward and
SymK run as subprocesses in their own session, killed by unified-planning at the time left;
grace_s leaves room for that before the guard fires.

When the chosen engine does not accept the problem as written, unified-planning compilers
are applied in the order of /work/shared/PDDL_NOTES.md (quantifiers removing, grounding,
disjunctive- and negative-conditions removing), each only when needed. Conditional effects
are compiled away only on request (compile_conditional_effects=True): that compiler makes
2^(number of conditional effects) actions per action, so for pyperplan and
fast-downward-opt the grounded STRIPS form of pddl_export.pddl_writer is the scalable route.
Plans of the compiled problem are mapped back (map_back_action_instance, in reverse order),
validated on the original problem with unified-planning's PlanValidator, converted to
action ids by name (`pick-P-release-R[-sN]` -> P * 6 + R) and replayed with the
SequentialSimulator to report the predicted symbolic states (objects `o<i>`, predicates
`code-<bits>`).
"""
from __future__ import annotations

import hashlib
import math
import multiprocessing as mp
import re
import time
import warnings
from dataclasses import dataclass
from typing import Any

from pddl_export.pddl_writer import (OBJECT_TYPE, StripsTask, action_id_from_name, action_name, code_from_predicate,
                                     code_predicate, object_index, object_name)
from search.result import PlanResult, PlanStatus, failed, one_line


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
    """(compilation kind name, whether the problem needs it) in the order PDDL_NOTES.md gives."""
    return [
        ("QUANTIFIERS_REMOVING", lambda p, k: k.has_existential_conditions() or k.has_universal_conditions()
         or k.has_forall_effects()),
        ("CONDITIONAL_EFFECTS_REMOVING", lambda p, k: compile_conditional_effects and k.has_conditional_effects()),
        ("GROUNDING", lambda p, k: any(a.parameters for a in p.actions)),
        ("DISJUNCTIVE_CONDITIONS_REMOVING", lambda p, k: k.has_disjunctive_conditions()),
        ("NEGATIVE_CONDITIONS_REMOVING", lambda p, k: k.has_negative_conditions()),
    ]


def _decode_state(state: Any, objects: list, fluents: list) -> tuple[int, ...]:
    """Per object (o0, o1, ...) the code whose predicate holds; -1 if not exactly one."""
    out = []
    for o in objects:
        held = [code for code, f in fluents if state.get_value(f(o)).bool_constant_value()]
        out.append(held[0] if len(held) == 1 else -1)
    return tuple(out)


def _predicted_states(problem: Any, plan: Any) -> tuple[tuple[tuple[int, ...], ...], str]:
    """Replay the plan on the original problem; ((), why) when objects/predicates are not ours."""
    from unified_planning.shortcuts import SequentialSimulator

    try:
        objects = sorted((o for o in problem.all_objects if o.type.name == OBJECT_TYPE),
                         key=lambda o: object_index(o.name))
        fluents = [(code_from_predicate(f.name), f) for f in problem.fluents]
    except ValueError as e:
        return (), f"no predicted states: {e}"
    if [object_index(o.name) for o in objects] != list(range(len(objects))):
        return (), "no predicted states: objects are not o0..oK-1"
    with SequentialSimulator(problem) as sim:
        state = sim.get_initial_state()
        states = [_decode_state(state, objects, fluents)]
        for ai in plan.actions:
            state = sim.apply(state, ai)
            states.append(_decode_state(state, objects, fluents))
    if any(c < 0 for s in states for c in s):
        return (), "no predicted states: some object does not hold exactly one code"
    return tuple(states), ""


def strips_problem(task: StripsTask) -> Any:
    """unified-planning's Problem for a grounded STRIPS task, built from its data without the PDDL reader.

    The same problem as reading task.domain and task.problem (tests compare the two); the reader
    does not finish within a minute on the ~12 MB of a 2-object task of the learned rules.
    """
    from unified_planning.shortcuts import BoolType, Fluent, InstantaneousAction, Object, Problem, UserType

    if not task.states or not task.bits:
        raise ValueError("the STRIPS task carries no states; make it with pddl_export.pddl_writer.strips_pddl")
    obj_type = UserType(OBJECT_TYPE)
    n = len(task.states[0])
    objects = [Object(object_name(i), obj_type) for i in range(n)]
    problem = Problem(task.name)
    fluents = {}
    for c in sorted(set(task.codes) | {c for c in task.goal if c is not None}):
        fluents[c] = Fluent(code_predicate(c, task.bits), BoolType(), o=obj_type)
        problem.add_fluent(fluents[c], default_initial_value=False)
    problem.add_objects(objects)
    atoms: dict[tuple[int, int], Any] = {}

    def atom(code: int, i: int) -> Any:
        if (code, i) not in atoms:
            atoms[code, i] = fluents[code](objects[i])
        return atoms[code, i]

    actions = []
    for i, a, j in task.edges:
        act = InstantaneousAction(f"{action_name(a)}-s{i}")
        pre, post = task.states[i], task.states[j]
        for k, c in enumerate(pre):
            act.add_precondition(atom(c, k))
        for k, (c, d) in enumerate(zip(pre, post)):
            if c != d:
                act.add_effect(atom(c, k), False)
                act.add_effect(atom(d, k), True)
        actions.append(act)
    if len({a.name for a in actions}) != len(actions):
        raise ValueError("the STRIPS task has two ground actions with one name")
    listed = getattr(problem, "_actions", None)
    if isinstance(listed, list) and not listed:
        # Problem.add_action compares each new name with every action's (quadratic: hours for the
        # 64,000 actions of a 2-object task); the names are checked unique above.
        listed.extend(actions)
    else:
        problem.add_actions(actions)
    for k, c in enumerate(task.states[0]):
        problem.set_initial_value(atom(c, k), True)
    for k, c in enumerate(task.goal):
        if c is not None:
            problem.add_goal(atom(c, k))
    return problem


_FEW_ACTIONS = 1000  # above this many actions, plans are validated on the problem cut to the plan's actions


def _with_only_actions(problem: Any, plan: Any) -> Any:
    """The problem with the same fluents, objects, initial state and goals, and only the plan's actions."""
    from unified_planning.model import Problem

    sub = Problem(problem.name, problem.environment)
    for f in problem.fluents:
        sub.add_fluent(f, default_initial_value=problem.fluents_defaults.get(f))
    sub.add_objects(problem.all_objects)
    used = {ai.action.name for ai in plan.actions}
    for a in problem.actions:
        if a.name in used:
            sub.add_action(a)
    for fluent, value in problem.explicit_initial_values.items():
        sub.set_initial_value(fluent, value)
    for g in problem.goals:
        sub.add_goal(g)
    return sub


_DOMAINS: dict[str, Any] = {}  # sha256 of a domain text -> its unified-planning problem without objects


def parsed_domain(domain_text: str) -> Any:
    """unified-planning's parse of a domain alone, cached by the text's hash.

    Parsing is the slow part of a call on a large learned domain (unified-planning's reader
    takes about 30 s for a 1,000-rule domain), so repeated calls on one domain parse it once.
    """
    key = hashlib.sha256(domain_text.encode()).hexdigest()
    if key not in _DOMAINS:
        from unified_planning.io import PDDLReader

        _DOMAINS[key] = PDDLReader().parse_problem_string(domain_text)
    return _DOMAINS[key]


def _instance(domain: Any, problem_text: str) -> Any | None:
    """The problem on a copy of a parsed domain, or None if it is more than this reads.

    The problem text is read with the `pddl` package: typed objects, positive ground init
    atoms and a goal that is an atom or a conjunction of atoms and negated atoms (what
    pddl_export.pddl_writer.problem_pddl writes). Anything else returns None, and the
    caller parses domain and problem together with unified-planning.
    """
    import sys

    from pddl.logic.base import And, Not
    from pddl.logic.predicates import Predicate
    from pddl.parser.problem import ProblemParser
    from unified_planning.model import Object

    old = getattr(sys, "tracebacklimit", None)
    try:
        parsed = ProblemParser()(problem_text)
    except Exception:  # noqa: BLE001 - let unified-planning's reader report the error
        return None
    finally:  # the pddl parser leaves sys.tracebacklimit at 0 on errors
        if old is None and hasattr(sys, "tracebacklimit"):
            del sys.tracebacklimit
    problem = domain.clone()
    problem.name = str(parsed.name).lower()
    try:
        for const in sorted(parsed.objects, key=lambda c: c.name):
            if len(const.type_tags) != 1:
                return None
            type_name = str(next(iter(const.type_tags))).lower()
            problem.add_object(Object(str(const.name).lower(), domain.user_type(type_name)))

        def atom(lit: Any) -> Any:
            if not isinstance(lit, Predicate):
                raise ValueError("not an atom")
            return problem.fluent(str(lit.name).lower())(*[problem.object(str(t.name).lower()) for t in lit.terms])

        for lit in parsed.init:
            problem.set_initial_value(atom(lit), True)
        goals = parsed.goal.operands if isinstance(parsed.goal, And) else (parsed.goal,)
        for g in goals:
            problem.add_goal(~atom(g.argument) if isinstance(g, Not) else atom(g))
    except Exception:  # noqa: BLE001 - an unknown name, type or form: fall back to the full parse
        return None
    return problem


def _solve_here(domain_text: str, problem_text: str, planner: str, timeout_s: float,
                compile_conditional_effects: bool, domain: Any = None, prebuilt: Any = None) -> PlanResult:
    """The whole pipeline in this process; never raises (ERROR instead)."""
    t0 = time.perf_counter()
    deadline = t0 + timeout_s
    spec = PLANNERS[planner]
    try:
        from unified_planning.engines import CompilationKind, PlanGenerationResultStatus, ValidationResultStatus
        from unified_planning.io import PDDLReader
        from unified_planning.shortcuts import Compiler, MinimizeSequentialPlanLength, OneshotPlanner, PlanValidator
        from unified_planning.shortcuts import get_environment
    except ImportError as e:
        return failed(planner, PlanStatus.ERROR, t0, f"unified-planning is not installed: {e}")
    env = get_environment()
    env.credits_stream = None
    if spec.engine not in env.factory.engines:
        return failed(planner, PlanStatus.ERROR, t0, f"engine {spec.engine!r} is not installed")
    engine_cls = env.factory.engine(spec.engine)
    original = prebuilt if prebuilt is not None else _instance(domain, problem_text) if domain is not None else None
    if original is None:
        try:
            original = PDDLReader(env).parse_problem_string(domain_text, problem_text)
        except Exception as e:  # noqa: BLE001 - any parser failure is reported, not raised
            return failed(planner, PlanStatus.ERROR, t0, f"PDDL parse failed: {type(e).__name__}: {e}")
    t_parse = time.perf_counter() - t0

    problem, chain, names = original, [], []
    pkind = original.kind  # computed once per problem: it walks every action (11 s for 64,000 of them)
    if (pkind.has_conditional_effects() and not compile_conditional_effects
            and not engine_cls.supported_kind().has_conditional_effects()):
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} does not support CONDITIONAL_EFFECTS; use the "
                       "grounded STRIPS form (pddl_export.pddl_writer.strips_pddl) or compile_conditional_effects=True",
                       engine=spec.engine, parse_time_s=t_parse)
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
    t_compile = time.perf_counter() - t0 - t_parse
    extra: dict[str, Any] = {
        "engine": spec.engine, "parse_time_s": t_parse, "compile_time_s": t_compile,
        "compilers": ",".join(names), "n_actions": len(problem.actions)}
    if not engine_cls.supports(pkind):
        missing = sorted(set(pkind.features) - set(engine_cls.supported_kind().features))
        hint = ("; use the grounded STRIPS form (pddl_export.pddl_writer.strips_pddl)"
                if "CONDITIONAL_EFFECTS" in missing else "")
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} does not support {', '.join(missing)}{hint}", **extra)

    remaining = deadline - time.perf_counter()
    if remaining <= 0:
        return failed(planner, PlanStatus.TIMEOUT, t0, "time limit reached before planning", **extra)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with OneshotPlanner(name=spec.engine, params=dict(spec.params)) as engine:
                t1 = time.perf_counter()
                res = engine.solve(problem, timeout=remaining if spec.native_timeout else None)
                planner_time = time.perf_counter() - t1
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} failed: {type(e).__name__}: {e}", **extra)
    extra.update(planner_time_s=planner_time, up_status=res.status.name,
                 optimal=res.status == PlanGenerationResultStatus.SOLVED_OPTIMALLY)
    logs = " ".join(m.message for m in (res.log_messages or []))
    found = _EXPANDED_RE.findall(logs)
    expansions = int(found[-1]) if found else None
    status = _status_from_up(res.status)
    if not spec.native_timeout and time.perf_counter() > deadline:
        return failed(planner, PlanStatus.TIMEOUT, t0, f"{planner} ran past the {timeout_s:g} s limit "
                       f"({planner_time:.3f} s; it has no time limit of its own)", **extra)
    if status is not PlanStatus.SOLVED:
        why = {PlanStatus.UNSOLVABLE: "no plan exists" if res.status == PlanGenerationResultStatus.UNSOLVABLE_PROVEN
               else "search space exhausted (no proof of unsolvability)",
               PlanStatus.TIMEOUT: f"{planner} hit the {timeout_s:g} s time limit"}.get(
                   status, f"{planner} ended with {res.status.name}")
        return failed(planner, status, t0, why, **extra)
    if res.plan is None:
        return failed(planner, PlanStatus.ERROR, t0, f"{planner} reported {res.status.name} without a plan", **extra)
    try:
        t2 = time.perf_counter()
        plan = res.plan
        for compiled in reversed(chain):
            plan = plan.replace_action_instances(compiled.map_back_action_instance)
        # A sequential plan's validity depends on the initial state, the goal and the actions it uses,
        # so a large grounded problem is validated with only those (the validator and the simulator
        # recompute the problem kind, a walk over every action, several times).
        checked = original if len(original.actions) <= _FEW_ACTIONS else _with_only_actions(original, plan)
        with PlanValidator(problem_kind=checked.kind, plan_kind=plan.kind) as validator:
            check = validator.validate(checked, plan)
        extra["validate_time_s"] = time.perf_counter() - t2
        if check.status != ValidationResultStatus.VALID:
            reason = getattr(check, "reason", None) or getattr(check, "inapplicable_action", None) or ""
            return failed(planner, PlanStatus.ERROR, t0, f"plan failed validation on the original problem {reason}", **extra)
        ids = tuple(action_id_from_name(ai.action.name) for ai in plan.actions)
        states, note = _predicted_states(checked, plan)
    except Exception as e:  # noqa: BLE001
        return failed(planner, PlanStatus.ERROR, t0, f"plan mapping/validation failed: {type(e).__name__}: {e}", **extra)
    if note:
        extra["note"] = note
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=ids, predicted_states=states,
                      expansions=expansions, planning_time_s=time.perf_counter() - t0, extra=extra)


def _worker(conn: Any, *args: Any) -> None:
    try:
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


def solve_pddl(
    domain_text: str,
    problem_text: str,
    planner: str,
    timeout_s: float,
    *,
    compile_conditional_effects: bool = False,
    grace_s: float = 3.0,
    cache_domain: bool = False,
    problem: Any = None,
) -> PlanResult:
    """Run one classical planner on PDDL text; every failure comes back as a status, never raised.

    Planners: "fast-downward" (satisficing, lama-first), "fast-downward-opt" (LM-cut; no conditional
    effects), "fast-downward-blind" (blind A*, optimal, takes conditional effects), "symk", "symk-opt",
    "pyperplan". The call takes at most about timeout_s + grace_s seconds. With cache_domain, the domain
    is parsed once in this process (parsed_domain; the first call's time includes it, outside
    the guard) and each call reads only the problem. With `problem` (a unified-planning Problem
    equal to the texts, e.g. strips_problem), nothing is parsed.
    """
    t0 = time.perf_counter()
    if not (isinstance(timeout_s, (int, float)) and math.isfinite(timeout_s) and timeout_s > 0):
        raise ValueError(f"timeout_s must be a positive number, got {timeout_s!r}")
    if not (math.isfinite(grace_s) and grace_s >= 0):
        raise ValueError(f"grace_s must be >= 0, got {grace_s!r}")
    name = str(planner)
    if name not in PLANNERS:
        return failed(name or "unknown", PlanStatus.ERROR, t0, f"unknown planner {name!r}; known: {', '.join(PLANNERS)}",
                       total_time_s=time.perf_counter() - t0)
    try:  # import here so a forked child starts with unified-planning loaded
        import unified_planning.shortcuts  # noqa: F401
        from unified_planning.shortcuts import get_environment

        get_environment().credits_stream = None
    except ImportError as e:
        return failed(name, PlanStatus.ERROR, t0, f"unified-planning is not installed: {e}",
                       total_time_s=time.perf_counter() - t0)
    domain = None
    if cache_domain:
        try:
            domain = parsed_domain(domain_text)
        except Exception as e:  # noqa: BLE001
            return failed(name, PlanStatus.ERROR, t0, f"PDDL parse failed: {type(e).__name__}: {e}",
                           total_time_s=time.perf_counter() - t0)
    ctx = _context()
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_worker, args=(send, domain_text, problem_text, name, float(timeout_s),
                                             compile_conditional_effects, domain, problem), daemon=True)
    answer: Any = None  # stays None if the child dies (or on an exception here); "late" on the guard
    proc.start()
    send.close()
    try:
        if recv.poll(timeout_s + grace_s):
            try:
                answer = recv.recv()
            except EOFError:
                answer = None
        else:
            answer = "late"
    finally:
        recv.close()
        if not isinstance(answer, dict):
            proc.kill()
        proc.join(5.0)
    total = time.perf_counter() - t0
    if answer == "late":
        return failed(name, PlanStatus.TIMEOUT, t0, f"no answer within {timeout_s:g} s + {grace_s:g} s grace; "
                       "planner process killed", total_time_s=total)
    if answer is None:
        return failed(name, PlanStatus.ERROR, t0, f"planner process died (exit code {proc.exitcode})", total_time_s=total)
    if "error" in answer:
        return failed(name, PlanStatus.ERROR, t0, answer["error"], total_time_s=total)
    inner = PlanResult.from_json(answer)
    extra = dict(inner.extra)
    extra["total_time_s"] = total
    extra.setdefault("planner_time_s", 0.0)
    return PlanResult(planner=inner.planner, status=inner.status, plan=inner.plan,
                      predicted_states=inner.predicted_states, expansions=inner.expansions,
                      planning_time_s=total, message=inner.message, extra=extra)
