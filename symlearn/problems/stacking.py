"""A symbolic model of dropping, picking and releasing: which object stands on which, at which location.

It mirrors the simulator's rules on the arrangements the structure suite scripts: an object dropped
or released at a location lands on the top object there, or on the end of a far-row stick lying
over it, or on the table; a pick takes the top object at a location, and a stick picked at its
middle carries everything standing on it (its end riders shift with it along the far row).
Scripts that leave these rules (a pick at an empty location or at a stick's end, a stick laid over
standing objects, riders carried off the locations, anything put on the end of a stick that does not
lie on the table, which tips it over) are refused with a ValueError. The simulator has the last
word: goal_problems checks every scripted plan there, and tests/test_shortest.py the shortest
plans that symlearn.problems.shortest searches over `successors`.

    >>> from symlearn.world import ObjectType as T
    >>> s = drop_all([(T.STICK, 4), (T.CUBE, 3)])
    >>> s = act(s, [T.STICK, T.CUBE], 4, 1); s = act(s, [T.STICK, T.CUBE], 3, 0)
    >>> s[1]
    ObjectGoal(location=0, on=0, end=True)
"""
from __future__ import annotations

from symlearn.problems.goals import ObjectGoal, stick_covers
from symlearn.world import FAR_ROW, N_LOCATIONS, ObjectType

State = tuple  # tuple[ObjectGoal | None, ...]: every placed object's location and support, in identity order


def _top(state: State, types, loc: int, skip=frozenset()) -> tuple[int, bool] | None:
    """(index, on_end) of what an object dropped at loc lands on: the column's top, a stick end, or None (table)."""
    col = [i for i, g in enumerate(state) if g is not None and g.location == loc and i not in skip]
    tops = [i for i in col if not any(state[j].on == i and not state[j].end for j in col)]
    if len(tops) > 1:
        raise ValueError(f"location {loc} holds two columns ({tops})")
    if tops:
        return tops[0], False
    for i, g in enumerate(state):
        if g is not None and i not in skip and types[i] == ObjectType.STICK and stick_covers(g.location, loc):
            if g.on is not None:  # a stick balanced on a column tips over under an end rider (docs/PROBLEMS.md)
                raise ValueError(f"location {loc} lies under an end of the stick standing on object {g.on}")
            return i, True
    return None


def _land(state: list, types, i: int, loc: int, skip=frozenset()) -> None:
    """Put object i down at loc (on whatever is there); a stick must not lie over standing objects."""
    if types[i] == ObjectType.STICK and loc in FAR_ROW:
        under = [j for j, g in enumerate(state) if g is not None and j not in skip and j != i
                 and stick_covers(loc, g.location)]
        if under:
            raise ValueError(f"the stick released at {loc} would lie over objects {under}")
    below = _top(state, types, loc, skip | {i})
    state[i] = ObjectGoal(loc) if below is None else ObjectGoal(loc, below[0], below[1])


def drop_all(spec) -> State:
    """The state after dropping (type, location) objects one after another (as TabletopSimulator.build)."""
    types = [t for t, _ in spec]
    state: list = [None] * len(spec)
    for i, (_, loc) in enumerate(spec):
        _land(state, types, i, loc)
    return tuple(state)


def carried(state: State, i: int) -> list[int]:
    """Everything standing on object i, directly or not."""
    out, frontier = [], [i]
    while frontier:
        j = frontier.pop()
        above = [k for k, g in enumerate(state) if g is not None and g.on == j]
        out += above
        frontier += above
    return out


def act(state: State, types, pick: int, release: int) -> State:
    """The state after one pick-and-release, or a ValueError where the script leaves the model's rules."""
    held = _top(state, types, pick)
    if held is None or held[1]:
        raise ValueError(f"pick at {pick} takes nothing, or a stick by its end")
    i = held[0]
    riders = carried(state, i)
    new = list(state)
    for r in riders:
        g = state[r]
        loc = release if g.location == state[i].location else g.location + (release - pick)
        if g.location != state[i].location and not (pick in FAR_ROW and release in FAR_ROW
                                                    and stick_covers(release, loc)):
            raise ValueError(f"object {r} riding the stick would leave the locations")
        new[r] = ObjectGoal(loc, g.on, g.end)
    _land(new, types, i, release, skip=frozenset(riders))
    if new[i].on is not None and any(new[r].end and new[r].on == i for r in riders):
        raise ValueError(f"the stick released at {release} onto object {new[i].on} would tip its end riders off")
    return tuple(new)


