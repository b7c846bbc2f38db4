"""The one result type returned by every planner: learned-net A* and classical PDDL planners.

Each planner converts its own outcome (an A* SearchOutcome, unified-planning's
PlanGenerationResultStatus) into a PlanResult in one adapter, so benchmarks compare planners
on the same fields.

    >>> r = PlanResult(planner="astar", status=PlanStatus.SOLVED, plan=(3, 17),
    ...                predicted_states=((0, 5), (1, 5), (1, 6)), expansions=4,
    ...                planning_time_s=0.01, extra={"generated": 9})
    >>> r.found, PlanResult.from_json(r.to_json()) == r
    (True, True)
"""
from __future__ import annotations

import math
import operator
import time
from dataclasses import dataclass, field
from enum import Enum
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from pddl_export.symbolic import N_ACTIONS


class PlanStatus(str, Enum):
    """How a planner run ended; only SOLVED carries a plan, only UNSOLVABLE is a proof."""

    SOLVED = "solved"
    UNSOLVABLE = "unsolvable"  # search space exhausted (or the planner proved it)
    NODE_LIMIT = "node_limit"  # stopped by the expansion limit: no proof either way
    TIMEOUT = "timeout"
    ERROR = "error"  # the planner crashed or refused the problem; see message


ExtraValue = bool | int | float | str


def _as_int(x: Any, what: str) -> int:
    """Exact integer conversion that refuses floats and bools (operator.index semantics)."""
    if isinstance(x, bool):
        raise TypeError(f"{what} must be an integer, got bool {x!r}")
    try:
        return operator.index(x)
    except TypeError:
        raise TypeError(f"{what} must be an integer, got {type(x).__name__} {x!r}") from None


def _freeze_extra(extra: Mapping[str, Any]) -> MappingProxyType:
    """Validate planner-specific metrics (str -> bool/int/float/str) and return a read-only copy."""
    if not isinstance(extra, Mapping):
        raise TypeError(f"extra must be a mapping, got {type(extra).__name__}")
    out: dict[str, ExtraValue] = {}
    for k, v in extra.items():
        if not isinstance(k, str):
            raise TypeError(f"extra keys must be str, got {k!r}")
        if isinstance(v, np.generic):
            v = v.item()
        if not isinstance(v, (bool, int, float, str)):
            raise TypeError(f"extra[{k!r}] must be a number or str, got {type(v).__name__}")
        out[k] = v
    return MappingProxyType(out)


