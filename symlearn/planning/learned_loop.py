"""The learned relational route, closed loop in simulation: observe, compute the learned state, plan, act, repeat.

At every step the scene is observed, the relational model computes its symbolic state (objects o1..ok,
`(at o l)`, `(rK a b)`, `(uB o)`: symlearn.symbolic.learned_state), the state and the goal are written as a
PDDL problem of the learned domain (pddl_export.learned_domain), stock Fast Downward plans (a satisficing
planner's plan then shortened, search.plan_shortening), and the first action of the plan is executed; then the
loop observes again, and keeps the rest of the plan while the scene reads as the domain predicted
(LearnedLoopConfig.monitor), else plans again. An object's unary bits are those it showed
so far in the episode (LearnedLoopConfig.unary): the domain takes them for properties, the encoder reads them anew
from each view. The goal is given as the problem's goal scene,
as the seed paper gives it: the scene is placed, observed and turned into learned atoms the same way, and the
goal keeps its `at` atoms and the atoms of the relation heads named in `goal_relations`. Each call plans first over
the objects the goal needs, then over those and the tops of the other stacks, so that a scene of 10 objects need
not be grounded whole, and searches a translation kept from an earlier step where it can (learned_calls).

Success is the simulator's: every object within the problem's tolerance of its goal position.
"""
from __future__ import annotations

import dataclasses
import re
from collections import Counter
import time
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from pddl_export.learned_domain import Atom, Operator, domain_pddl, predicates_of, step_successor
from search.plan_shortening import shorten_plan
from search.stock_planners import STOCK_PLANNERS
from symlearn.config_file import TIMEOUT_S, Bound, check_bounds
from symlearn.planning.learned_calls import Grounding, Translations, shortest_plan, solve
from symlearn.problems.problem import GOAL_TOLERANCE_M, Problem, max_goal_distance
from symlearn.symbolic.learned_state import atoms_of, scene_symbols
from symlearn.world import N_LOCATIONS, Action


UNARY = re.compile(r"u\d+")  # the unary bits' predicates, (uB o)
RELAX_SHARE = 0.6  # of a planner call's time limit for the whole goal, when relax_unreachable may plan again
# with reuse_translation, the seconds of a planner call's time limit left for the relaxed goal instead: a translation
# of the whole goal's call is kept even where its search runs out of time, and the relaxed goal's call then searches
# the same task, which takes about 1 s at 10 objects
RELAX_RESERVE_S = 2.0
HIDDEN_BITS = ("off", "always", "unsolvable")  # LearnedLoopConfig.hidden_bits


