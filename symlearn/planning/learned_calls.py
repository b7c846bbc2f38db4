"""The planner calls of one step of the learned route (learned_loop): over which objects, in what time, on which
translation.

A step plans first over the objects the goal needs (focus_objects), then over those and the tops of the other
stacks, then over every object (object_sets): at 10 objects grounding every one takes the translator 3-6 s of a
10 s call. A call stopped in translation rules out later calls of the step that could not get past it (Grounding),
and a translation is kept for the episode and searched from each later state and goal where it can stand for them
(Translations, search.sas_task).
"""
from __future__ import annotations

import time
from typing import Iterable, Sequence

from pddl_export.learned_domain import Atom, problem_pddl
from search.result import PlanResult, PlanStatus, failed
from search.sas_task import Translation
from search.stock_planners import solve_keeping_translation, solve_sas_text, solve_texts
from symlearn.world import N_LOCATIONS

LOCATIONS = frozenset(f"l{i}" for i in range(N_LOCATIONS))  # the domain's location constants
FOCUS_SHARE = 0.5  # of the time left for each of object_sets in turn, when LearnedLoopConfig.focus (learned_loop)
# an object set is planned over alone only where it holds at most this share of the objects: grounding grows with
# about the cube of the objects (a three-item operator: 10,800 of 18,086 ground operators at 10 objects), so 8 of 9
# cost nearly what all 9 do, and a failed call over them would leave the whole problem too little time to be
# grounded (object_sets; dev figures at LearnedLoopConfig.focus)
FOCUS_MAX = 0.75


def focus_objects(state: frozenset[Atom], goal: frozenset[Atom]) -> set[str]:
    """The objects a plan for `goal` from `state` needs to name: each one a goal atom names that does not hold now,
    and each one covering a cell the goal wants empty; then, until nothing is added, what rests on one of them (it
    must be cleared), what a goal atom of one of them names, and the top of what stands at a cell the goal puts one
    of them at (where nothing there reads clear, all of it); last, what each of them rests on (an operator that lifts
    an object off another names both).

    An operator's precondition and effects name its parameters and the locations alone, and its precondition is
    positive, so a plan over these objects, with every atom of the others left out (the cells they fill stay not
    `empty`, what they rest on not `clear`), is a plan of the whole state: it never moves the others, and their goal
    atoms hold now. It may be longer, with fewer places to set an object down, or not found; then the caller plans
    over every object (the incremental object sets of Silver et al., AAAI 2021, with the goal, not a learned score,
    choosing the first set)."""
    objects = lambda a: [x for x in a[1:] if x not in LOCATIONS]  # noqa: E731
    on = [(a[1], a[2]) for a in state if a[0] == "on"]
    at = [(a[1], a[2]) for a in state if a[0] == "at"]
    clear = {a[1] for a in state if a[0] == "clear"}
    vacate = {a[1] for a in goal - state if a[0] == "empty"}
    focus = {o for a in goal - state for o in objects(a)} | {o for o, c in at if c in vacate}
    while True:
        cells = {a[2] for a in goal if a[0] == "at" and a[1] in focus}
        there = {c: {o for o, where in at if where == c} for c in cells}
        more = ({x for x, y in on if y in focus} | {o for here in there.values() for o in (here & clear or here)}
                | {o for a in goal if set(objects(a)) & focus for o in objects(a)})
        if more <= focus:
            return focus | {y for x, y in on if x in focus}
        focus |= more


def focus_problem(objects: Sequence[str], state: frozenset[Atom], goal: frozenset[Atom]
                  ) -> tuple[list[str], frozenset[Atom], frozenset[Atom]] | None:
    """The problem over focus_objects alone (the first of object_sets), or None where object_sets has none."""
    sets = object_sets(objects, state, goal)
    return sub_problem(objects, sets[0], state, goal) if sets else None


