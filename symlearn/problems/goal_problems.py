"""Goals made real: build a goal's arrangement in the simulator, run its reference plan, and make a Problem.

The arrangement is built by dropping the fixed objects in support order at their goal locations
(free objects after them, at an empty location), letting them settle, and checking every fixed
object against where the arrangement puts it (goals.arrangement_errors). A reference plan is run
from the initial scene; its end scene is the problem's goal and must agree with the arrangement
within 2 cm on the fixed objects; its shortest plan is recorded (symlearn.problems.shortest). The
simulator is passed in; nothing here imports pybullet.

    >>> with TabletopSimulator() as sim:                                              # doctest: +SKIP
    ...     problem = goal_problem(sim, load_goal(path), name=path.stem, where=f"goal file {path}")
"""
from __future__ import annotations

from pathlib import Path

from symlearn.problems.goals import ARRANGEMENT_TOLERANCE_M, Goal, arrangement_errors, drop_order, load_goal
from symlearn.problems.paths import check_safe_name
from symlearn.problems.problem import Problem, max_goal_distance
from symlearn.problems.shortest import with_shortest
from symlearn.world import FAR_ROW, N_LOCATIONS, ObjectType, Scene, decode_action


def _free_location(sim, otype: ObjectType, prefer: int) -> int | None:
    """An empty location for a free object (a stick in the far row also needs its neighbours empty)."""
    occupied = sim.occupied()
    for loc in [prefer] + [x for x in range(N_LOCATIONS) if x != prefer]:
        near = [loc] + ([n for n in FAR_ROW if abs(n - loc) == 1] if otype == ObjectType.STICK and loc in FAR_ROW else [])
        if not occupied[near].any():
            return loc
    return None


def build_arrangement(sim, goal: Goal, where: str) -> Scene:
    """Drop the arrangement in the simulator, settle, check it; the settled scene in identity order."""
    order = list(drop_order(goal))
    sim.build([(goal.spec[i][0], goal.targets[i].location) for i in order])
    for i in goal.free:
        loc = _free_location(sim, goal.spec[i][0], goal.spec[i][1])
        if loc is None:
            raise ValueError(f"{where}: no empty location left for the free object {i}")
        sim.drop_object(goal.spec[i][0], loc)
        order.append(i)
    dropped = sim.get_scene().objects
    scene = Scene(tuple(dropped[order.index(i)] for i in range(len(goal.spec))))
    errors = arrangement_errors(scene, goal)
    if errors:
        raise ValueError(f"{where}: the arrangement does not settle as stated: {'; '.join(errors)}")
    return scene


def run_plan(sim, goal: Goal, where: str) -> tuple[Scene, Scene]:
    """Build the initial scene, run the reference plan from it; (initial, end) scenes."""
    sim.build(goal.spec)
    initial = sim.get_scene()
    sim.reset(initial)  # execution starts from a reset to these poses, so the reference run does too
    for step, a in enumerate(goal.plan or ()):
        try:
            res = sim.step(decode_action(a))
        except RuntimeError as e:
            raise ValueError(f"{where}: reference plan step {step} ({a}) cannot be executed: {e}") from None
        if res.off_table:
            raise ValueError(f"{where}: reference plan step {step} ({a}) knocks an object off the table")
    return initial, sim.get_scene()


def goal_problem(sim, goal: Goal, name: str, where: str) -> Problem:
    """The Problem of a goal: its initial scene, and the plan's end scene (or the built arrangement) as goal."""
    arrangement = build_arrangement(sim, goal, where)
    initial, end = run_plan(sim, goal, where)
    if goal.plan is None:
        return _problem(where, name, goal, initial, arrangement)
    dist = max_goal_distance(end, arrangement, goal.free)
    if dist > ARRANGEMENT_TOLERANCE_M:
        raise ValueError(f"{where}: the reference plan does not reach the goal (a fixed object ends "
                         f"{dist * 100:.1f} cm from the arrangement, more than {ARRANGEMENT_TOLERANCE_M * 100:.0f} cm)")
    return _problem(where, name, goal, initial, end)


def _problem(where: str, name: str, goal: Goal, initial: Scene, goal_scene: Scene) -> Problem:
    try:
        return with_shortest(Problem(name, goal.seed, goal.spec, initial, goal.plan or (), goal_scene, task=goal.task,
                                     free=goal.free))
    except ValueError as e:
        raise ValueError(f"{where}: {e}") from None


def goal_file_problem(path: Path, sim=None) -> Problem:
    """A goal file's Problem, named after the file's stem (a simulator is made when none is given)."""
    path = Path(path)
    where = f"goal file {path}"
    goal = load_goal(path)
    check_safe_name(path.stem, where)
    if sim is not None:
        return goal_problem(sim, goal, path.stem, where)
    from symlearn.sim.simulator import TabletopSimulator

    with TabletopSimulator() as own:
        return goal_problem(own, goal, path.stem, where)
