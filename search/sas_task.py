"""Fast Downward's translated task (its SAS+ file) with a new initial state and goal, so that one translation serves
every later call over the same objects.

Grounding is most of a call at 9-10 objects (the translator takes 3-6 s of a 10 s call; search often well under
1 s), and a closed loop plans again and again over the same objects, only the state and the goal changing. The
translator's output stays valid for another initial state s' and goal g' where (Helmert 2009, sections 5-6):

- every atom true in s' is a value of some variable, at most one value of a variable and of a mutex group holds,
  and a variable with no value true has a value for "none of these";
- every atom that is no value of any variable (static, or pruned as unreachable, or constant after simplification)
  holds in s' exactly where it held in the initial state translated: then every atom true in s' was reachable in the
  relaxed task from that initial state, so whatever the relaxed task reaches from s', including the operators that
  apply, is in the translation too;
- every atom of g' is a value (the translator was told to keep every variable, `--keep-unimportant-variables`, so
  that a variable the first goal did not need is not gone).

Where one fails, `Translation.task_for` says None and the caller translates again. The operators, mutex groups and
variables are the translator's, untouched; the plan's steps name the ground operators as from a fresh translation.
Axioms (derived variables) are not handled: a task with them is never reused.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

NONE_OF_THOSE = "<none of those>"
# the translator options a reusable translation needs (see the module docstring)
KEEP_OPTIONS = ("--keep-unimportant-variables",)


@dataclass(frozen=True)
class SasTask:
    """The parts of a SAS+ file a new initial state and goal need; the rest is kept as text."""

    head: str  # everything before begin_state: version, metric, variables, mutex groups
    values: tuple[tuple[str, ...], ...]  # each variable's values as the file names them ("Atom on(a, b)", ...)
    mutexes: tuple[tuple[tuple[int, int], ...], ...]  # each mutex group's (variable, value) facts
    tail: str  # everything after end_goal: operators, axioms
    init: tuple[int, ...]  # the initial state's value of each variable


def atom_name(atom: Sequence[str]) -> str:
    """A ground atom (predicate, arg, ...) as Fast Downward's translator names it: "on(a, b)", "handempty()"."""
    return f"{atom[0]}({', '.join(atom[1:])})"


def _section(lines: list[str], start: int, name: str) -> tuple[list[str], int]:
    """The lines between begin_NAME at lines[start] and end_NAME, and the index after end_NAME."""
    if lines[start] != f"begin_{name}":
        raise ValueError(f"expected begin_{name} at line {start + 1}, found {lines[start]!r}")
    end = lines.index(f"end_{name}", start)
    return lines[start + 1:end], end + 1


def parse_sas(text: str) -> SasTask:
    """The SasTask of a SAS+ file's text (Fast Downward's translator output, version 3). ValueError where the text is
    not one, or where it has derived variables (axioms), which a new initial state cannot be checked against."""
    cut = text.find("\nbegin_state\n")
    end = text.find("\nend_goal\n")
    if cut < 0 or end < cut:
        raise ValueError("not a SAS+ task: no begin_state ... end_goal")
    head_lines = text[:cut].split("\n")
    values: list[tuple[str, ...]] = []
    mutexes: list[tuple[tuple[int, int], ...]] = []
    derived: list[str] = []
    i = 0
    try:
        while i < len(head_lines):
            line = head_lines[i]
            if line == "begin_variable":
                body, i = _section(head_lines, i, "variable")
                if int(body[1]) != -1:
                    derived.append(f"{body[0]} (axiom layer {body[1]})")
                n = int(body[2])
                if len(body) != 3 + n:
                    raise ValueError(f"variable {body[0]} lists {len(body) - 3} values, says {n}")
                values.append(tuple(body[3:]))
            elif line == "begin_mutex_group":
                body, i = _section(head_lines, i, "mutex_group")
                mutexes.append(tuple((int(v), int(x)) for v, x in (ln.split() for ln in body[1:])))
            else:
                i += 1
        state, _ = _section(text[cut + 1:end].split("\n"), 0, "state")
        init = tuple(int(x) for x in state)
    except (IndexError, ValueError) as e:
        raise ValueError(f"not a SAS+ task this reader knows: {e}") from None
    if derived:
        raise ValueError(f"variable {derived[0]} is derived: not reusable")
    if len(init) != len(values) or any(not 0 <= x < len(v) for x, v in zip(init, values)):
        raise ValueError("the initial state does not match the variables")
    return SasTask(text[:cut + 1], tuple(values), tuple(mutexes), text[end + len("\nend_goal\n"):], init)


@dataclass(frozen=True)
class Translation:
    """One translation of a task, and the initial state it was translated from (atom names)."""

    task: SasTask
    translated_from: frozenset[str]

    @classmethod
    def of(cls, sas_text: str, init: Iterable[Sequence[str]]) -> "Translation":
        """The translator's output for a problem whose initial state is `init` (ground atoms)."""
        return cls(parse_sas(sas_text), frozenset(atom_name(a) for a in init))

    def task_for(self, init: Iterable[Sequence[str]], goal: Iterable[Sequence[str]]) -> str | None:
        """The SAS+ text of this translation from `init` to `goal` (ground atoms, the goal a conjunction of them), or
        None where the translation cannot stand for that task (the module docstring says when)."""
        values = self.task.values
        where = {name[5:]: (v, x) for v, names in enumerate(values) for x, name in enumerate(names)
                 if name.startswith("Atom ")}
        true = {atom_name(a) for a in init}
        if {a for a in true if a not in where} != {a for a in self.translated_from if a not in where}:
            return None
        state: list[int | None] = [None] * len(values)
        for a in true & where.keys():
            v, x = where[a]
            if state[v] is not None:
                return None  # two values of one variable
            state[v] = x
        for v, names in enumerate(values):
            if state[v] is None:
                other = [x for x, name in enumerate(names) if name == NONE_OF_THOSE or name.startswith("NegatedAtom ")]
                if len(other) != 1:
                    return None  # no value says "none of these"
                state[v] = other[0]
        if any(sum(state[v] == x for v, x in group) > 1 for group in self.task.mutexes):
            return None
        goal_facts = set()
        for a in goal:
            name = atom_name(a)
            if name not in where:
                return None
            goal_facts.add(where[name])
        if len({v for v, _ in goal_facts}) != len(goal_facts):
            return None  # two values of one variable asked: no state holds both
        lines = ["begin_state", *map(str, state), "end_state", "begin_goal", str(len(goal_facts)),
                 *(f"{v} {x}" for v, x in sorted(goal_facts)), "end_goal"]
        return self.task.head + "\n".join(lines) + "\n" + self.task.tail


__all__ = ["KEEP_OPTIONS", "SasTask", "Translation", "atom_name", "parse_sas"]
