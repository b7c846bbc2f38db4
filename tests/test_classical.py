"""Classical planners on exported PDDL: valid plans, optimal lengths, and honest failures.

Uses the ToyRobot network of test_pddl_export (3-bit codes, stick with rider, occlusion).
Each planner test skips, with the reason, when that engine is not installed.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np
import pytest

from pddl_export.enumeration import enumerate_transitions
from pddl_export.pddl_writer import PddlForm, conditional_domain, problem_pddl, strips_pddl
from pddl_export.distil import distil_rules
from search.classical import PLANNERS, solve_pddl
from search.up_solve import PlannerSpec
from search.up_problem import strips_problem
from search.result import PlanStatus
from pddl_export.symbolic import SymbolicGoal
from test_pddl_export import FAR, NEAR, RIDER, RIDER_M, STICK, TOY_VOCAB, UNDER, ToyRobot


@dataclass(frozen=True)
class TinyProblem:
    """A named start/goal pair with its known shortest plan length under ToyRobot."""

    name: str
    init: tuple[int, ...]
    goal: tuple[int | None, ...]
    optimal_length: int


STICK_CARRIES_RIDER = TinyProblem("stick-carries-rider", (NEAR, STICK, NEAR), (RIDER_M, None, None), 2)
UNCOVER_TWICE = TinyProblem("uncover-twice", (UNDER, FAR), (NEAR, NEAR), 3)  # U,F -> U,N -> F,N -> N,N
NEVER = TinyProblem("stick-never-rides", (STICK,), (RIDER,), -1)  # a lone stick never becomes a rider


def _installed(planner: str) -> bool:
    from unified_planning.shortcuts import get_environment

    return PLANNERS[planner].engine in get_environment().factory.engines


def _require(planner: str) -> None:
    if not _installed(planner):
        pytest.skip(f"unified-planning engine {PLANNERS[planner].engine!r} is not installed")


@pytest.fixture(scope="module")
def rules():
    return distil_rules(enumerate_transitions(ToyRobot(), TOY_VOCAB, max_objects=3))


def _conditional(rules, p: TinyProblem) -> tuple[str, str]:
    return conditional_domain(rules, "test"), problem_pddl(rules, p.init, p.goal, "test", name=p.name)


def _strips(rules, p: TinyProblem) -> tuple[str, str]:
    task = strips_pddl(rules, p.init, p.goal, "test", name=p.name)
    return task.domain, task.problem


def _check_plan(result, p: TinyProblem) -> None:
    """The plan reaches the goal under the NETWORK, and predicted states are the network's rollout."""
    assert result.status is PlanStatus.SOLVED, result.message
    net, states = ToyRobot(), [np.array(p.init)]
    for a in result.plan:
        states.append(net(states[-1][None], np.array([a]))[0])
    assert SymbolicGoal(p.goal).satisfied(states[-1])[0]
    assert result.predicted_states == tuple(tuple(int(c) for c in s) for s in states)
    assert len(result.plan) >= p.optimal_length
    assert result.extra["total_time_s"] >= result.extra["planner_time_s"] > 0


@pytest.mark.parametrize("planner", ["fast-downward", "symk"])
def test_conditional_form_satisficing(rules, planner):
    _require(planner)
    result = solve_pddl(*_conditional(rules, UNCOVER_TWICE), planner=planner, timeout_s=20)
    _check_plan(result, UNCOVER_TWICE)
    assert result.extra["compilers"] == ""  # taken as written


def test_cached_domain_reads_only_the_problem(rules, monkeypatch, tmp_path):
    """cache_domain parses the domain once; each call builds its problem from the problem text."""
    import hashlib

    import search.up_problem as up_problem
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import OneshotPlanner

    _require("fast-downward")
    domain, problem = _conditional(rules, UNCOVER_TWICE)
    up_problem._DOMAINS.pop(hashlib.sha256(domain.encode()).hexdigest(), None)
    log, real = tmp_path / "parses.txt", PDDLReader.parse_problem_string

    def counted(self, domain_str, problem_str=None):  # the forked planner processes inherit it
        with open(log, "a") as f:
            f.write("domain-only\n" if problem_str is None else "domain+problem\n")
        return real(self, domain_str, problem_str)

    monkeypatch.setattr(PDDLReader, "parse_problem_string", counted)
    first = solve_pddl(domain, problem, planner="fast-downward", timeout_s=20, cache_domain=True)
    _check_plan(first, UNCOVER_TWICE)
    _, other = _conditional(rules, STICK_CARRIES_RIDER)
    second = solve_pddl(domain, other, planner="fast-downward", timeout_s=20, cache_domain=True)
    _check_plan(second, STICK_CARRIES_RIDER)
    assert log.read_text().split() == ["domain-only"]  # one parse of the domain, none of a problem
    monkeypatch.undo()
    # the instance built on the cached domain is the problem unified-planning's reader gives
    built = up_problem.problem_on_domain(up_problem.parsed_domain(domain), other)
    from unified_planning.io import PDDLReader
    full = PDDLReader().parse_problem_string(domain, other)
    assert {o.name for o in built.all_objects} == {o.name for o in full.all_objects}
    assert {str(g) for g in built.goals} == {str(g) for g in full.goals}
    assert {str(k): str(v) for k, v in built.explicit_initial_values.items()} == \
        {str(k): str(v) for k, v in full.explicit_initial_values.items()}
    with OneshotPlanner(name="fast-downward") as engine:
        assert engine.solve(built).plan is not None
    assert up_problem.problem_on_domain(up_problem.parsed_domain(domain), "(define (problem x) (:domain d) (:objects a - nosuchtype) (:init) (:goal (and)))") is None


