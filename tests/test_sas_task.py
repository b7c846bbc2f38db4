"""One translation of Fast Downward's, searched from another state to another goal (search/sas_task.py), and the
loop's use of it (symlearn/planning/learned_calls.py: Translations)."""
from __future__ import annotations

from pathlib import Path

import pytest

from pddl_export.learned_domain import domain_pddl, predicates_of, problem_pddl, successor
from search.result import PlanStatus
from search.sas_task import Translation, parse_sas
from search.stock_planners import solve_keeping_translation, solve_sas_text, solve_texts

# a cube o1 at l3 under o2, a cube o3 alone at l4 (as in tests/test_learned_domain.py)
STATE = frozenset({("at", "o1", "l3"), ("at", "o2", "l3"), ("on", "o2", "o1"), ("clear", "o2"), ("on-table", "o1"),
                   ("at", "o3", "l4"), ("clear", "o3"), ("on-table", "o3"), ("u3", "o2"), ("empty", "l0"),
                   ("empty", "l1"), ("empty", "l2"), ("empty", "l5")})
GOAL = frozenset({("on", "o2", "o3"), ("at", "o1", "l0")})
OBJECTS = ["o1", "o2", "o3"]

# two variables: where a is (x, y or neither) and whether x is free; a at x and x free are mutex
TOY = """begin_version
3
end_version
begin_metric
0
end_metric
2
begin_variable
var0
-1
3
Atom at(a, x)
Atom at(a, y)
<none of those>
end_variable
begin_variable
var1
-1
2
Atom free(x)
NegatedAtom free(x)
end_variable
1
begin_mutex_group
2
0 0
1 0
end_mutex_group
begin_state
0
1
end_state
begin_goal
1
0 1
end_goal
1
begin_operator
go a x y
0
1
0 0 0 1
1
end_operator
0
"""


def _carry():
    from symlearn.export.learned_export import load_operators

    ops = load_operators(Path("pretrained/relations_carry"))
    return ops, domain_pddl(ops), predicates_of(ops)


def _applies(ops, steps, state):
    by_name, now = {o.name: o for o in ops}, state
    for step in steps:
        name, *args = step.strip("()").split()
        now = successor(by_name[name], args, now)
        assert now is not None, step
    return now


def test_the_translators_task_rewritten_for_its_own_state_and_goal_is_the_same_file():
    ops, domain, predicates = _carry()
    res, sas = solve_keeping_translation(domain, problem_pddl("p", OBJECTS, STATE, GOAL, predicates),
                                         "fd-lama-first", 20.0)
    assert res.status is PlanStatus.SOLVED and sas is not None
    assert Translation.of(sas, STATE).task_for(STATE, GOAL) == sas


def test_a_kept_translation_plans_from_a_later_state_to_another_goal_as_a_fresh_translation_does():
    ops, domain, predicates = _carry()
    res, sas = solve_keeping_translation(domain, problem_pddl("p", OBJECTS, STATE, GOAL, predicates), "fd-lmcut", 20.0)
    kept = Translation.of(sas, STATE)
    later = _applies(ops, res.steps[:1], STATE)  # the state after the plan's first step
    goal = frozenset({("at", "o3", "l5"), ("at", "o1", "l1")})
    text = kept.task_for(later, goal)
    assert text is not None and text != sas
    again = solve_sas_text(text, "fd-lmcut", 20.0)
    fresh = solve_texts(domain, problem_pddl("p", OBJECTS, later, goal, predicates), "fd-lmcut", 20.0)
    assert again.status is PlanStatus.SOLVED and fresh.status is PlanStatus.SOLVED
    assert len(again.steps) == len(fresh.steps) == 3  # both optimal: the same length
    assert goal <= _applies(ops, again.steps, later)
    # a goal no state reaches (o1 on itself is no atom of the task): not this translation's to answer
    assert kept.task_for(later, goal | {("on", "o1", "o1")}) is None
    # a unary bit is static: the translator compiled it away, so a state with another one needs a new translation
    assert kept.task_for(later | {("u0", "o3")}, goal) is None
    assert kept.task_for(later - {("u3", "o2")}, goal) is None


