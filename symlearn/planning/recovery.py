"""Closed-loop recovery after a departure: keep the plan, fall back to another plan's suffix, or replan.

The policy (symlearn.planning.execution runs it): roll the rest of the current plan from the
observed codes through the corrected models; if one of them says it still reaches the goal codes,
keep it. Else
take the first plan among the current one and the planner's alternatives (top-k) that passes
through the observed codes and whose suffix from there reaches the goal when rolled the same
way. Else the caller replans. The models are the planner's own (the network, or a rule planner's
rules) and the network, each answering from memory where execution has seen a step.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from pddl_export.symbolic import SymbolicGoal, TransitionFn
from search.result import PlanResult


def roll(model: TransitionFn, start: tuple[int, ...], actions: list[int]) -> list[tuple[int, ...]]:
    """start and the state after each action, as `model` predicts them."""
    states = [tuple(int(c) for c in start)]
    for a in actions:
        nxt = model(np.asarray([states[-1]], np.int64), np.asarray([a], np.int64))[0]
        states.append(tuple(int(c) for c in nxt))
    return states


@dataclass
class Segment:
    """The plan being executed: its actions, predicted states (start first), next index, and top-k alternatives."""

    actions: list[int]
    predicted: list[tuple[int, ...]]
    alternatives: list[tuple[tuple[int, ...], tuple[tuple[int, ...], ...]]]
    t: int = 0

    @staticmethod
    def of(plan: PlanResult) -> "Segment":
        return Segment(list(plan.plan), [tuple(s) for s in plan.predicted_states], list(plan.alternatives))


@dataclass
class Progress:
    """What execution has done so far (mutable while it runs)."""

    observed: list[tuple[int, ...]]
    executed: list[int] = field(default_factory=list)
    replans: int = 0
    continued: int = 0
    fallbacks: int = 0
    diverged: bool = False
    segment_ok: bool = True
    replan_failed: bool = False
    off_table: bool = False
    first_departure: int | None = None
    departed: tuple[int, ...] = ()


def _reaching(models: Sequence[TransitionFn], codes: tuple[int, ...], actions: list[int],
              goal: SymbolicGoal) -> list[tuple[int, ...]] | None:
    """The states of the first model whose roll of `actions` from `codes` ends at the goal codes, else None."""
    for model in models:
        rolled = roll(model, codes, actions)
        if goal.satisfied(np.asarray(rolled[-1], np.int64))[0]:
            return rolled
    return None


def recover(seg: Segment, codes: tuple[int, ...], models: Sequence[TransitionFn], goal: SymbolicGoal,
            prog: Progress, max_fallbacks: int) -> Segment | None:
    """After a departure: the segment to go on with (continued or a fallback suffix), or None to replan.

    A plan is kept (or a suffix taken) when ANY of `models` predicts it reaches the goal: keeping the
    plan is what open loop does, so abandoning it asks for every model's evidence that it fails.
    """
    rolled = _reaching(models, codes, seg.actions[seg.t + 1:], goal)
    if rolled is not None:
        prog.continued += 1
        seg.predicted = seg.predicted[:seg.t + 1] + rolled
        seg.t += 1
        return seg
    if prog.fallbacks >= max_fallbacks:
        return None
    for plan, states in [(tuple(seg.actions), tuple(seg.predicted)), *seg.alternatives]:
        for j, state in enumerate(states):
            if tuple(state) != codes or (plan == tuple(seg.actions) and j == seg.t + 1):
                continue
            rolled = _reaching(models, codes, list(plan[j:]), goal)
            if rolled is not None:
                prog.fallbacks, prog.segment_ok = prog.fallbacks + 1, True
                return Segment(list(plan[j:]), rolled, seg.alternatives)
    return None


def replanned(replan: Callable[[np.ndarray], PlanResult], codes: tuple[int, ...], prog: Progress) -> Segment | None:
    prog.replans += 1
    new = replan(np.asarray(codes, np.int64))
    if not new.found:
        prog.replan_failed = True
        return None
    prog.segment_ok = True
    return Segment.of(new)