@pytest.mark.parametrize("problem", [STICK_CARRIES_RIDER, UNCOVER_TWICE])
def test_conditional_form_optimal_with_fast_downward_blind(rules, problem):
    _require("fast-downward")
    result = solve_pddl(*_conditional(rules, problem), planner="fast-downward-blind", timeout_s=20)
    _check_plan(result, problem)
    assert len(result.plan) == problem.optimal_length and result.extra["compilers"] == ""


def test_conditional_form_optimal_with_symk(rules):
    _require("symk-opt")
    result = solve_pddl(*_conditional(rules, STICK_CARRIES_RIDER), planner="symk-opt", timeout_s=20)
    _check_plan(result, STICK_CARRIES_RIDER)
    assert len(result.plan) == STICK_CARRIES_RIDER.optimal_length and result.extra["optimal"]


@pytest.mark.parametrize("planner", ["fast-downward", "fast-downward-opt", "symk", "pyperplan"])
def test_strips_form_every_planner(rules, planner):
    _require(planner)
    result = solve_pddl(*_strips(rules, UNCOVER_TWICE), planner=planner, timeout_s=20)
    _check_plan(result, UNCOVER_TWICE)
    if PLANNERS[planner].optimal:
        assert len(result.plan) == UNCOVER_TWICE.optimal_length and result.extra["optimal"]
    if planner.startswith("fast-downward"):
        # a forward search expands every state before the goal on the plan it returns, and (neither lama-first
        # nor A* with LM-cut reopening a state here) no state twice: the count read from its log lies in between
        reachable = _reachable(UNCOVER_TWICE.init)
        assert reachable == {(UNDER, FAR), (UNDER, NEAR), (FAR, NEAR), (NEAR, NEAR), (FAR, FAR)}
        assert len(result.plan) <= result.expansions <= len(reachable), result.expansions


