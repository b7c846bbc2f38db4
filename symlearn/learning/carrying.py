"""Carrying probes: the paper's Table I and variants nobody trained on, predicted by the relational model.

Each probe scene is built in the simulator, observed once (object crops and the six location crops), its
effects predicted by a trained relational model (symlearn.learning.relational), then the action is executed
for the truth. An object's prediction is right when, for an object that moved at least MOVED_MM, the
predicted horizontal displacement lies within RIDER_TOL_MM of the true one, and for one that stayed, the
predicted horizontal displacement is under STILL_MM. The variants: the stick moved the other way with the
rider mirrored, the riders carried to the near row, the objects listed in another order, a distractor
elsewhere, a two-cube stack beside the stick (not touching it: no rider), and two cubes stacked on the
stick's end.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from symlearn.learning.entities import entity_inputs, location_crops
from symlearn.sim.scenarios import SCENARIO_BY_NAME
from symlearn.world import Action, ObjectType

C, S = ObjectType.CUBE, ObjectType.STICK
MOVED_MM = 100.0
STILL_MM = 20.0
RIDER_TOL_MM = 50.0


@dataclass(frozen=True)
class CarryProbe:
    """Objects dropped in order at (type, location), then `action`; `order` lists the objects as the model
    sees them (a permutation of the drop order)."""

    name: str
    description: str
    spec: tuple[tuple[ObjectType, int], ...]
    action: Action
    order: tuple[int, ...] | None = None


def _table1(name: str, description: str) -> CarryProbe:
    """One of Table I's cases, its objects and action as the simulator's scenario table (symlearn.sim.scenarios)
    sets it up."""
    sc = SCENARIO_BY_NAME[name]
    return CarryProbe(sc.name, description, sc.spec, sc.action)


CARRY_PROBES: tuple[CarryProbe, ...] = (
    _table1("table1_case1", "Table I: stick moved one location right, both cubes elsewhere"),
    _table1("table1_case2", "Table I: stick moved right, one cube on its left end"),
    _table1("table1_case3", "Table I: stick moved right, a cube on each end"),
    CarryProbe("mirrored", "stick moved one location left, one cube on its right end, one elsewhere",
               ((S, 1), (C, 2), (C, 5)), Action(1, 0)),
    CarryProbe("to_near_row", "stick with a cube on each end carried to the near row's middle",
               ((S, 1), (C, 0), (C, 2)), Action(1, 4)),
    CarryProbe("reordered", "Table I case 3 with the objects listed cubes first",
               ((S, 1), (C, 0), (C, 2)), Action(1, 2), order=(2, 1, 0)),
    CarryProbe("distractor", "Table I case 3 with a cube at the near row's middle",
               ((S, 1), (C, 0), (C, 2), (C, 4)), Action(1, 2)),
    CarryProbe("stack_beside_near", "stick in the near row moved; a two-cube stack in the far row does not touch it",
               ((S, 4), (C, 1), (C, 1)), Action(4, 5)),
    CarryProbe("stack_beside_far", "stick at the far left moved to the near row; a two-cube stack at the far right, "
               "beyond the stick's end", ((S, 0), (C, 2), (C, 2)), Action(0, 3)),
    CarryProbe("stacked_on_end", "two cubes stacked on the stick's left end, the stick moved right",
               ((S, 1), (C, 0), (C, 0)), Action(1, 2)),
)


def judge(pred_mm: np.ndarray, truth_mm: np.ndarray) -> dict:
    """One object's verdict: moved or not, and whether the prediction is right (see the module docstring)."""
    moved = float(np.linalg.norm(truth_mm[:2])) >= MOVED_MM
    miss = float(np.linalg.norm(pred_mm[:2] - truth_mm[:2]))
    right = miss <= RIDER_TOL_MM if moved else float(np.linalg.norm(pred_mm[:2])) <= STILL_MM
    return {"moved": moved, "right": bool(right), "miss_mm": round(miss, 1)}


@torch.no_grad()
def predict_observation(model, blob: dict, crops: np.ndarray, origins: np.ndarray, action_id: int) -> np.ndarray:
    """One observed scene (k, 64, 64) crops and (k, 2) origins -> predicted effects (k, 3) in metres."""
    k = crops.shape[0]
    depth = crops.astype(np.float16)[None]
    windows = blob["windows"].numpy()
    loc = location_crops(depth, origins[None], np.array([k]), windows)
    obj, loc_in = entity_inputs(depth, origins[None], loc, windows)
    mask = torch.ones(1, k, dtype=torch.bool)
    eff = model(obj, mask, loc_in, torch.tensor([action_id])).effect[0].numpy()
    return eff * blob["std"].numpy() + blob["mean"].numpy()


def run_probes(model, blob: dict, probes=CARRY_PROBES) -> dict:
    """Every probe scene predicted and executed; a summary of the verdicts."""
    from symlearn.sim.simulator import TabletopSimulator

    rows = []
    with TabletopSimulator() as sim:
        for p in probes:
            sim.build(p.spec)
            obs = sim.observe()
            order = list(p.order or range(len(p.spec)))
            pred = np.empty((len(order), 3))
            pred[order] = predict_observation(model, blob, obs.crops[order], obs.origins[order], p.action.id)
            res = sim.step(p.action)
            objs = []
            for t, pr, tr in zip(sim.types, pred * 1000, res.effect * 1000):
                objs.append({"type": t.name.lower(), "predicted_mm": np.round(pr, 1).tolist(),
                             "truth_mm": np.round(tr, 1).tolist()} | judge(pr, tr))
            rows.append({"name": p.name, "description": p.description, "action": [p.action.pick, p.action.release],
                         "objects": objs})
    table1 = [o for r in rows if r["name"].startswith("table1") for o in r["objects"]]
    riders = [o for r in rows for o in r["objects"] if o["moved"] and o["type"] == "cube"]
    return {"probes": rows,
            "table1_right": f"{sum(o['right'] for o in table1)}/{len(table1)}",
            "all_right": f"{sum(o['right'] for r in rows for o in r['objects'])}/{sum(len(r['objects']) for r in rows)}",
            "riders_right": f"{sum(o['right'] for o in riders)}/{len(riders)}"}


def carrying(run_dir: Path) -> dict:
    """The probes for RUN/relations.pt."""
    from symlearn.learning.relational_training import load_relational

    model, blob = load_relational(Path(run_dir))
    return {"run": str(run_dir)} | run_probes(model, blob)


# Goals that need a stick carried with its riders: (name, objects dropped, the actions that make the goal scene).
# The planner sees the initial and goal scenes only; the actions only build the goal in the simulator.
CARRY_GOALS: tuple[tuple[str, tuple[tuple[ObjectType, int], ...], tuple[Action, ...]], ...] = (
    ("carry_one_rider", ((S, 1), (C, 0)), (Action(1, 2),)),
    ("carry_two_riders", ((S, 1), (C, 0), (C, 2)), (Action(1, 2),)),
    ("carry_rider_to_near_row", ((S, 1), (C, 0)), (Action(1, 4),)),
    ("carry_riders_to_near_row", ((S, 1), (C, 0), (C, 2)), (Action(1, 4),)),
)


def carry_problems(sim) -> list:
    """The CARRY_GOALS as problems: initial scene, goal scene made by executing the actions."""
    from symlearn.problems.problem import Problem

    out = []
    for name, spec, actions in CARRY_GOALS:
        sim.build(spec)
        initial = sim.get_scene()
        for a in actions:
            sim.step(a)
        out.append(Problem(name, 0, spec, initial, tuple(a.id for a in actions), sim.get_scene(), task=name))
    return out
