"""Operators found from data over learned predicates, written as a lifted PDDL domain (pure: no torch).

A symbolic state is a set of ground atoms over objects `o1..ok` and the six locations `l0..l5`:
`("at", o, l)` (the learned object-location relation), `("rK", a, b)` (learned object-object relation K) and
`("uB", o)` (bit B of o's learned unary code). An observed transition is a pre-state, a post-state and the
action's pick and release locations.

Operators are found as the authors' follow-up does (arXiv 2401.01123): transitions are grouped by their
lifted effect, and each group's precondition is what every member's pre-state holds.

- Lifting: the pick location becomes ?from, the release location ?to (one ?at when they are equal), every
  object named by an added or deleted atom a variable ?o1, ?o2, ... numbered in the order that gives the
  smallest written effect, so two transitions that differ only in the names of their objects share a group.
  Any other location stays a constant of the domain: a rider on a stick's end moves from one named location
  to another, and which ones is what the data showed for these two arguments.
- The precondition of a group is the set of lifted atoms over its variables true in every member's
  pre-state (or in a share of them: learned symbols are noisy); atoms naming an object outside the effect are left out (STRIPS has no quantifiers), so the
  precondition says what must hold of the objects that change and of the two locations.
- A group seen fewer than `min_count` times is dropped as noise of the learned symbols.

Why grouping by effect: an operator of STRIPS has one add and one delete list, so transitions with
different effects cannot share one; grouping by the precondition instead would merge different outcomes.
"""
from __future__ import annotations

import dataclasses
import itertools
from collections import Counter, defaultdict
from dataclasses import dataclass
from typing import Iterable, Sequence

Atom = tuple[str, ...]


@dataclass(frozen=True)
class Transition:
    """One observed action: ground atoms before and after, the pick and release location names."""

    pre: frozenset[Atom]
    post: frozenset[Atom]
    pick: str
    release: str


@dataclass(frozen=True)
class Operator:
    """A lifted STRIPS operator: typed parameters, precondition, add and delete lists, and its support."""

    name: str
    parameters: tuple[tuple[str, str], ...]  # (variable, type)
    precondition: tuple[Atom, ...]
    add: tuple[Atom, ...]
    delete: tuple[Atom, ...]
    count: int  # transitions in its group


def _lift(atom: Atom, names: dict[str, str]) -> Atom | None:
    """The atom with its entities renamed (a location outside `names` stays a constant), or None if it names an
    object outside `names`."""
    args = tuple(names.get(a, a if a.startswith("l") else None) for a in atom[1:])
    return None if None in args else (atom[0], *args)


STATIC_PREFIX = "u"  # unary bits: what an object looks like; read in preconditions, never changed by an operator


def changes(t: Transition) -> tuple[frozenset[Atom], frozenset[Atom]]:
    """The atoms a transition adds and deletes, unary bits left out: the shape code of an object seen from
    another place flips bits with the perspective, which is no effect of the action."""
    add = frozenset(a for a in t.post - t.pre if not a[0].startswith(STATIC_PREFIX))
    delete = frozenset(a for a in t.pre - t.post if not a[0].startswith(STATIC_PREFIX))
    return add, delete


def location_binding(t: Transition) -> dict[str, str]:
    """The action's location variables and their locations: ?at when it releases where it picked, else ?from and
    ?to."""
    return {"?at": t.pick} if t.pick == t.release else {"?from": t.pick, "?to": t.release}


def names_a_place(atoms: Iterable[Atom]) -> bool:
    """Whether lifted atoms name a location constant (a location outside the action's two arguments)."""
    return any(not x.startswith("?") and x.startswith("l") for a in atoms for x in a[1:])


