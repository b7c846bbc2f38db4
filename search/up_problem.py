"""unified-planning Problems for the learned rules: built from task data, on a cached domain, cut to a plan.

search.classical plans on these problems; this module only builds and reads them.
`strips_problem` builds the grounded STRIPS task of pddl_export.pddl_writer directly (its PDDL
is too large for unified-planning's reader), `parsed_domain` and `problem_on_domain` parse a
large domain once and read each problem text with the `pddl` package, `with_only_actions`
cuts a large problem to a plan's actions for validation, and `predicted_states` replays a
plan to the symbolic states it predicts (objects `o<i>`, predicates `code-<bits>`).
"""
from __future__ import annotations

import hashlib
from typing import Any

from pddl_export.pddl_writer import (OBJECT_TYPE, StripsTask, action_name, code_from_predicate, code_predicate,
                                     object_index, object_name)


def _decode_state(state: Any, objects: list, fluents: list) -> tuple[int, ...]:
    """Per object (o0, o1, ...) the code whose predicate holds; -1 if not exactly one."""
    out = []
    for o in objects:
        held = [code for code, f in fluents if state.get_value(f(o)).bool_constant_value()]
        out.append(held[0] if len(held) == 1 else -1)
    return tuple(out)


def predicted_states(problem: Any, plan: Any) -> tuple[tuple[tuple[int, ...], ...], str]:
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


def with_only_actions(problem: Any, plan: Any) -> Any:
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


def problem_on_domain(domain: Any, problem_text: str) -> Any | None:
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