@dataclass(frozen=True)
class LearnedLoopConfig:
    """How the learned route runs a problem."""

    # a search.stock_planners configuration: A* with LM-cut, chosen on dev (cover model: 0.975 / 0.85 at 1-5 / 6-8
    # objects against lama-first's 0.925 / 0.80; lama-first's first plans run 1.2-1.9 times the shortest, and an
    # object moved out of the way on a detour can lose the unary bits the next step needs)
    planner: str = "fd-lmcut"
    timeout_s: float = 10.0  # per planner call
    max_steps_factor: float = 2.0  # at most factor x the generator's plan length + 2 actions are executed
    goal_relations: tuple[str, ...] = ()  # object-object heads ("r1", ...) the goal keeps beside `at`
    drop: tuple[str, ...] = ()  # the ablation: predicates ("r1", "nothing-r1", ...) removed from domain and states
    # the ablation of what decides where an action applies: predicates removed from every operator's precondition
    # alone (effects, states and goals keep them, so a goal can still be stated and reached); a location parameter
    # no precondition names then ranges over every cell, and the robot picks where the plan says
    drop_preconditions: tuple[str, ...] = ()
    # when the planner proves the whole goal unreachable in the learned domain (a goal scene's relation read wrong
    # can ask for two objects on one) or runs out of RELAX_SHARE of the time limit, plan for its `at` atoms alone
    # (relaxed_goal) in the time left
    relax_unreachable: bool = False
    # plan first over the objects the goal needs to move and what stands in their way (focus_objects), then over
    # those and the tops of the other stacks (object_sets): a plan over them is a plan of the whole scene, and at
    # 9-10 objects grounding every object takes the translator 3-6 s of the time limit; chosen on dev (cover model,
    # walks 1-5 / 6-8 / 9-10 / structures): 0.975 / 0.85 / 0.60 / 0.82, without 0.975 / 0.85 / 0.40 / 0.82, and
    # the median call at 6-8 objects 0.21 s against 1.96 s. The second set, FOCUS_MAX and the calls a translation
    # timeout rules out (_Grounding): carry model, lama-first, two runs at a time, dev 9-10 (105 / 106): seed 0
    # 0.70 / 0.75 -> 0.85 / 0.75, seed 1 0.65 / 0.55 -> 0.65 / 0.65 (53 -> 58 of 80, within a 20-problem set's
    # noise of 0.1 each); 6-8: seed 0 (107) 0.90 -> 0.95, seed 1 (102) 0.80 -> 0.80; 1-5 and structures unchanged
    # (relations_dev_object_sets.json)
    focus: bool = True
    # execution monitoring: the rest of a plan is kept, without a planner call, while each scene observed is the
    # one its last step predicted (every atom but the unary bits, which flip with the view and which no operator
    # changes) and its next step applies there; else the loop plans again. Planning again at every step undoes the
    # last action where a bit flipped on the moved object (a cube set on a stick's end loses the bit the next step
    # needs; from the scene before, with the bit back, the plan is to set it there again). Chosen on dev with
    # unary="seen" (carry model, LM-cut, walks 1-5 / 6-8 / 9-10 / structures): 1.00 / 0.85 / 0.75 / 0.86 against
    # 0.975 / 0.85 / 0.70 / 0.82 without either; monitor alone changed no outcome and halved the planner calls at 1-5
    monitor: bool = True
    # which unary bits a state holds: "each" those read from the scene now; "first" those read in the episode's
    # first scene, kept (no operator changes a bit: the domain takes them for properties of the object, while the
    # encoder's bits flip with the view, a cube set on a stick's end read without the bit the next step needs);
    # "seen" every bit read of the object in the episode so far (preconditions are positive: a bit read once
    # permits what it permits); dev, without monitor: "seen" 0.975 / 0.85 / 0.75 / 0.86, "first" 1.00 / 0.75 /
    # 0.70 / 0.86, "each" 0.975 / 0.85 / 0.70 / 0.82
    unary: str = "seen"
    # an item read with another resting on it shows other bits than uncovered, and the domain takes bits for
    # properties, so an item covered now may be proved immovable. "always": each covered item holds every unary bit
    # the domain reads (dev, lama-first: seed 1 at 6-8 / 9-10 0.80 / 0.60 against 0.70 / 0.55; the shipped seed 0
    # mixed, walks 1-5 / 6-8 / 9-10 / structures 0.95 / 0.85 / 0.75 / 0.68 against 0.975 / 0.85 / 0.70 / 0.77,
    # relations_dev_hidden_bits.json). "unsolvable": only where the planner proves the goal unreachable from the
    # state as read, plan again with those bits (before relax_unreachable's `at` goal), and keep the bits that plan
    # assumed for the rest of the episode, as if seen; a plan found without them stays as it was. "off": neither.
    # Chosen on dev, lama-first, two runs at a time: seed 1 at 6-8 / 9-10 0.80 / 0.65 against 0.70 / 0.55 (assumed
    # bits not kept: 0.80 / 0.60); seed 0 proved no goal unreachable at 1-10 objects on dev, so it never planned
    # again there (relations_dev_hidden_unsolvable.json)
    hidden_bits: str = "unsolvable"
    # seconds of a planner call's time limit (of what the planner left) for shortening a satisficing planner's plan
    # by plan neighborhood graph search (search.plan_shortening); 0 executes the plan as it comes. An optimal
    # planner's plan is never shortened: none shorter exists. Chosen on dev (carry, lama-first, walks 1-5 / 6-8 /
    # 9-10 / structures): 0.975 / 0.85 / 0.70 / 0.77 against 0.95 / 0.90 / 0.70 / 0.68 without, executed over the
    # shortest 1.02 / 1.12 / 1.21 / 1.00 against 1.18 / 1.25 / 1.08 / 1.06 (LM-cut with it, 2 s: the same outcomes)
    shorten_s: float = 2.0
    # keep each translation of the episode (by the objects planned over) and search it from a later state to a later
    # goal where it can stand for them (learned_calls.Translations, search.sas_task; else translate again); a step
    # whose whole task is kept searches it first, and the whole goal gets all of the time but RELAX_RESERVE_S, as
    # the relaxed goal searches its translation. At 10 objects the translator takes 5-6 s of CPU and search often
    # under 1 s, so that 6 s of 10 (RELAX_SHARE) left many whole problems untranslated. Chosen on dev (lama-first,
    # two runs at a time, 9-10 objects, 105 / 106): whole-scene calls stopped in translation 13 -> 4, goals built
    # 0.65 / 0.75 -> 0.80 / 0.75 (28 -> 31 of 40; the code before read 0.85 / 0.75 the day before, so within a
    # set's noise); 6-8, 1-5 and structures within a problem or two, each that changed the same again with it off
    # (relations_dev_reuse.json). Stock Fast Downward's search (the planner's own options) on its translator's task,
    # told to keep every variable; Fast Downward only
    reuse_translation: bool = True
    # seconds of a planner call's time limit (of what the planner left) for stock A* with LM-cut on the translation
    # of a satisficing planner's first plan (kept: search alone, learned_calls.shortest_plan), whose shortest plan
    # then replaces it; where it finds none in time, the first plan is shortened (shorten_s). 0: none. lama-first's
    # first plans wander (14 actions where 7 do, 31 after an action that did not do what the domain said), and a
    # long plan meets the step limit. Chosen on dev (with reuse_translation, two runs at a time): structures 0.727
    # -> 0.864, walks 1-5 0.95 -> 0.975, 6-8 0.85 / 0.90 -> 0.85 / 0.95, 9-10 31 -> 29 of 40 (123 of 142 against
    # 120; relations_dev_reuse.json)
    optimal_s: float = 3.0

    def __post_init__(self) -> None:
        """Refuse a planner, time limit, step factor or unary reading no run can use, before the simulator starts."""
        if self.unary not in ("each", "first", "seen"):
            raise ValueError(f"unary must be each, first or seen; got {self.unary!r}")
        if self.hidden_bits not in HIDDEN_BITS:
            raise ValueError(f"hidden_bits must be {', '.join(HIDDEN_BITS)}; got {self.hidden_bits!r}")
        if self.planner not in STOCK_PLANNERS:
            raise ValueError(f"unknown planner {self.planner!r}; known: {', '.join(STOCK_PLANNERS)}")
        check_bounds(self, {"timeout_s": TIMEOUT_S, "max_steps_factor": Bound(0.0, 100.0, lo_open=True),
                            "shorten_s": Bound(0.0, 3600.0), "optimal_s": Bound(0.0, 3600.0)})