def lift(t: Transition, placed: bool = False) -> tuple[tuple, dict[str, str]]:
    """A transition's lifted effect key ((location variables), add, delete, where) and the names it gave. With
    `placed`, an effect that names a location outside the action's two arguments is keyed by where the action
    was too (`where`: ((variable, location), ...); () otherwise): such an effect depends on the place (a stick
    released at l1 covers l0 and l2 as well, one released at l4 does not), so its operator is for that place. A
    location it adds pins the release location (`?to`), one it deletes the pick location (`?from`)."""
    add, delete = changes(t)
    binding = location_binding(t)
    locs = {loc: var for var, loc in binding.items()}
    objs = sorted({a for atom in add | delete for a in atom[1:] if a not in locs and not a.startswith("l")})
    best = None
    for perm in itertools.permutations(objs) if len(objs) <= 4 else [tuple(objs)]:
        names = dict(locs) | {o: f"?o{i + 1}" for i, o in enumerate(perm)}
        key = (tuple(sorted(locs.values())), tuple(sorted(_lift(a, names) for a in add)),
               tuple(sorted(_lift(a, names) for a in delete)))
        if best is None or key < best[0]:
            best = (key, names)
    key, names = best
    where = ()
    if placed:  # a place it adds depends on where it let go, a place it deletes on where it picked
        add, delete = key[1], key[2]  # (empty l) is "nothing at l": its deletion is an arrival, its addition a leaving
        arrives = [a for a in add if a[0] != "empty"] + [a for a in delete if a[0] == "empty"]
        leaves = [a for a in delete if a[0] != "empty"] + [a for a in add if a[0] == "empty"]
        pinned = {"?to", "?at"} if names_a_place(arrives) else set()
        pinned |= {"?from", "?at"} if names_a_place(leaves) else set()
        where = tuple(sorted((v, loc) for v, loc in binding.items() if v in pinned))
    return (*key, where), names


def learn_operators(transitions: Iterable[Transition], min_count: int = 3, share: float = 1.0,
                    max_objects: int = 4, placed: bool = False, multi_min_count: int = 0) -> list[Operator]:
    """Operators over the transitions' atoms, most supported first (see the module docstring). A precondition
    atom must hold in at least `share` of its group's pre-states (1: in all); an effect naming more than
    `max_objects` objects is dropped (it grounds into too many actions to be worth its rare use). With `placed`,
    an effect naming another location is grouped per place of the action (lift), and its operator binds its
    location variables there: `(= ?to l1)` in its precondition. A group whose effect moves three or more items (a
    stick and two riders) needs `multi_min_count` transitions where that is set and below min_count: such scenes are
    rare, and each group of them splits further by what the riders read. The groups are named in order of size,
    so a rarer group never renames a common one."""
    groups: dict[tuple, list[frozenset[Atom]]] = defaultdict(list)
    for t in transitions:
        if not any(changes(t)):
            continue  # nothing changed: no operator needed (the planner never needs a no-op)
        key, names = lift(t, placed)
        groups[key].append(frozenset(x for x in (_lift(a, names) for a in t.pre) if x is not None))
    ops = []
    for key, pres in sorted(groups.items(), key=lambda kv: -len(kv[1])):
        loc_vars, add, delete, where = key
        moved = {a[1] for a in add if a[0] == "at"} & {a[1] for a in delete if a[0] == "at"}
        need = min(min_count, multi_min_count) if multi_min_count and len(moved) >= 3 else min_count
        if len(pres) < need:
            continue
        if len({v for a in add + delete for v in a[1:] if v.startswith("?o")}) > max_objects:
            continue
        counts = Counter(a for p in pres for a in p)
        pre = frozenset(a for a, c in counts.items() if c >= share * len(pres)) | {("=", v, loc) for v, loc in where}
        variables = sorted({v for a in (*add, *delete, *pre) for v in a[1:] if v.startswith("?")} | set(loc_vars))
        params = tuple((v, "location" if v in ("?at", "?from", "?to") else "item") for v in variables)
        ops.append(Operator(f"move-{len(ops)}", params, tuple(sorted(pre)), add, delete, len(pres)))
    return ops