def test_a_state_the_variables_cannot_hold_is_refused():
    kept = Translation.of(TOY, {("at", "a", "x")})
    text = kept.task_for({("at", "a", "x")}, {("at", "a", "y")})
    assert text == TOY  # its own state and goal: the same file
    state = lambda text: text.split("begin_state\n")[1].split("\nend_state")[0].split()  # noqa: E731
    assert state(kept.task_for(set(), {("at", "a", "y")})) == ["2", "1"]  # none of those; free(x) false
    assert state(kept.task_for({("at", "a", "y"), ("free", "x")}, {("at", "a", "x")})) == ["1", "0"]
    assert kept.task_for({("at", "a", "x"), ("at", "a", "y")}, {("at", "a", "y")}) is None  # two values of one
    assert kept.task_for({("at", "a", "x"), ("free", "x")}, {("at", "a", "y")}) is None  # a mutex group broken
    assert kept.task_for({("at", "a", "z")}, {("at", "a", "y")}) is None  # an atom no variable holds, true now
    assert kept.task_for(set(), {("at", "a", "x"), ("at", "a", "y")}) is None  # a goal no state holds


def test_a_task_with_derived_variables_or_not_a_task_is_refused():
    with pytest.raises(ValueError, match="derived"):
        parse_sas(TOY.replace("var1\n-1\n", "var1\n0\n"))
    with pytest.raises(ValueError, match="no begin_state"):
        parse_sas("begin_version\n3\nend_version\n")
    with pytest.raises(ValueError, match="lists 2 values, says 3"):
        parse_sas(TOY.replace("<none of those>\n", ""))
    with pytest.raises(ValueError, match="initial state does not match"):
        parse_sas(TOY.replace("begin_state\n0\n1\n", "begin_state\n0\n7\n"))


def test_only_fast_downward_searches_a_translated_task():
    res = solve_sas_text(TOY, "pyperplan", 5.0)
    assert res.status is PlanStatus.ERROR and "does not read a translated task" in res.message
    ok = solve_sas_text(TOY, "fd-lama-first", 20.0)  # the toy task itself: one step, a from x to y
    assert ok.status is PlanStatus.SOLVED and ok.steps == ("(go a x y)",)
    with pytest.raises(ValueError, match="timeout_s"):
        solve_sas_text(TOY, "fd-lama-first", 0)


def test_the_loop_translates_a_set_of_objects_once_and_searches_its_task_from_each_later_state(monkeypatch):
    from symlearn.planning import learned_calls
    from symlearn.planning.learned_calls import Grounding, Translations, call, solve

    ops, domain, predicates = _carry()
    translated = []
    real = learned_calls.solve_keeping_translation

    def counted(*args, **kwargs):
        translated.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(learned_calls, "solve_keeping_translation", counted)
    kept = Translations(predicates)
    first = call(domain, predicates, OBJECTS, STATE, GOAL, "fd-lmcut", 20.0, Grounding(kept))
    assert first.status is PlanStatus.SOLVED and len(translated) == 1 and kept.reused == 0
    later = _applies(ops, first.steps[:1], STATE)
    second = call(domain, predicates, OBJECTS, later, GOAL, "fd-lmcut", 20.0, Grounding(kept))
    assert second.status is PlanStatus.SOLVED and len(translated) == 1 and kept.reused == 1
    assert list(second.steps) == list(first.steps[1:])  # the rest of the optimal plan: one step
    # another bit seen on o3: the translation cannot stand for it, so the objects are translated again
    third = call(domain, predicates, OBJECTS, later | {("u0", "o3")}, GOAL, "fd-lmcut", 20.0, Grounding(kept))
    assert third.status is PlanStatus.SOLVED and len(translated) == 2 and kept.reused == 1
    # a step whose whole task is kept searches it alone, before any object set (which would need translating)
    seen = later | {("u0", "o3")}  # the state the last translation was made from, bits and all
    plan, (names, _, _) = solve(domain, predicates, OBJECTS, seen, GOAL, "fd-lmcut", True, 20.0, Grounding(kept))
    assert plan.status is PlanStatus.SOLVED and names == OBJECTS and len(translated) == 2 and kept.reused == 2
    for i in range(Translations.KEEP + 1):  # at most KEEP sets of objects are kept
        kept.keep([f"x{i}"], frozenset(), TOY)
    assert len(kept.tasks) == Translations.KEEP and tuple(OBJECTS) not in kept.tasks