@dataclass
class LoopResult:
    """One problem's run: success, the actions executed, planner calls and their times, why it stopped."""

    name: str
    k: int
    optimal_length: int | None
    success: bool
    actions: list[int] = field(default_factory=list)
    plan_times_s: list[float] = field(default_factory=list)
    first_plan_length: int | None = None
    stop: str = ""
    relaxed_calls: int = 0  # planner calls made again for the goal's `at` atoms (relaxed_goal, relax_unreachable)
    hidden_calls: int = 0  # planner calls made again with the covered items' bits (hidden_bits "unsolvable")
    kept_steps: int = 0  # actions executed from a plan made at an earlier step (LearnedLoopConfig.monitor)

    def to_json(self) -> dict:
        return dict(self.__dict__)


def observe_atoms(sim, model, blob: dict) -> frozenset[Atom]:
    """The learned state of the scene in the simulator now."""
    obs = sim.observe()
    k = obs.crops.shape[0]
    codes, rel = scene_symbols(model, blob["windows"].numpy(), obs.crops[None].astype(np.float16),
                               obs.origins[None], np.array([k]))
    return atoms_of(codes[0], rel[0], k, model.cfg.support)


def goal_atoms(sim, model, blob: dict, problem: Problem, relations: Sequence[str]) -> frozenset[Atom]:
    """The goal scene's learned atoms: `at` and the named relation heads, for the objects the goal fixes, without
    the `on` atoms that contradict its `at` atoms (consistent_goal). With a cover model (model.cfg.cover) and no free
    object, also its `empty` atoms: a far-row stick at l0 covers l0 and l1, one at l1 covers l0 and l2 as well, so
    the cells it leaves empty are part of where it lies (with one location per object they follow from `at`). With
    `on`, also `(on-table o)` for what rests on no object: else a cube on a stick's end over l0 meets "the cube at
    l0, the stick at l1 and l2" as well as the cube on the table beside it does (dev structures 0.73 -> 0.82)."""
    sim.reset(problem.goal)
    free = {f"o{i + 1}" for i in problem.free}
    keep = ({"at", *relations} | ({"empty"} if model.cfg.cover and not free else set())
            | ({"on-table"} if "on" in relations else set()))
    return consistent_goal(frozenset(a for a in observe_atoms(sim, model, blob)
                                     if a[0] in keep and not free & set(a[1:])))