def bindings(op: Operator, state: frozenset[Atom], fixed: dict[str, str]) -> Iterable[dict[str, str]]:
    """Every binding of an operator's variables to the entities of `state` under which its precondition holds,
    extending `fixed` (the location variables); different variables take different entities, as a planner's
    grounding would be asked to."""
    by_pred: dict[str, list[Atom]] = defaultdict(list)
    for a in state:
        by_pred[a[0]].append(a)
    fixed = dict(fixed)
    for _, var, loc in (a for a in op.precondition if a[0] == "="):  # a placed operator: its variable is that place
        if fixed.setdefault(var, loc) != loc:
            return
    pre = sorted((a for a in op.precondition if a[0] != "="), key=lambda a: len(by_pred.get(a[0], ())))

    def extend(i: int, b: dict[str, str]):
        if i == len(pre):
            yield b
            return
        atom = pre[i]
        for cand in by_pred.get(atom[0], ()):
            nb, ok = dict(b), True
            for var, val in zip(atom[1:], cand[1:]):
                if not var.startswith("?"):
                    ok = var == val
                elif var in nb:
                    ok = nb[var] == val
                elif val in nb.values():
                    ok = False
                else:
                    nb[var] = val
                if not ok:
                    break
            if ok:
                yield from extend(i + 1, nb)

    yield from extend(0, dict(fixed))


def ground(atoms: Iterable[Atom], binding: dict[str, str]) -> set[Atom]:
    """Lifted atoms with each variable replaced by what `binding` gives it (constants, and variables it does not
    name, stay as they are)."""
    return {tuple([a[0], *(binding.get(x, x) for x in a[1:])]) for a in atoms}


def successor(op: Operator, args: Sequence[str], state: frozenset[Atom]) -> frozenset[Atom] | None:
    """The state a plan step `(op args...)` leads to from `state` in the learned domain (STRIPS: the delete list
    removed, the add list added), or None where its precondition does not hold there: what the domain predicts the
    step does, for a closed loop that checks the scene it observes next against it."""
    if len(args) != len(op.parameters):
        raise ValueError(f"{op.name} takes {len(op.parameters)} arguments, got {len(args)}: {list(args)}")
    b = {v: a for (v, _), a in zip(op.parameters, args)}
    pre = ground(op.precondition, b)
    if any(a[0] == "=" and a[1] != a[2] for a in pre) or not {a for a in pre if a[0] != "="} <= state:
        return None
    return frozenset((state - ground(op.delete, b)) | ground(op.add, b))


def step_successor(ops: dict[str, Operator], step: str, state: frozenset[Atom]) -> frozenset[Atom] | None:
    """successor() of a plan step as a planner writes it, "(move-3 l0 o1 l2)", its operator looked up by name in ops;
    None where ops has no such operator or its precondition does not hold in state."""
    name, *args = step.strip("() ").split()
    return successor(ops[name], args, state) if name in ops else None


def precision(ops: Sequence[Operator], transitions: Sequence[Transition]) -> list[tuple[int, int]]:
    """For each operator, (groundings that apply in a transition's pre-state at the action's two locations, those
    that predict the observed change exactly). A planner may pick any applicable grounding, so each counts: an
    operator whose precondition is too weak (noise removed an atom, or `clear ?o2` is missing so ?o2 may be a
    block under the top) applies in many states or ways where the robot saw something else happen."""
    out = []
    for op in ops:
        loc_vars = {v for v, t in op.parameters if t == "location"}
        applies = hits = 0
        for t in transitions:
            fixed = location_binding(t)
            if set(fixed) != loc_vars:
                continue
            add, delete = changes(t)
            for b in bindings(op, t.pre, fixed):
                applies += 1
                hits += ground(op.add, b) == add and ground(op.delete, b) == delete
        out.append((applies, hits))
    return out