def test_with_kept_translations_the_whole_goal_gets_all_but_the_relaxed_goals_reserve(monkeypatch):
    # the relaxed goal's call searches the whole goal's kept translation (about 1 s at 10 objects), so the whole goal
    # gets all of a call's 10 s but RELAX_RESERVE_S; without kept translations, RELAX_SHARE of it
    from search.result import failed
    from symlearn.planning import learned_loop
    from symlearn.planning.learned_calls import Translations
    from symlearn.planning.learned_loop import RELAX_RESERVE_S, RELAX_SHARE, LearnedLoopConfig, LoopResult, _plan

    given = []

    def timed_out(domain, predicates, objects, state, goal, planner, focus, timeout_s, grounding):
        given.append((round(timeout_s, 1), grounding.translations is not None))
        return failed(planner, PlanStatus.TIMEOUT, 0.0, "stopped", phase="search"), (objects, state, goal)

    monkeypatch.setattr(learned_loop, "solve", timed_out)
    ops, domain, predicates = _carry()
    cfg = LearnedLoopConfig(planner="fd-lama-first", goal_relations=("on",), relax_unreachable=True)
    located = frozenset(a for a in GOAL if a[0] == "at")
    for kept in (Translations(predicates), None):
        res = LoopResult("p", 3, None, False)
        steps, _ = _plan(ops, domain, predicates, OBJECTS, STATE, GOAL, located, cfg, res, ["u3"], kept)
        assert steps == [] and res.relaxed_calls == 1 and "timeout" in res.stop
    assert [t for t, _ in given[0::2]] == [10.0 - RELAX_RESERVE_S, 10.0 * RELAX_SHARE]
    assert given[1][0] >= RELAX_RESERVE_S - 0.1 and [k for _, k in given] == [True, True, False, False]


def _atoms(text: str) -> frozenset:
    return frozenset(tuple(a.split()) for a in text.strip("()").split(") ("))


# two two-cube towers that swap cells (a structures dev problem, 103 #20, as the carry model reads it): the shortest
# plan is 7 actions, lama-first's first plan 14
SWAP = _atoms("(at o1 l3) (at o2 l3) (at o3 l5) (at o4 l5) (clear o2) (clear o4) (empty l0) (empty l1) (empty l2) "
              "(empty l4) (on o2 o1) (on o4 o3) (on-table o1) (on-table o3) (u0 o4) (u1 o2) (u1 o4) (u2 o1) (u2 o3) "
              "(u3 o1) (u3 o2) (u3 o4) (u4 o1) (u4 o3) (u5 o4) (u6 o3) (u7 o1) (u7 o3)")
SWAPPED = _atoms("(at o1 l5) (at o2 l5) (at o3 l3) (at o4 l3) (empty l0) (empty l1) (empty l2) (empty l4) (on o2 o1) "
                 "(on o4 o3) (on-table o1) (on-table o3)")


def test_a_satisficing_first_plan_gives_way_to_a_shortest_one_found_on_its_kept_translation():
    from symlearn.planning.learned_loop import LearnedLoopConfig, LoopResult, _plan
    from symlearn.planning.learned_calls import Translations, shortest_plan

    ops, domain, predicates = _carry()
    objects = ["o1", "o2", "o3", "o4"]
    located = frozenset(a for a in SWAPPED if a[0] == "at")
    lengths = {}
    for optimal_s in (0.0, 5.0):
        cfg = LearnedLoopConfig(planner="fd-lama-first", goal_relations=("on",), relax_unreachable=True,
                                optimal_s=optimal_s, shorten_s=0.0, focus=False, timeout_s=20.0)
        res = LoopResult("swap", 4, 7, False)
        steps, _ = _plan(ops, domain, predicates, objects, SWAP, SWAPPED, located, cfg, res, [],
                         Translations(predicates))
        assert SWAPPED <= _applies(ops, steps, SWAP)
        lengths[optimal_s] = (len(steps), res.first_plan_length)
    assert lengths[0.0][0] == lengths[0.0][1] > 7  # lama-first's plan as it comes
    assert lengths[5.0] == (7, lengths[0.0][1])  # A* with LM-cut on the same translation: the shortest
    assert shortest_plan(Translations(predicates), objects, SWAP, SWAPPED, 5.0) is None  # nothing kept: no search