def _reachable(init: tuple[int, ...]) -> set[tuple[int, ...]]:
    """Every state ToyRobot reaches from init under any sequence of actions (breadth first, all 36 actions)."""
    net, seen, frontier = ToyRobot(), {tuple(init)}, [tuple(init)]
    while frontier:
        states = np.repeat(np.array(frontier, np.int64), 36, axis=0)
        frontier = []
        for s in map(tuple, net(states, np.tile(np.arange(36), len(states) // 36)).tolist()):
            if s not in seen:
                seen.add(s)
                frontier.append(s)
    return seen


def _conjuncts(conditions) -> list[str]:
    """The atoms of a list of conditions, with conjunctions opened, sorted as text."""
    out = []
    for c in conditions:
        out += [str(x) for x in c.args] if c.is_and() else [str(c)]
    return sorted(out)


def test_strips_problem_built_directly_equals_the_parsed_one(rules):
    from unified_planning.io import PDDLReader

    p = UNCOVER_TWICE
    task = strips_pddl(rules, p.init, p.goal, "test", name=p.name)
    built, parsed = strips_problem(task), PDDLReader().parse_problem_string(task.domain, task.problem)
    assert built.name == parsed.name and len(built.actions) == len(parsed.actions) == task.n_actions
    for a in built.actions:
        b = parsed.action(a.name)
        assert _conjuncts(a.preconditions) == _conjuncts(b.preconditions), a.name
        assert sorted(map(str, a.effects)) == sorted(map(str, b.effects)), a.name
    assert {str(k): str(v) for k, v in built.initial_values.items()} == \
        {str(k): str(v) for k, v in parsed.initial_values.items()}
    assert _conjuncts(built.goals) == _conjuncts(parsed.goals)
    if _installed("pyperplan"):
        result = solve_pddl("", "", planner="pyperplan", timeout_s=20, problem=built)
        _check_plan(result, p)
    with pytest.raises(ValueError, match="no states"):
        strips_problem(dataclasses.replace(task, states=()))


def test_validation_on_the_plans_actions_decides_like_the_whole_problem(rules):
    """with_only_actions keeps init, goal and the used actions: valid plans stay valid, invalid ones invalid."""
    from unified_planning.plans import ActionInstance, SequentialPlan
    from unified_planning.shortcuts import PlanValidator

    from search.up_problem import with_only_actions

    p = UNCOVER_TWICE
    whole = strips_problem(strips_pddl(rules, p.init, p.goal, "test"))
    result = solve_pddl("", "", planner="fast-downward", timeout_s=20, problem=whole)
    assert result.status is PlanStatus.SOLVED, result.message
    names = [a.name for a in whole.actions]
    good = SequentialPlan([ActionInstance(whole.action(n)) for n in _plan_names(whole, result.plan)])
    bad = SequentialPlan(list(good.actions[:-1]))
    shuffled = SequentialPlan(list(reversed(good.actions)))
    for plan, want in ((good, "VALID"), (bad, "INVALID"), (shuffled, None)):
        verdicts = []
        for problem in (whole, with_only_actions(whole, plan)):
            with PlanValidator(problem_kind=problem.kind) as validator:
                verdicts.append(validator.validate(problem, plan).status.name)
        assert verdicts[0] == verdicts[1] and want in (None, verdicts[0]), verdicts
    sub = with_only_actions(whole, good)
    assert len(sub.actions) == len({ai.action.name for ai in good.actions}) < len(names)


def _plan_names(problem, plan_ids: tuple[int, ...]) -> list[str]:
    """Ground action names of a STRIPS plan, replayed from the initial state through the problem's actions."""
    from unified_planning.shortcuts import SequentialSimulator

    out = []
    with SequentialSimulator(problem) as sim:
        state = sim.get_initial_state()
        for a in plan_ids:
            prefix = f"pick-{a // 6}-release-{a % 6}-s"
            act = next(x for x in problem.actions if x.name.startswith(prefix) and sim.is_applicable(state, x))
            out.append(act.name)
            state = sim.apply(state, act)
    return out


def test_conditional_form_refused_by_fd_opt_with_a_reason(rules):
    _require("fast-downward-opt")
    result = solve_pddl(*_conditional(rules, STICK_CARRIES_RIDER), planner="fast-downward-opt", timeout_s=20)
    assert result.status is PlanStatus.ERROR and "STRIPS" in result.message and result.plan == ()


@pytest.mark.parametrize("planner,form", [("fast-downward", PddlForm.CONDITIONAL), ("pyperplan", PddlForm.STRIPS)])
def test_unsolvable(rules, planner, form):
    _require(planner)
    texts = _conditional(rules, NEVER) if form is PddlForm.CONDITIONAL else _strips(rules, NEVER)
    result = solve_pddl(*texts, planner=planner, timeout_s=20)
    assert result.status is PlanStatus.UNSOLVABLE and result.plan == () and result.message


@pytest.mark.parametrize("planner", ["fast-downward", "pyperplan"])
def test_tiny_timeout_is_reported(rules, planner):
    _require(planner)
    result = solve_pddl(*_strips(rules, UNCOVER_TWICE), planner=planner, timeout_s=0.001)
    assert result.status is PlanStatus.TIMEOUT and result.plan == ()


def test_guard_kills_a_runaway_call(rules):
    _require("pyperplan")
    t0 = time.perf_counter()
    # Compiling conditional effects away blows up (2^n actions); the outer guard must stop it.
    result = solve_pddl(*_conditional(rules, STICK_CARRIES_RIDER), planner="pyperplan", timeout_s=0.5,
                        compile_conditional_effects=True, grace_s=0.5)
    assert result.status is PlanStatus.TIMEOUT
    assert time.perf_counter() - t0 < 10


def test_unknown_and_missing_planners_are_errors(rules, monkeypatch):
    texts = _strips(rules, UNCOVER_TWICE)
    result = solve_pddl(*texts, planner="no-such-planner", timeout_s=5)
    assert result.status is PlanStatus.ERROR and "unknown planner" in result.message
    monkeypatch.setitem(PLANNERS, "ghost", PlannerSpec("ghost-engine", optimal=False, native_timeout=True))
    result = solve_pddl(*texts, planner="ghost", timeout_s=5)
    assert result.status is PlanStatus.ERROR and "not installed" in result.message


def test_bad_pddl_and_bad_timeout(rules):
    result = solve_pddl("(define (domain", "(define", planner="fast-downward", timeout_s=5)
    assert result.status is PlanStatus.ERROR and "parse" in result.message
    with pytest.raises(ValueError):
        solve_pddl(*_strips(rules, UNCOVER_TWICE), planner="fast-downward", timeout_s=0)