def run_script(spec, plan) -> State:
    """The state a plan of (pick, release) pairs ends in, from the dropped spec."""
    types = [t for t, _ in spec]
    state = drop_all(spec)
    for p, r in plan:
        state = act(state, types, p, r)
    return state


def touched(spec, plan) -> set[int]:
    """Locations a script uses: every object's location at every step, picks, releases, and a far stick's ends."""
    types = [t for t, _ in spec]
    state, used = drop_all(spec), set()
    for step in range(len(plan) + 1):
        for i, g in enumerate(state):
            used.add(g.location)
            if types[i] == ObjectType.STICK and g.location in FAR_ROW:
                used |= {n for n in FAR_ROW if abs(n - g.location) == 1}
        if step < len(plan):
            used |= set(plan[step])
            state = act(state, types, *plan[step])
    return used


LEVEL_M = 0.05  # heights come in layers of 5 cm: a cube is two layers tall, the stick one
LAYERS = {ObjectType.CUBE: 2, ObjectType.STICK: 1}


def levels(state: State, types) -> tuple[int, ...]:
    """Each object's bottom, in layers (LEVEL_M) above the table: the sum of the heights under it."""
    out: list[int | None] = [None] * len(state)

    def level(i: int) -> int:
        if out[i] is None:
            on = state[i].on
            out[i] = 0 if on is None else level(on) + LAYERS[types[on]]
        return out[i]

    return tuple(level(i) for i in range(len(state)))


def check_state(state: State, types) -> None:
    """Refuse (ValueError) a state the rules above cannot produce or run: two objects on one seat, a support
    that is absent, at another location or not a stick's end, an object on the table under a far-row stick's
    end, a rider on the end of a stick that does not lie on the table, a support cycle."""
    seats: dict[tuple, int] = {}
    for i, g in enumerate(state):
        if g is None:
            raise ValueError(f"object {i} has no place")
        if g.on is not None:
            if not 0 <= g.on < len(state) or g.on == i:
                raise ValueError(f"object {i} stands on object {g.on}, which is absent")
            below = state[g.on]
            if g.end and not (types[g.on] == ObjectType.STICK and stick_covers(below.location, g.location)):
                raise ValueError(f"object {i} at {g.location} is not on an end of object {g.on} at {below.location}")
            if g.end and below.on is not None:
                raise ValueError(f"object {i} rides on an end of the stick standing on object {below.on}")
            if not g.end and below.location != g.location:
                raise ValueError(f"object {i} at {g.location} stands on object {g.on} at {below.location}")
        seat = ("table" if g.on is None else g.on, g.location)
        if seat in seats:
            raise ValueError(f"objects {seats[seat]} and {i} share one seat at location {g.location}")
        seats[seat] = i
    for s, g in enumerate(state):
        if types[s] == ObjectType.STICK:
            under = [i for i, h in enumerate(state) if h.on is None and stick_covers(g.location, h.location)]
            if under:
                raise ValueError(f"objects {under} on the table lie under an end of the stick at {g.location}")
    for i in range(len(state)):  # cycles: a chain of supports longer than the scene
        j, steps = state[i].on, 0
        while j is not None:
            j, steps = state[j].on, steps + 1
            if steps > len(state):
                raise ValueError(f"object {i} is on a support cycle")


def successors(state: State, types):
    """(action id, next state) of every pick-and-release the model covers from `state`, in action-id order.

    A pick at an empty location or a release where it was picked changes nothing and is left out, as is an
    action the rules refuse (a stick picked by its end, riders carried off the locations, ...): a search over
    these steps finds only plans whose every step the model can vouch for.
    """
    occupied = {g.location for g in state} | {n for i, g in enumerate(state) if types[i] == ObjectType.STICK
                                              for n in FAR_ROW if stick_covers(g.location, n)}
    for pick in sorted(occupied):
        for release in range(N_LOCATIONS):
            if release == pick:
                continue
            try:
                yield pick * N_LOCATIONS + release, act(state, types, pick, release)
            except ValueError:
                continue