def consistent_goal(goal: frozenset[Atom]) -> frozenset[Atom]:
    """The goal without `(on a b)` where the goal puts a and b at no common location (an object of a cover model
    that something stands on is at none: the tool meets what is on top; its `on` atoms stay): a release puts an
    object at the location of what it lands on, so no plan of the learned domain reaches both, and a planner would
    spend its whole time limit finding that out. Such an atom is the rests-on head misreading the goal scene (a cube
    beside a tower read as resting on it), or a cube on a stick's end over the next cell, which the `at` atoms fix.
    Likewise every `(on a b)` of a b that two goal objects rest on: the domain puts one object on a clear one, and
    the head reads the top of a three-cube tower as resting on the bottom now and then. And both of `(on a b)`,
    `(on b a)`: no scene holds them, and proving that takes a planner longer than its time limit at 7 objects.
    Then what rests on an object is put at the cells it shares with it alone (_on_support_cells)."""
    where = _cells_of(goal)  # one location each, or every cell an object covers (a cover model)
    apart = lambda a, b: a in where and b in where and not where[a] & where[b]  # noqa: E731
    kept = [a for a in goal if a[0] != "on" or not (apart(a[1], a[2]) or ("on", a[2], a[1]) in goal)]
    supports = Counter(a[2] for a in kept if a[0] == "on")
    kept = [a for a in kept if a[0] != "on" or supports[a[2]] == 1]
    return frozenset(_on_support_cells(kept, where))


def _on_support_cells(goal: list[Atom], where: dict[str, set[str]]) -> list[Atom]:
    """`(at a l)` dropped for every cell l that a's support b does not cover, where `(on a b)` and a and b share a
    cell: a release onto an object puts the held one at that object's cell alone (move operators add `(at ?o1 ?to)`
    only), so no plan reaches more. The top of a three-cube tower in the near row is read over two cells now and
    then; the cells of what it rests on, read lower, fix it.
    From the bottom of each stack up, so a tower's fixed cells reach its top."""
    below = {a[1]: a[2] for a in goal if a[0] == "on"}
    cells = {o: set(c) for o, c in where.items()}
    for _ in range(len(below)):
        changed = False
        for a, b in below.items():
            if a in cells and b in cells and cells[a] & cells[b] and not cells[a] <= cells[b]:
                cells[a] &= cells[b]
                changed = True
        if not changed:
            break
    return [g for g in goal if g[0] != "at" or g[2] in cells[g[1]]]


def relaxed_goal(located: frozenset[Atom], state: frozenset[Atom]) -> frozenset[Atom]:
    """The goal's `at` atoms, with an object read over several goal cells kept at those it covers now, where it
    covers any: the same object, read over one more cell in the goal scene than now (a stick under a cube placed
    beside its end), asks for a cell no operator adds."""
    now = _cells_of(state)
    keep = {o: (c & now[o] if len(c) > 1 and c & now.get(o, set()) else c) for o, c in _cells_of(located).items()}
    return frozenset(a for a in located if a[2] in keep[a[1]])


def _cells_of(atoms: Iterable[Atom]) -> dict[str, set[str]]:
    """Each object's locations among the `(at o l)` atoms."""
    cells: dict[str, set[str]] = {}
    for a in atoms:
        if a[0] == "at":
            cells.setdefault(a[1], set()).add(a[2])
    return cells


def step_action(step: str, ops: dict[str, Operator]) -> int:
    """A plan step "(move-3 l0 o1 l2)" -> the action id pick * 6 + release of its location arguments."""
    parts = step.strip("() ").split()
    op = ops[parts[0]]
    binding = {v: a for (v, _), a in zip(op.parameters, parts[1:])}
    pick = binding.get("?at", binding.get("?from"))
    release = binding.get("?at", binding.get("?to"))
    loc = re.compile(r"l(\d)$")
    return Action(int(loc.match(pick).group(1)), int(loc.match(release).group(1))).id


def without(ops: Sequence[Operator], drop: Sequence[str], preconditions: Sequence[str] = ()) -> list[Operator]:
    """The operators with every atom of the predicates in `drop` removed, and the atoms of those in `preconditions`
    removed from their preconditions alone (the load-bearing ablations)."""
    if not drop and not preconditions:
        return list(ops)
    gone, gone_pre = set(drop), {*drop, *preconditions}

    def keep(atoms: Sequence[Atom], names: set[str]) -> tuple[Atom, ...]:
        return tuple(a for a in atoms if a[0] not in names)

    return [dataclasses.replace(o, precondition=keep(o.precondition, gone_pre), add=keep(o.add, gone),
                                delete=keep(o.delete, gone)) for o in ops]