def object_sets(objects: Sequence[str], state: frozenset[Atom], goal: frozenset[Atom]) -> list[set[str]]:
    """The growing sets of objects a planning step plans over before every object (incremental object sets, as in
    Silver et al., AAAI 2021, with the goal, not a learned score, choosing them): focus_objects; then those and
    every item read clear, the tops of the other stacks, as places to set an object on where the cells the others
    fill leave the focus none. Each set holds at most FOCUS_MAX of the objects (grounding a set costs about the cube
    of its size, so one of nearly every object costs what the whole does); none where the focus is empty (the goal
    holds now, and the whole problem says so at once). A plan over any set is a plan of the whole state
    (focus_objects says why)."""
    few, cap = focus_objects(state, goal), FOCUS_MAX * len(objects)
    if not few or len(few) > cap:
        return []
    more = few | {a[1] for a in state if a[0] == "clear"}
    return [few, more] if few < more and len(more) <= cap else [few]


def sub_problem(objects: Sequence[str], few: set[str], state: frozenset[Atom], goal: frozenset[Atom]
                ) -> tuple[list[str], frozenset[Atom], frozenset[Atom]]:
    """The problem over the objects `few` alone: those objects (in the order of `objects`), and the atoms of state
    and goal that name no other object (the cells the others fill stay not `empty`)."""
    keep = lambda atoms: frozenset(a for a in atoms if all(x in few for x in a[1:] if x not in LOCATIONS))  # noqa: E731
    return [o for o in objects if o in few], keep(state), keep(goal)


class Translations:
    """The translated tasks of one episode, by the objects planned over (LearnedLoopConfig.reuse_translation): the
    last few, each with the state it was translated from (search.sas_task.Translation)."""

    KEEP = 4  # sets of objects: the whole scene and the latest object sets (a 10-object task is about 2 MB)

    def __init__(self, predicates: Iterable[str]) -> None:
        self.known = set(predicates)  # what problem_pddl writes of a state
        self.tasks: dict[tuple[str, ...], Translation] = {}
        self.reused = 0

    def task_for(self, names: Sequence[str], state: frozenset[Atom], goal: frozenset[Atom]) -> str | None:
        """The kept task over these objects, from state to goal, or None (none kept, or it cannot stand for them)."""
        kept = self.tasks.get(tuple(names))
        text = kept.task_for([a for a in state if a[0] in self.known], goal) if kept is not None else None
        self.reused += text is not None
        return text

    def keep(self, names: Sequence[str], state: frozenset[Atom], sas_text: str) -> None:
        """Keep the translator's task over these objects, translated from state."""
        try:
            translation = Translation.of(sas_text, [a for a in state if a[0] in self.known])
        except ValueError:
            return  # not one that can be reused (search.sas_task.parse_sas)
        self.tasks.pop(tuple(names), None)
        self.tasks[tuple(names)] = translation
        while len(self.tasks) > self.KEEP:
            self.tasks.pop(next(iter(self.tasks)))


class Grounding:
    """The calls of one planning step that the time limit stopped before search began, as (objects, time limit):
    a later call over at least as many objects in at most as much time would be stopped there too, so it is not
    made, and its time goes to the calls that can still finish (at 9-10 objects the translator alone takes 3-6 s).
    A call whose translation is kept (Translations) goes straight to search, so nothing rules it out."""

    def __init__(self, translations: Translations | None = None) -> None:
        self.stopped: list[tuple[int, float]] = []
        self.translations = translations

    def hopeless(self, n: int, timeout_s: float) -> bool:
        return any(n >= m and timeout_s <= t for m, t in self.stopped)

    def note(self, plan: PlanResult, n: int, timeout_s: float) -> None:
        if plan.status.name == "TIMEOUT" and plan.extra.get("phase") in ("translation", "start-up"):
            self.stopped.append((n, timeout_s))


