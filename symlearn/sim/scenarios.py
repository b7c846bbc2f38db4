"""Named scripted scenarios: a scene built by dropping objects, then one action.

They pin down the physical phenomena the symbols must capture (P1-P5) and the three stick
cases of the paper's Table I. `run_scenario` returns each object's ground-truth effect.

    >>> [s.name for s in SCENARIOS][:2]
    ['p1_lone_move', 'p2_rides_on_stick']
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from symlearn.world import Action, ObjectType

C, S = ObjectType.CUBE, ObjectType.STICK


@dataclass(frozen=True)
class Scenario:
    """Objects dropped in order at (type, location), then `action`; object order is identity."""

    name: str
    description: str
    spec: tuple[tuple[ObjectType, int], ...]
    action: Action


@dataclass(frozen=True)
class ScenarioResult:
    scenario: Scenario
    types: tuple[ObjectType, ...]
    effect: np.ndarray  # (k, 3) metres

    def to_json(self) -> dict:
        return {"name": self.scenario.name, "description": self.scenario.description,
                "action": [self.scenario.action.pick, self.scenario.action.release],
                "objects": [{"type": t.name.lower(), "effect_mm": [round(float(v) * 1000, 1) for v in e]}
                            for t, e in zip(self.types, self.effect)]}


SCENARIOS: tuple[Scenario, ...] = (
    Scenario("p1_lone_move", "a lone cube picked at the near middle and released at the far left",
             ((C, 4),), Action(4, 0)),
    Scenario("p2_rides_on_stick", "a cube on the right end of a stick rides along when the stick "
             "is picked at its middle and moved one location left", ((S, 1), (C, 2)), Action(1, 0)),
    Scenario("p3_under_not_grasped", "the lower of two stacked cubes is not grasped and stays",
             ((C, 4), (C, 4)), Action(4, 5)),
    Scenario("p4_empty_pick", "picking at an empty location changes nothing",
             ((C, 3), (C, 4)), Action(5, 0)),
    Scenario("p5_stack", "a cube released onto another cube stacks on it", ((C, 3), (C, 4)), Action(3, 4)),
    Scenario("p5_stack_on_stick", "a cube released onto a stick stacks on it", ((S, 4), (C, 3)), Action(3, 4)),
    Scenario("table1_case1", "stick moved one location right; both cubes elsewhere",
             ((S, 1), (C, 3), (C, 5)), Action(1, 2)),
    Scenario("table1_case2", "stick moved one location right; one cube on its left end",
             ((S, 1), (C, 3), (C, 0)), Action(1, 2)),
    Scenario("table1_case3", "stick moved one location right; two cubes on it, one near each end",
             ((S, 1), (C, 0), (C, 2)), Action(1, 2)),
    Scenario("table1_case3_stacked", "stick moved one location right; two cubes stacked on its left end "
             "(an extra case, not in the paper)", ((S, 1), (C, 0), (C, 0)), Action(1, 2)),
)
SCENARIO_BY_NAME = {s.name: s for s in SCENARIOS}


def run_scenario(sim, scenario: Scenario) -> ScenarioResult:
    """Build the scenario's scene in `sim` (a TabletopSimulator), act, and return the effects."""
    sim.build(scenario.spec)
    res = sim.step(scenario.action)
    return ScenarioResult(scenario, tuple(o.type for o in res.before.objects), res.effect)