def generalize(op: Operator, transitions: Sequence[Transition], slack: float = 0.05,
               keep_deleted: bool = False) -> Operator:
    """The operator with every precondition atom dropped that the data do not need: an atom goes when, without
    it, the operator still predicts the observed change as often (its precision falls by at most `slack`).

    A group's shared atoms include correlates of its members (most stacks are built on a cube that stands on
    the table, so `on-table ?o2` holds in nearly every member of "put ?o1 on ?o2"); a precondition kept for no
    reason forbids plans the robot can carry out, such as a third cube on a tower. Atoms are tried in a fixed
    order, and the relations of the objects the effect moves (`at ?o ?from`) are never dropped.

    With `keep_deleted`, no atom the operator deletes is dropped: the data rarely show "put a stick on ?o2" where
    something already rests on ?o2, so its precision does not miss `(clear ?o2)`, yet without it a planner puts the
    stick on a covered cube, deletes `(clear ?o2)` that was false, and the robot undoes what the plan expected."""
    def prec(o: Operator) -> float:
        a, h = precision([o], transitions)[0]
        return h / a if a else 0.0

    base = prec(op)
    for atom in sorted(op.precondition, key=lambda a: (a[0].startswith(STATIC_PREFIX) is False, a)):
        if (atom in op.delete and (keep_deleted or atom[0] == "at")) or atom[0] == "=":
            continue
        trial = dataclasses.replace(op, precondition=tuple(a for a in op.precondition if a != atom))
        if prec(trial) >= base - slack:
            op = trial
    return op


def coverage(ops: Sequence[Operator], transitions: Iterable[Transition]) -> dict:
    """How many changing transitions fall in a kept operator's group, and of those, how many satisfy its
    precondition (the precondition is an intersection, so all do on the data it was learned from)."""
    keys = Counter()
    kept = {(tuple(sorted({v for v, t in o.parameters if t == "location"})), o.add, o.delete,
             tuple(sorted((a[1], a[2]) for a in o.precondition if a[0] == "="))) for o in ops}
    placed = any(k[3] for k in kept)
    for t in transitions:
        if not any(changes(t)):
            keys["unchanged"] += 1
            continue
        keys["changed"] += 1
        keys["covered"] += lift(t, placed)[0] in kept
    return dict(keys)


def predicates_of(ops: Sequence[Operator], extra: Iterable[Atom] = ()) -> dict[str, tuple[str, ...]]:
    """Each predicate's argument types, from the atoms the operators and `extra` name."""
    out: dict[str, tuple[str, ...]] = {"at": ("item", "location")}
    for a in itertools.chain((a for o in ops for a in (*o.precondition, *o.add, *o.delete)), extra):
        if a[0] in ("at", "="):
            continue
        out.setdefault(a[0], ("location",) if a[0] == "empty" else ("item",) * (len(a) - 1))
    return dict(sorted(out.items()))


def carried(op: Operator) -> list[str]:
    """The items one action of the operator moves (it adds an `at` of each and deletes one): two or more is
    carrying, what rests on the held item riding along. An item that only gains a cell (a stick whose end a lifted
    cube no longer hides) did not move."""
    gains, loses = ({a[1] for a in atoms if a[0] == "at"} for atoms in (op.add, op.delete))
    return sorted(gains & loses)


def _atom(a: Atom) -> str:
    return "(" + " ".join(a) + ")"


def distinct(op: Operator, equality: bool = True) -> list[str]:
    """`(not (= ?a ?b))` for every pair of variables of one type: lifting gave different objects (and the pick and
    release location, when they differ) different variables, so an operator was only ever seen with them apart.
    Without it a planner may bind two to one object (move ?o1 onto itself) and reach a goal no robot can. Without
    `equality`, `(differ ?a ?b)`, a static predicate the problem states of every two different objects
    (problem_pddl): pyperplan's parser takes no `=`."""
    out = []
    for (a, ta), (b, tb) in itertools.combinations(op.parameters, 2):
        if ta == tb:
            out.append(f"(not (= {a} {b}))" if equality else f"(differ {a} {b})")
    return out


def _precondition(op: Operator, equality: bool) -> list[str]:
    """The operator's precondition atoms as PDDL, and distinct's; without `equality`, a placed operator's
    `(= ?to l1)` written `(same ?to l1)` (problem_pddl states `(same l l)` of each location)."""
    same = lambda a: ("same", *a[1:]) if a[0] == "=" and not equality else a  # noqa: E731
    return [*(_atom(same(a)) for a in op.precondition), *distinct(op, equality)]