def call(domain: str, predicates: dict, names: list[str], state: frozenset[Atom], goal: frozenset[Atom],
         planner: str, timeout_s: float, grounding: Grounding | None) -> PlanResult:
    """One planner call over the objects `names`: the search alone on a translation kept this episode where one can
    stand for state and goal (Translations); else, where grounding says it cannot get past the translator in
    timeout_s, a TIMEOUT result without one; else the planner on the PDDL problem, its translation kept."""
    translations = grounding.translations if grounding is not None else None
    sas = translations.task_for(names, state, goal) if translations is not None else None
    if sas is not None:
        return solve_sas_text(sas, planner, timeout_s)
    problem = problem_pddl("p", names, state, goal, predicates)
    if grounding is None:
        return solve_texts(domain, problem, planner, timeout_s)
    n = len(names)
    if grounding.hopeless(n, timeout_s):
        return failed(planner, PlanStatus.TIMEOUT, time.perf_counter(), f"{planner} not called: {n} objects "
                      f"did not get past translation in as much time this step", phase="translation")
    if translations is None:
        plan = solve_texts(domain, problem, planner, timeout_s)
    else:
        plan, sas = solve_keeping_translation(domain, problem, planner, timeout_s)
        if sas is not None:
            translations.keep(names, state, sas)
    grounding.note(plan, n, timeout_s)
    return plan


def solve(domain: str, predicates: dict, objects: list[str], state: frozenset[Atom], goal: frozenset[Atom],
          planner: str, focus: bool, timeout_s: float, grounding: Grounding | None = None
          ) -> tuple[PlanResult, tuple[list[str], frozenset[Atom], frozenset[Atom]]]:
    """A plan for `goal` from `state` by `planner` (search.stock_planners.STOCK_PLANNERS), and the (objects, state,
    goal) it was found for: with `focus`, over each of object_sets in turn, each in FOCUS_SHARE of the time left,
    until one yields a plan; then over every object in the time left. `grounding` (one planning step's) skips the
    calls that could not get past translation and holds the episode's kept translations: where one of every object
    stands for this state and goal, the search on it alone, which costs less than translating any object set
    (about 1 s at 10 objects, where translating 7 of them takes 1-2 s)."""
    t0 = time.perf_counter()
    translations = grounding.translations if grounding is not None else None
    whole = translations.task_for(objects, state, goal) if translations is not None else None
    if whole is not None:  # search alone: no object set is cheaper
        return solve_sas_text(whole, planner, timeout_s), (objects, state, goal)
    for few in object_sets(objects, state, goal) if focus else []:
        names, few_state, few_goal = sub_problem(objects, few, state, goal)
        left = max(timeout_s - (time.perf_counter() - t0), 1.0)
        plan = call(domain, predicates, names, few_state, few_goal, planner, left * FOCUS_SHARE, grounding)
        if plan.status.name == "SOLVED":
            return plan, (names, few_state, few_goal)
    left = max(timeout_s - (time.perf_counter() - t0), 1.0)
    return call(domain, predicates, objects, state, goal, planner, left, grounding), (objects, state, goal)


def shortest_plan(translations: Translations, names: list[str], state: frozenset[Atom], goal: frozenset[Atom],
                  timeout_s: float) -> list[str] | None:
    """A shortest plan from state to goal over the objects `names` by stock A* with LM-cut (fd-lmcut) on the
    translation kept of them (Translations: search alone, no grounding), or None where none is kept or it finds none
    in timeout_s. Run after a satisficing planner's first plan, whose translation it searches again."""
    sas = translations.task_for(names, state, goal)
    if sas is None:
        return None
    plan = solve_sas_text(sas, "fd-lmcut", timeout_s)
    return list(plan.steps) if plan.status is PlanStatus.SOLVED else None


__all__ = ["FOCUS_MAX", "FOCUS_SHARE", "Grounding", "LOCATIONS", "Translations", "call", "focus_objects",
           "focus_problem", "object_sets", "shortest_plan", "solve", "sub_problem"]
