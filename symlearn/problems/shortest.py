"""The shortest plan of a problem: an A* search over the simulator's own symbolic model.

A problem's depth is the length of the shortest plan that reaches its goal, not the length of the
random walk that made it (a walk of 8 actions often ends one action from where it began). The search
runs over symlearn.problems.stacking (which object stands on which, at which location; `successors`),
from the problem's initial scene read as a stacking state (`scene_state`), and stops at the first state
whose judged objects (all but the goal's free ones) stand where the goal scene has them: at the same
location and at the same height, i.e. on the same kind of support, which is what the 2 cm success test
judges (a free object may hold one up in place of another).

Where the model cannot decide, the answer says why and has no length (`ShortestPlan.reason`):

- "goal_off_locations": a judged object of the goal lies more than 5 cm from every location
  (Problem.goal_off_locations): no state of the model puts it there;
- "pose_not_covered": an object of the initial scene, or a judged one of the goal, is not where some
  state of the model puts it (within POSE_TOLERANCE_M), or stands tilted, or crosswise;
- "search_cap": no plan of at most MAX_PLAN_LENGTH actions (or within MAX_STATES states) reaches it;
- "unreachable": the whole state space of the model was searched and no state reaches the goal.

The model is checked against the simulator in tests/test_shortest.py: plans found here, executed there,
reach their goals within 2 cm, and are never longer than the reference plan.

    >>> shortest_plan(problem).length           # doctest: +SKIP
    2
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from symlearn.problems.problem import OPTIMAL_REASONS, Problem
from search.astar import astar
from search.result import PlanStatus
from symlearn.problems.stacking import LAYERS, LEVEL_M, State, carried, check_state, levels, successors
from symlearn.problems.goals import MAX_TILT_DEG, ObjectGoal, stick_covers
from symlearn.world import LOCATIONS, OBJECT_SIZE, TABLE_TOP_Z, ObjectState, ObjectType, Scene

POSE_TOLERANCE_M = 0.01  # an object this close (xy and z) to a model pose is in it; the simulator settles within 2 mm
MAX_YAW_DEG = 10.0  # a stick turned farther from the y axis has its ends elsewhere than the model says
MAX_PLAN_LENGTH = 12  # the search stops here: deeper goals are "search_cap"
MAX_STATES = 100_000  # and after this many expanded states (a 5-object space holds about 30,000)
SEARCH_TIMEOUT_S = 600.0  # a bound on one search's wall clock; MAX_STATES stops it first
REASONS = OPTIMAL_REASONS


@dataclass(frozen=True)
class ShortestPlan:
    """A shortest plan (action ids) and its length, or no length and the reason the model cannot decide."""

    length: int | None
    plan: tuple[int, ...] | None
    reason: str | None = None
    detail: str = ""  # one line: what was off, or how far the search went
    states: int = 0  # distinct states the search visited

    def __post_init__(self) -> None:
        if (self.length is None) == (self.reason is None):
            raise ValueError("a shortest plan has a length or a reason, not both")
        if self.reason is not None and self.reason not in REASONS:
            raise ValueError(f"unknown reason {self.reason!r}; known: {', '.join(REASONS)}")


class NotCovered(ValueError):
    """A scene the model has no state for; its message is one line."""


def _place(o, i: int) -> tuple[int, int]:
    """(location, layer) of one object: within POSE_TOLERANCE_M of a location and of a whole layer, upright."""
    x, y, z = o.position
    dists = [math.hypot(x - lx, y - ly) for lx, ly in LOCATIONS]
    loc = min(range(len(LOCATIONS)), key=dists.__getitem__)
    if dists[loc] > POSE_TOLERANCE_M:
        raise NotCovered(f"object {i} is {dists[loc] * 100:.1f} cm from the nearest location ({loc})")
    qx, qy, qz, qw = o.orientation
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy)))))
    if tilt > MAX_TILT_DEG:
        raise NotCovered(f"object {i} is tilted by {tilt:.0f} degrees")
    if o.type == ObjectType.STICK:
        yaw = math.degrees(math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)))
        off = min(abs(yaw), abs(abs(yaw) - 180.0))
        if off > MAX_YAW_DEG:
            raise NotCovered(f"the stick (object {i}) is turned {off:.0f} degrees from the y axis")
    bottom = (z - OBJECT_SIZE[o.type][2] / 2 - TABLE_TOP_Z) / LEVEL_M
    layer = round(bottom)
    if abs(bottom - layer) * LEVEL_M > POSE_TOLERANCE_M or layer < 0:
        raise NotCovered(f"object {i} hangs between layers ({bottom * LEVEL_M * 100:.1f} cm above the table)")
    return loc, layer


def scene_state(scene: Scene) -> State:
    """The stacking state of a scene: each object's location and support, read from its pose.

    Refused (NotCovered, one line) where an object is off the locations, tilted, between layers, or rests
    on nothing the model has (two supports, a stick over standing objects, a rider on a raised stick's end).
    """
    types = [o.type for o in scene.objects]
    places = [_place(o, i) for i, o in enumerate(scene.objects)]
    state: list = [None] * len(places)
    for i in sorted(range(len(places)), key=lambda i: places[i][1]):
        loc, layer = places[i]
        if layer == 0:
            state[i] = ObjectGoal(loc)
            continue
        under = [j for j, (lj, yj) in enumerate(places) if j != i and yj + LAYERS[types[j]] == layer
                 and (lj == loc or (types[j] == ObjectType.STICK and stick_covers(lj, loc)))]
        if len(under) != 1:
            raise NotCovered(f"object {i} at location {loc} rests on {'nothing' if not under else under}")
        state[i] = ObjectGoal(loc, under[0], places[under[0]][0] != loc)
    try:
        check_state(tuple(state), types)
    except ValueError as e:
        raise NotCovered(str(e)) from None
    return tuple(state)


def state_scene(state: State, types) -> Scene:
    """The scene a state stands for: every object upright over its location, resting on its support's top."""
    lv = levels(state, types)
    return Scene(tuple(ObjectState(t, (*LOCATIONS[g.location], TABLE_TOP_Z + lv[i] * LEVEL_M + OBJECT_SIZE[t][2] / 2))
                       for i, (t, g) in enumerate(zip(types, state))))


def goal_places(problem: Problem) -> dict[int, tuple[int, int]]:
    """(location, layer) of every judged object of the goal scene; NotCovered when one has none."""
    return {i: _place(problem.goal.objects[i], i) for i in problem.fixed}


def lower_bound(state: State, types, want: dict[int, tuple[int, int]]) -> int:
    """Actions still needed at least: an admissible heuristic for the shortest-plan search.

    Every action picks one object and moves it with what it carries (`stacking.carried`); only a stick carries
    others (its riders), or a cube a stick rests on. An object outside the stick's group (the stick, what
    stands on it, what it rests on) moves only when it is picked itself, and nothing joins that group without
    moving: so each misplaced object outside the group needs an action of its own, and a misplaced member of
    the group one more, shared. With two or more sticks: one action while anything is misplaced.
    """
    lv = levels(state, types)
    wrong = [i for i, (loc, layer) in want.items() if state[i].location != loc or lv[i] != layer]
    if not wrong:
        return 0
    sticks = [i for i, t in enumerate(types) if t == ObjectType.STICK]
    if len(sticks) > 1:
        return 1
    group: set[int] = set()
    if sticks:
        s = sticks[0]
        group = {s, *carried(state, s)} | ({state[s].on} if state[s].on is not None else set())
    return sum(i not in group for i in wrong) + int(any(i in group for i in wrong))


def shortest_plan(problem: Problem, max_length: int = MAX_PLAN_LENGTH, max_states: int = MAX_STATES) -> ShortestPlan:
    """A* (search.astar, unit costs, the admissible `lower_bound`) from the initial scene's state to the first
    state that meets the goal (module doc): shortest plans, and far fewer states than a breadth-first search
    where the goal moves many objects one at a time (the 6-8-object scenes)."""
    if problem.goal_off_locations:
        return ShortestPlan(None, None, "goal_off_locations",
                            f"{problem.goal_off_locations} judged object(s) of the goal lie off the locations")
    try:
        start = scene_state(problem.initial)
    except NotCovered as e:
        return ShortestPlan(None, None, "pose_not_covered", f"initial scene: {e}")
    try:
        want = goal_places(problem)
    except NotCovered as e:
        return ShortestPlan(None, None, "pose_not_covered", f"goal scene: {e}")
    types = tuple(problem.initial.objects[i].type for i in range(problem.k))

    needs = lower_bound(start, types, want)
    if needs > max_length:
        return ShortestPlan(None, None, "search_cap", f"no plan of at most {max_length} actions (it needs at "
                                                      f"least {needs})", 0)
    pruned = False  # a state was cut off for needing more than max_length: exhausting the rest proves nothing

    def h(state: State) -> float:
        nonlocal pruned
        bound = lower_bound(state, types, want)
        if bound <= max_length:
            return float(bound)
        pruned = True
        return math.inf

    out = astar(start, lambda s: lower_bound(s, types, want) == 0,
                lambda s: ((a, child, 1.0) for a, child in successors(s, types)), h,
                max_expansions=max_states, timeout_s=SEARCH_TIMEOUT_S)
    if out.status == PlanStatus.SOLVED and len(out.actions) <= max_length:
        return ShortestPlan(len(out.actions), tuple(out.actions), states=out.expansions)
    if out.status == PlanStatus.UNSOLVABLE and not pruned:
        return ShortestPlan(None, None, "unreachable", f"all {out.expansions} states of the model within "
                                                       f"{max_length} actions searched", out.expansions)
    return ShortestPlan(None, None, "search_cap", f"no plan of at most {max_length} actions found in "
                                                  f"{out.expansions} states ({out.status.value})", out.expansions)


def with_shortest(problem: Problem) -> Problem:
    """The problem with its shortest plan recorded (optimal_length and optimal_plan, or optimal_reason)."""
    sp = shortest_plan(problem)
    return dataclasses.replace(problem, optimal_length=sp.length, optimal_reason=sp.reason, optimal_plan=sp.plan)
