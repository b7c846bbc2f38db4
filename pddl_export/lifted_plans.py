"""A plan of the lifted domain read back as robot actions: each step's schema, the cube held between a pick-cube and
its release, and the (pick * 6 + release, outcome) pair of every robot action.

    >>> plan_actions(rules, ["(pick-cube o1 l0 h2 h0)", "(release-cube-3 o1 l4)"])   # doctest: +SKIP
    [4]
"""
from __future__ import annotations

from typing import Callable, Sequence

from pddl_export.lifted_domain import schemas
from pddl_export.lifted_rules import LiftedRules
from pddl_export.lifted_scene import N_LOCATIONS


def plan_decoder(rules: LiftedRules, costs: bool = False) -> Callable[[Sequence[str]], list[tuple[int, int]]]:
    """Plan steps -> one (robot action id, pick * 6 + release; the outcome of its rule the step stands for, 0 for the
    rule's own) per robot action: a whole move ('(pick-release-stick-l1-l4-30 o2)') is one, a pick-cube and the
    release-cube that puts the cube down ('(pick-cube o1 l0 h2 h0)', '(release-cube-3-alt1 o1 l4)') are one
    together. A cube put back where it was picked is no robot action (the rules say it changes nothing there) and
    is left out. Raises ValueError on a step of no action of the domain, a release of a cube not held, a move
    while a cube is held, or a plan that ends holding one."""
    by_name = {s.name: s for s in schemas(rules, costs)}

    def location(word: str) -> int:
        if len(word) != 2 or word[0] != "l" or not word[1].isdigit() or int(word[1]) >= N_LOCATIONS:
            raise ValueError(f"{word!r} is not a location")
        return int(word[1])

    def decode(steps: Sequence[str]) -> list[tuple[int, int]]:
        out: list[tuple[int, int]] = []
        held: tuple[str, int] | None = None  # the cube in the hand and where it was picked
        for step in steps:
            words = step.strip().strip("()").lower().split()
            if not words or words[0] not in by_name:
                raise ValueError(f"plan step {step!r} names no action of the lifted domain")
            s = by_name[words[0]]
            if len(words) != len(s.params) + 1:
                raise ValueError(f"plan step {step!r} gives {len(words) - 1} arguments, {s.name} takes {len(s.params)}")
            if s.step == "release" and held is None:
                raise ValueError(f"plan step {step!r} releases a cube that is not held")
            if s.step != "release" and held is not None:
                raise ValueError(f"plan step {step!r} comes while {held[0]} is held")
            if s.step == "pick":
                held = (words[1], location(words[2]))
                continue
            if s.step == "release":
                if words[1] != held[0]:
                    raise ValueError(f"plan step {step!r} releases {words[1]}, but {held[0]} is held")
                frm, to = held[1], s.release if s.release is not None else location(words[2])
                held = None
                if frm != to:
                    out.append((frm * N_LOCATIONS + to, s.alternative))
                continue
            if s.pick is not None:
                out.append((s.pick * N_LOCATIONS + s.release, s.alternative))
                continue
            frm = location(words[2])
            to = s.release if s.release is not None else location(words[3])  # a schema refined on ?to fixes it
            out.append((frm * N_LOCATIONS + to, s.alternative))
        if held is not None:
            raise ValueError(f"the plan ends with {held[0]} held")
        return out
    return decode


def plan_actions(rules: LiftedRules, steps: Sequence[str]) -> list[int]:
    """Plan steps ('(pick-cube o1 l0 h2 h0)', '(release-cube-3 o1 l4)', ...) -> robot action ids (pick * 6 +
    release), as plan_decoder reads them."""
    return [a for a, _ in plan_decoder(rules)(steps)]