def domain_pddl(ops: Sequence[Operator], name: str = "learned-relations", comments: dict[str, str] | None = None,
                n_locations: int = 6, equality: bool = True) -> str:
    """The operators as a typed STRIPS domain with equality (distinct); `comments` say what each predicate was found
    to mean. Without `equality`, the same domain in plain typed STRIPS, for planners whose parser takes no `=`
    (stock pyperplan): `(differ ?a ?b)` and `(same ?to l1)` in place of `(not (= ?a ?b))` and `(= ?to l1)`, both
    static, stated in each problem (problem_pddl with equality=False)."""
    comments = comments or {}
    predicates = predicates_of(ops)
    taken = set() if equality else {"differ", "same"} & set(predicates)
    if taken:
        raise ValueError(f"the operators already name a predicate {sorted(taken)[0]!r}: no plain STRIPS form")
    locs = " ".join(f"l{i}" for i in range(n_locations))
    lines = [f"(define (domain {name})", f"  (:requirements :strips :typing{' :equality' if equality else ''})",
             "  (:types item location)", f"  (:constants {locs} - location)", "  (:predicates"]
    for p, types in predicates.items():
        args = " ".join(f"?x{i} - {t}" for i, t in enumerate(types))
        note = f"  ; {comments[p]}" if p in comments else ""
        lines.append(f"    ({p} {args}){note}")
    if not equality:
        lines += ["    (differ ?x0 ?x1)  ; static: two different objects or locations",
                  "    (same ?x0 - location ?x1 - location)  ; static: a location and itself"]
    lines.append("  )")
    for o in ops:
        params = " ".join(f"{v} - {t}" for v, t in o.parameters)
        moved = carried(o)
        what = f"; carries {' and '.join(moved)} together" if len(moved) > 1 else ""
        lines += [f"  (:action {o.name}  ; seen {o.count} times{what}", f"    :parameters ({params})",
                  f"    :precondition (and {' '.join(_precondition(o, equality))})",
                  f"    :effect (and {' '.join(map(_atom, o.add))} "
                  f"{' '.join('(not ' + _atom(a) + ')' for a in o.delete)}))"]
    lines.append(")")
    return "\n".join(lines) + "\n"


def problem_pddl(name: str, objects: Sequence[str], init: Iterable[Atom], goal: Iterable[Atom],
                 predicates: Iterable[str], domain: str = "learned-relations", equality: bool = True,
                 n_locations: int = 6) -> str:
    """A problem over the learned predicates: objects, the observed atoms and a goal (the six locations are the
    domain's constants l0..l5). Atoms of a predicate the domain does not declare (a bit no operator reads or
    changes) are left out of the initial state: they can neither help nor hinder a plan. Without `equality` (the
    domain written so), also the static `(differ a b)` of every two objects and every two locations, and `(same l
    l)` of each location."""
    known = set(predicates)
    init = [a for a in init if a[0] in known]
    if not equality:
        locs = [f"l{i}" for i in range(n_locations)]
        init += [("differ", a, b) for group in (list(objects), locs) for a, b in itertools.permutations(group, 2)]
        init += [("same", x, x) for x in locs]
    return (f"(define (problem {name}) (:domain {domain})\n  (:objects {' '.join(objects)} - item)\n"
            f"  (:init {' '.join(map(_atom, sorted(init)))})\n  (:goal (and {' '.join(map(_atom, sorted(goal)))})))\n")


def operators_to_json(ops: Sequence[Operator]) -> list[dict]:
    """The operators as plain JSON."""
    return [{"name": o.name, "parameters": [list(p) for p in o.parameters], "precondition": [list(a) for a in o.precondition],
             "add": [list(a) for a in o.add], "delete": [list(a) for a in o.delete], "count": o.count} for o in ops]


def operators_from_json(rows: list[dict], where: str = "operators") -> list[Operator]:
    """Operators back from operators_to_json's form; a malformed entry is refused naming `where`."""
    try:
        return [Operator(str(r["name"]), tuple((str(v), str(t)) for v, t in r["parameters"]),
                         tuple(tuple(map(str, a)) for a in r["precondition"]), tuple(tuple(map(str, a)) for a in r["add"]),
                         tuple(tuple(map(str, a)) for a in r["delete"]), int(r["count"])) for r in rows]
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{where}: not a list of learned operators ({e})") from None