@dataclass(frozen=True)
class PlanResult:
    """What one planner run produced: status, plan (action ids 0..35), predicted states, metrics."""

    planner: str  # e.g. "astar", "astar-ucs", "fast-downward"
    status: PlanStatus
    plan: tuple[int, ...]  # action ids (pick * 6 + release); empty unless SOLVED
    predicted_states: tuple[tuple[int, ...], ...]  # start + one state per action, or () if none
    expansions: int | None  # None for planners that do not report it
    planning_time_s: float  # wall clock of the whole planner call
    message: str = ""  # one-line reason for ERROR / TIMEOUT / NODE_LIMIT / UNSOLVABLE
    extra: Mapping[str, ExtraValue] = field(default_factory=dict, hash=False)  # small metrics
    # further plans of a top-k planner, best first, each (plan, predicted_states); the main plan not among them
    alternatives: tuple[tuple[tuple[int, ...], tuple[tuple[int, ...], ...]], ...] = field(default=(), hash=False)
    # the ground plan as a PDDL planner wrote it, e.g. "(pick-release b1 l0 l3)", one str per step; () for planners
    # that plan on action ids. An action may take more than one step (a lifted domain's pick-cube and release-cube),
    # so a plan has at most as many actions as steps. A stock planner on a domain whose steps are not mapped to
    # action ids returns a SOLVED result with steps and an empty plan (search.stock_planners)
    steps: tuple[str, ...] = field(default=(), hash=False)

    def __post_init__(self) -> None:
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if not isinstance(self.planner, str) or not self.planner:
            raise ValueError("planner must be a non-empty name")
        set_("status", PlanStatus(self.status))
        plan = tuple(_as_int(a, "action id") for a in self.plan)
        bad = [a for a in plan if not 0 <= a < N_ACTIONS]
        if bad:
            raise ValueError(f"action ids must lie in 0..{N_ACTIONS - 1}, got {bad}")
        if plan and self.status is not PlanStatus.SOLVED:
            raise ValueError(f"a plan is only allowed with status solved, not {self.status.value}")
        set_("plan", plan)
        states = tuple(tuple(_as_int(c, "state code") for c in s) for s in self.predicted_states)
        if states:
            if self.status is not PlanStatus.SOLVED:
                raise ValueError("predicted_states are only allowed with status solved")
            if len(states) != len(plan) + 1:
                raise ValueError(
                    f"predicted_states must hold start + one state per action: "
                    f"{len(plan) + 1}, got {len(states)}")
            if len({len(s) for s in states}) != 1:
                raise ValueError("predicted_states must all have the same number of objects")
            if any(c < 0 for s in states for c in s):
                raise ValueError("state codes must be non-negative")
        set_("predicted_states", states)
        if self.expansions is not None:
            set_("expansions", _as_int(self.expansions, "expansions"))
            if self.expansions < 0:
                raise ValueError(f"expansions must be >= 0, got {self.expansions}")
        t = float(self.planning_time_s)
        if not (math.isfinite(t) and t >= 0.0):
            raise ValueError(f"planning_time_s must be finite and >= 0, got {self.planning_time_s}")
        set_("planning_time_s", t)
        if not isinstance(self.message, str) or "\n" in self.message:
            raise ValueError("message must be a one-line str")
        set_("extra", _freeze_extra(self.extra))
        alts = []
        for alt in self.alternatives:
            if self.status is not PlanStatus.SOLVED:
                raise ValueError("alternatives are only allowed with status solved")
            a_plan, a_states = alt
            a_plan = tuple(_as_int(a, "action id") for a in a_plan)
            a_states = tuple(tuple(_as_int(c, "state code") for c in s) for s in a_states)
            if any(not 0 <= a < N_ACTIONS for a in a_plan):
                raise ValueError(f"alternative plan action ids must lie in 0..{N_ACTIONS - 1}")
            if a_states and len(a_states) != len(a_plan) + 1:
                raise ValueError("an alternative's predicted states must hold start + one state per action")
            alts.append((a_plan, a_states))
        set_("alternatives", tuple(alts))
        steps = tuple(self.steps)
        if steps:
            if self.status is not PlanStatus.SOLVED:
                raise ValueError("steps are only allowed with status solved")
            if any(not isinstance(x, str) or not x or "\n" in x for x in steps):
                raise ValueError("steps must be non-empty one-line str")
            if len(plan) > len(steps):
                raise ValueError(f"steps must cover the plan's actions: {len(plan)} actions, {len(steps)} steps")
        set_("steps", steps)

    @property
    def found(self) -> bool:
        """True when the planner returned a plan (empty if the start already met the goal)."""
        return self.status is PlanStatus.SOLVED

    def to_json(self) -> dict[str, Any]:
        """Plain JSON-ready dict (lists, str status) that from_json reads back ("steps" only when there are some)."""
        out = {
            "planner": self.planner,
            "status": self.status.value,
            "plan": list(self.plan),
            "predicted_states": [list(s) for s in self.predicted_states],
            "expansions": self.expansions,
            "planning_time_s": self.planning_time_s,
            "message": self.message,
            "extra": dict(self.extra),
            "alternatives": [[list(p), [list(x) for x in st]] for p, st in self.alternatives],
        }
        if self.steps:
            out["steps"] = list(self.steps)
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> PlanResult:
        """Inverse of to_json; validates like the constructor."""
        return cls(
            planner=d["planner"],
            status=PlanStatus(d["status"]),
            plan=tuple(d["plan"]),
            predicted_states=tuple(tuple(s) for s in d.get("predicted_states", ())),
            expansions=d.get("expansions"),
            planning_time_s=d["planning_time_s"],
            message=d.get("message", ""),
            extra=dict(d.get("extra", {})),
            alternatives=tuple((tuple(p), tuple(tuple(x) for x in st)) for p, st in d.get("alternatives", ())),
            steps=tuple(d.get("steps", ())),
        )

    def __reduce__(self):
        """Pickle through the JSON form (a MappingProxyType field cannot be pickled directly)."""
        return (PlanResult.from_json, (self.to_json(),))


def one_line(text: Any, limit: int = 300) -> str:
    """Text on one line (whitespace runs become one space), cut to limit characters."""
    s = " ".join(str(text).split())
    return s if len(s) <= limit else s[: limit - 3] + "..."


def failed(planner: str, status: PlanStatus, t0: float, message: str = "", **extra: Any) -> PlanResult:
    """A result without a plan: its status, the time since t0 (time.perf_counter) and a one-line message."""
    return PlanResult(planner=planner, status=status, plan=(), predicted_states=(), expansions=None,
                      planning_time_s=time.perf_counter() - t0, message=one_line(message), extra=extra)