def check_ablation(cfg: LearnedLoopConfig, ops: Sequence[Operator], where: str) -> None:
    """Refuse (ValueError, one line) a predicate in cfg.drop or cfg.drop_preconditions that the domain of `where`
    does not have: an ablation of a name it lacks would change nothing and read as a finding."""
    have = set(predicates_of(ops))
    for key in ("drop", "drop_preconditions"):
        unknown = [p for p in getattr(cfg, key) if p not in have]
        if unknown:
            raise ValueError(f"[learned_loop] {key} names {', '.join(map(repr, unknown))}, which the domain of {where} "
                             f"does not have; it has {', '.join(sorted(have))}")


def run_learned(sim, model, blob: dict, ops: Sequence[Operator], problem: Problem,
                cfg: LearnedLoopConfig = LearnedLoopConfig(), goal: frozenset[Atom] | None = None) -> LoopResult:
    """One problem, closed loop (see the module docstring). `goal`: atoms a person wrote (objects o1..ok), in
    place of those read from the problem's goal scene; success is still the simulator's, against the goal scene."""
    ops = without(ops, cfg.drop, cfg.drop_preconditions)
    domain = domain_pddl(ops)
    by_name = {o.name: o for o in ops}
    predicates = predicates_of(ops)
    unary_names = sorted(p for p in predicates if UNARY.fullmatch(p))
    if goal is None:
        goal = goal_atoms(sim, model, blob, problem, cfg.goal_relations)
    goal = frozenset(a for a in goal if a[0] not in cfg.drop)
    located = frozenset(a for a in goal if a[0] == "at")  # what relax_unreachable plans for
    sim.reset(problem.initial)
    objects = [f"o{i + 1}" for i in range(problem.initial.k)]
    res = LoopResult(problem.name, problem.initial.k, problem.optimal_length, False)
    limit = int(cfg.max_steps_factor * max(problem.generator_length, 1)) + 2
    rest: list[str] = []  # the steps left of the plan being executed, and the scene its last step predicted
    expected: frozenset[Atom] | None = None
    kept: set[Atom] | None = None  # the unary bits the last state held
    assumed: set[Atom] = set()  # the bits a plan assumed for covered items (hidden_bits "unsolvable")
    translations = Translations(predicates) if cfg.reuse_translation else None
    while True:
        if max_goal_distance(sim.get_scene(), problem.goal, problem.free) <= GOAL_TOLERANCE_M:
            res.success, res.stop = True, "goal reached"
            return res
        if len(res.actions) >= limit:
            res.stop = "step limit"
            return res
        state = frozenset(a for a in observe_atoms(sim, model, blob) if a[0] not in cfg.drop)
        bits = {a for a in state if UNARY.fullmatch(a[0])}
        kept = held_bits(cfg.unary, kept, bits)
        state = (state - bits) | kept | assumed
        if cfg.hidden_bits == "always":
            state |= covered_bits(state, unary_names)
        if goal <= state:
            res.stop = "goal believed reached"
            return res
        keep = cfg.monitor and rest and expected is not None and _as_predicted(state, expected)
        after = step_successor(by_name, rest[0], state) if keep else None
        if after is not None:
            res.kept_steps += 1
        else:
            rest, planned = _plan(ops, domain, predicates, objects, state, goal, located, cfg, res, unary_names,
                                  translations)
            if not rest:
                return res
            assumed |= planned - state  # the covered items' bits a plan assumed stay for the episode, as if seen
            after = step_successor(by_name, rest[0], planned)
        step, expected = rest.pop(0), after
        action = step_action(step, by_name)
        sim.step(Action(action // N_LOCATIONS, action % N_LOCATIONS))
        res.actions.append(action)


def covered_bits(state: frozenset[Atom], unary: Sequence[str]) -> set[Atom]:
    """Every unary bit of `unary` for each item another rests on in `state` (LearnedLoopConfig.hidden_bits)."""
    return {(u, a[2]) for a in state if a[0] == "on" for u in unary}


def held_bits(mode: str, before: set[Atom] | None, now: set[Atom]) -> set[Atom]:
    """The unary bits a state of the loop holds (LearnedLoopConfig.unary), given those the state before held (None
    at the first) and those read from the scene now: "each" those read now, "first" those of the first scene,
    "seen" every one read so far."""
    if mode == "each" or before is None:
        return set(now)
    return before | now if mode == "seen" else before


def _as_predicted(state: frozenset[Atom], expected: frozenset[Atom]) -> bool:
    """Whether the observed state is the predicted one on every atom but the unary bits (LearnedLoopConfig.monitor)."""
    relational = lambda atoms: {a for a in atoms if not UNARY.fullmatch(a[0])}  # noqa: E731
    return relational(state) == relational(expected)


def _plan(ops: Sequence[Operator], domain: str, predicates: dict, objects: list[str], state: frozenset[Atom],
          goal: frozenset[Atom], located: frozenset[Atom], cfg: LearnedLoopConfig, res: LoopResult,
          unary: Sequence[str], translations: Translations | None = None) -> tuple[list[str], frozenset[Atom]]:
    """A plan's steps from state (shortened, LearnedLoopConfig.shorten_s), its call recorded in res, and the state
    it was planned from (state, or with the covered items' bits: hidden_bits "unsolvable"); no steps, with res.stop
    saying why, where no plan came."""
    t0 = time.perf_counter()
    share = RELAX_SHARE if cfg.relax_unreachable else 1.0  # of the time, leaving the rest for the relaxed goal
    if cfg.relax_unreachable and translations is not None:
        share = max(1.0 - RELAX_RESERVE_S / cfg.timeout_s, RELAX_SHARE)
    grounding = Grounding(translations)
    plan, solved = solve(domain, predicates, objects, state, goal, cfg.planner, cfg.focus, cfg.timeout_s * share,
                         grounding)
    hidden = covered_bits(state, unary) if cfg.hidden_bits == "unsolvable" else set()
    if plan.status.name == "UNSOLVABLE" and not hidden <= state:
        res.hidden_calls += 1
        state = state | hidden
        left = max(cfg.timeout_s - (time.perf_counter() - t0), 1.0)
        plan, solved = solve(domain, predicates, objects, state, goal, cfg.planner, cfg.focus, left * share,
                             grounding)
    if cfg.relax_unreachable and plan.status.name in ("UNSOLVABLE", "TIMEOUT"):
        relaxed = relaxed_goal(located, state)
        if relaxed != goal:
            res.relaxed_calls += 1
            left = max(cfg.timeout_s - (time.perf_counter() - t0), 1.0)
            plan, solved = solve(domain, predicates, objects, state, relaxed, cfg.planner, cfg.focus, left,
                                 grounding)
    steps = list(plan.steps) if plan.status.name == "SOLVED" else []
    if res.first_plan_length is None and steps:
        res.first_plan_length = len(steps)
    shortest = STOCK_PLANNERS[cfg.planner].optimal  # an optimal plan is shortest
    budget = min(cfg.optimal_s, cfg.timeout_s - (time.perf_counter() - t0))
    if len(steps) > 1 and budget > 0 and not shortest and translations is not None:
        better = shortest_plan(translations, *solved, budget)
        if better is not None and len(better) <= len(steps):
            steps, shortest = better, True
    budget = min(cfg.shorten_s, cfg.timeout_s - (time.perf_counter() - t0))
    if len(steps) > 1 and budget > 0 and not shortest:
        steps = shorten_plan(ops, *solved, steps, timeout_s=budget, n_locations=N_LOCATIONS)
    res.plan_times_s.append(round(time.perf_counter() - t0, 3))
    if not steps:
        res.stop = f"planner: {plan.status.name.lower()} {plan.message}"[:200]
        return [], state
    return steps, state


def summarize(results: Sequence[LoopResult]) -> dict:
    """Success rate by object count band, and executed length over the shortest plan."""
    out = {}
    for name, lo, hi in (("1-5", 1, 5), ("6-8", 6, 8), ("9-10", 9, 10), ("all", 1, 99)):
        rows = [r for r in results if lo <= r.k <= hi]
        if not rows:
            continue
        ok = [r for r in rows if r.success and r.optimal_length]
        out[name] = {"problems": len(rows), "success": round(sum(r.success for r in rows) / len(rows), 3),
                     "length_over_shortest": round(float(np.mean([len(r.actions) / r.optimal_length for r in ok])), 3)
                     if ok else None,
                     "median_plan_s": round(float(np.median([t for r in rows for t in r.plan_times_s])), 3)
                     if any(r.plan_times_s for r in rows) else None,
                     "max_plan_s": max((t for r in rows for t in r.plan_times_s), default=None)}
    return out
