"""The structure suite: named planning tasks (towers, cubes on the stick, a carried stick, swaps, Fig. 6).

Each template scripts a core scene (objects dropped at locations) and a reference plan of
(pick, release) pairs; the arrangement the plan ends in is worked out by the symbolic model
(stacking.run_script) and becomes a Goal, which goal_problems builds and checks in the simulator.
Scenes with more objects than the core get extra cubes (or the stick) standing at locations the
script never uses, each kept fixed or left free at random. Locations and roles are drawn from the
rng, so problems vary over seeds.

    >>> goal = structure_goal("tower-2", np.random.default_rng([0, 0]), k=2)
    >>> goal.task, len(goal.spec)
    ('tower-2', 2)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from symlearn.problems.goals import Goal, check_goal
from symlearn.problems.stacking import run_script, touched
from symlearn.world import FAR_ROW, N_LOCATIONS, NEAR_ROW, ObjectType, action_id

C, S = ObjectType.CUBE, ObjectType.STICK
MAX_EXTRA_STACK = 2  # extra cubes stacked at most this high at one spare location
Script = tuple[list[tuple[ObjectType, int]], list[tuple[int, int]]]


def _pick(rng: np.random.Generator, among, n: int) -> list[int]:
    """n distinct locations drawn from `among`."""
    return [int(x) for x in rng.choice(sorted(among), n, replace=False)]


def _others(*used) -> list[int]:
    return [x for x in range(N_LOCATIONS) if x not in used]


def tower_2(rng, k) -> Script:
    """Two cubes stacked: the top one onto the other (1 action) or both to a third location (2)."""
    a, b = _pick(rng, range(N_LOCATIONS), 2)
    if rng.random() < 0.5:
        return [(C, a), (C, b)], [(b, a)]
    t = _pick(rng, _others(a, b), 1)[0]
    return [(C, a), (C, b)], [(a, t), (b, t)]


def tower_3(rng, k) -> Script:
    """Three cubes stacked on the one at a drawn location (2 actions) or at a fourth location (3)."""
    locs = _pick(rng, range(N_LOCATIONS), 3)
    spec = [(C, x) for x in locs]
    if rng.random() < 0.5:
        order = [locs[i] for i in rng.permutation(3)]
        return spec, [(order[1], order[0]), (order[2], order[0])]
    t = _pick(rng, _others(*locs), 1)[0]
    return spec, [(x, t) for x in rng.permutation(locs).tolist()]


def reverse_tower(rng, k) -> Script:
    """A tower of three rebuilt upside down: at another location (3 actions) or in place (6)."""
    a, b, c, d = _pick(rng, range(N_LOCATIONS), 4)
    spec = [(C, a)] * 3
    if rng.random() < 0.5:
        return spec, [(a, b)] * 3
    return spec, [(a, b), (a, c), (a, d), (b, a), (c, a), (d, a)]


def stick_one_rider(rng, k) -> Script:
    """One cube onto the stick: on its middle (1), on an end of a far stick (1), or stick to the far row first (2)."""
    ls, lc = _pick(rng, NEAR_ROW, 2)
    v = int(rng.integers(3 if k <= 4 else 2))  # the far-row move leaves room for two extras only
    if v == 0:
        return [(S, ls), (C, lc)], [(lc, ls)]
    if v == 1:
        return [(S, 1), (C, lc)], [(lc, int(rng.choice([0, 2])))]
    s = int(rng.choice(FAR_ROW))
    return [(S, ls), (C, lc)], [(ls, s), (lc, 1 if s != 1 else int(rng.choice([0, 2])))]


def stick_two_riders(rng, k) -> Script:
    """Cubes on both ends of the stick at the far middle (Table I case 3), or stacked on one end."""
    ls, la, lb = _pick(rng, NEAR_ROW, 3)
    ends = [0, 2] if rng.random() < 0.5 else [2, 0]
    if rng.random() < 0.3:
        e = ends[0]
        return [(S, 1), (C, la), (C, lb)], [(la, e), (lb, e)]
    if k > 3 or rng.random() < 0.5:
        return [(S, 1), (C, la), (C, lb)], [(la, ends[0]), (lb, ends[1])]
    return [(S, ls), (C, la), (C, lb)], [(ls, 1), (la, ends[0]), (lb, ends[1])]


def carry_loaded_stick(rng, k) -> Script:
    """A stick carrying cubes one location along the far row (Table I case 2); loaded first when it starts bare."""
    e = int(rng.choice([0, 2]))
    to = 2 - e  # riders on end e come to rest over the middle location
    v = int(rng.integers(4))
    if v == 0:
        return [(S, 1), (C, e)], [(1, to)]
    if v == 1 and k >= 3:
        return [(S, 1), (C, e), (C, 1)], [(1, to)]  # a rider on each: the middle one ends over `to`
    if v == 2 and k >= 3:
        return [(S, 1), (C, e), (C, e)], [(1, to)]  # a tower of two on the end
    ls, lc = _pick(rng, NEAR_ROW, 2)
    if k > 4 or rng.random() < 0.5:  # a stick starting in the near row leaves room for two extras only
        return [(S, 1), (C, lc)], [(lc, e), (1, to)]
    return [(S, ls), (C, lc)], [(ls, 1), (lc, e), (1, to)]


def near_to_far(rng, k) -> Script:
    """Every object from the near row to the far row, each to a drawn far location (k actions)."""
    spec = [(C, int(x)) for x in rng.permutation(NEAR_ROW)] + [(C, int(rng.choice(NEAR_ROW))) for _ in range(k - 3)]
    spec = spec[:k]
    stacks = {x: [i for i, (_, l) in enumerate(spec) if l == x] for x in NEAR_ROW}
    height = {x: 0 for x in FAR_ROW}
    plan = []
    while any(stacks.values()):
        src = int(rng.choice([x for x in NEAR_ROW if stacks[x]]))
        stacks[src].pop()
        dst = int(rng.choice([x for x in FAR_ROW if height[x] < 2]))
        height[dst] += 1
        plan.append((src, dst))
    return spec, plan


def swap(rng, k) -> Script:
    """Two cubes exchange places through a free location (3 actions)."""
    a, b, c = _pick(rng, range(N_LOCATIONS), 3)
    return [(C, a), (C, b)], [(a, c), (b, a), (c, b)]


def rotate(rng, k) -> Script:
    """Three or four cubes each move one place along a cycle of locations, through a free one (4 or 5 actions)."""
    n = 3 if k == 3 else int(rng.choice([3, 4]))
    locs = _pick(rng, range(N_LOCATIONS), n + 1)
    ring, spare = locs[:n], locs[n]
    plan = [(ring[-1], spare)] + [(ring[i - 1], ring[i]) for i in range(n - 1, 0, -1)] + [(spare, ring[0])]
    return [(C, x) for x in ring], plan


def swap_towers(rng, k) -> Script:
    """Two towers of two exchange places: through one free location with one tower ending upside down (6 actions),
    or through two with both kept the right way up (7)."""
    a, b, c, d = _pick(rng, range(N_LOCATIONS), 4)
    spec = [(C, a), (C, a), (C, b), (C, b)]
    if rng.random() < 0.5:
        return spec, [(a, c), (a, c), (b, a), (b, a), (c, b), (c, b)]
    return spec, [(a, c), (a, d), (b, c), (b, a), (c, a), (d, b), (c, b)]


def fig6_composite(rng, k) -> Script:
    """A loaded stick at the far middle beside a tower of two in the near row (the paper's Fig. 6), from the near row."""
    ls, la, lb = _pick(rng, NEAR_ROW, 3)
    e = int(rng.choice([0, 2]))
    if k == 4:
        spec = [(S, ls), (C, la), (C, la), (C, lb)]
        if rng.random() < 0.5:
            return spec, [(ls, 1), (la, e), (lb, la)]
        return spec, [(ls, 1), (la, e), (la, ls), (lb, ls)]
    spec = [(S, ls), (C, la), (C, la), (C, lb), (C, lb)]
    if rng.random() < 0.5:
        return spec, [(ls, 1), (la, e), (lb, 2 - e), (la, lb)]
    return spec, [(ls, 1), (la, e), (lb, 2 - e), (la, ls), (lb, ls)]


@dataclass(frozen=True)
class Template:
    """A named task: its script and the object counts it is drawn for."""

    name: str
    script: Callable[[np.random.Generator, int], Script]
    objects: tuple[int, int]


TEMPLATES: tuple[Template, ...] = (
    Template("tower-2", tower_2, (2, 5)),
    Template("tower-3", tower_3, (3, 5)),
    Template("reverse-tower", reverse_tower, (3, 5)),
    Template("stick-one-rider", stick_one_rider, (2, 5)),
    Template("stick-two-riders", stick_two_riders, (3, 5)),
    Template("carry-loaded-stick", carry_loaded_stick, (2, 5)),
    Template("near-to-far", near_to_far, (1, 5)),
    Template("swap", swap, (2, 5)),
    Template("rotate", rotate, (3, 5)),
    Template("swap-towers", swap_towers, (4, 5)),
    Template("fig6-composite", fig6_composite, (4, 5)),
)
TEMPLATE_BY_NAME = {t.name: t for t in TEMPLATES}


def _extras(rng, spec, plan, n: int) -> tuple[list, list[bool]]:
    """n extra objects at locations the script never uses (cubes stacked at most MAX_EXTRA_STACK high; the stick,
    when the core has none and a near location is spare, alone), and which of them are free."""
    spots = [int(x) for x in rng.permutation([x for x in range(N_LOCATIONS) if x not in touched(spec, plan)])]
    free = sorted(bool(rng.random() < 0.5) for _ in range(n))  # fixed ones first: a free one never holds one up
    extra = []
    near = [x for x in spots if x in NEAR_ROW]
    if n and S not in [t for t, _ in spec] and near and len(spots) > 1 and rng.random() < 0.5:
        extra.append((S, near[0]))
        spots.remove(near[0])
    if n - len(extra) > len(spots) * MAX_EXTRA_STACK:
        raise ValueError(f"no room for {n} extra objects beside the script")
    extra += [(C, spots[i % len(spots)]) for i in range(n - len(extra))]
    return extra, free


def structure_goal(task: str, rng: np.random.Generator, k: int, seed: int = 0) -> Goal:
    """One drawn Goal of a template: its script, extras up to k objects, the arrangement the plan ends in."""
    t = TEMPLATE_BY_NAME.get(task)
    if t is None:
        raise ValueError(f"unknown structure task {task!r}; known: {', '.join(TEMPLATE_BY_NAME)}")
    if not t.objects[0] <= k <= t.objects[1]:
        raise ValueError(f"task {task} takes {t.objects[0]}-{t.objects[1]} objects, not {k}")
    spec, plan = t.script(rng, k)
    extra, free = _extras(rng, spec, plan, k - len(spec))
    spec = spec + extra
    state = run_script(spec, plan)
    n_core = k - len(extra)
    targets = tuple(g if i < n_core or not free[i - n_core] else None for i, g in enumerate(state))
    goal = Goal(tuple(spec), targets, tuple(action_id(p, r) for p, r in plan), task, seed)
    check_goal(goal, f"task {task}")
    return goal
