"""Reproduction of the paper's Table I: predicted vs ground-truth effects in the three stick cases.

Each case is built in the simulator, observed, encoded and decoded by the trained model; the
same action is then executed to read the ground truth. Millimetres, objects in scenario order
(the moved stick first).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from symlearn.data.model_input import model_inputs
from symlearn.learning.checkpoint import load_effect_model, stage_record
from symlearn.provenance import atomic_write_json
from symlearn.sim.scenarios import SCENARIO_BY_NAME

CASES = ("table1_case1", "table1_case2", "table1_case3")


@torch.no_grad()
def predict_scene_effects(model, ck, crops: np.ndarray, origins: np.ndarray, action_id: int) -> np.ndarray:
    """One observed scene's crops (k, S, S) and origins (k, 2) -> predicted effects (k, 3) in metres."""
    depth = torch.from_numpy(crops.astype(np.float16).astype(np.float32))[None]  # as stored in the data set
    x = model_inputs(depth, torch.from_numpy(origins.astype(np.float32))[None])  # (1, k, 3, S, S)
    mask = torch.ones(1, crops.shape[0], dtype=torch.bool)
    out = model.eval()(x, mask, torch.tensor([action_id]))
    return out.effect[0].numpy() * ck.effect_std + ck.effect_mean


def table1(run_dir: Path) -> dict:
    """Run the three cases, write RUN/table1.json (with config, seed, versions, model hash) and return it."""
    from symlearn.sim.simulator import TabletopSimulator

    model, ck = load_effect_model(Path(run_dir))
    rows = []
    with TabletopSimulator() as sim:
        for name in CASES:
            sc = SCENARIO_BY_NAME[name]
            sim.build(sc.spec)
            obs = sim.observe()
            pred = predict_scene_effects(model, ck, obs.crops, obs.origins, sc.action.id)
            res = sim.step(sc.action)
            rows.append({"name": name, "description": sc.description,
                         "action": [sc.action.pick, sc.action.release],
                         "objects": [{"type": t.name.lower(),
                                      "predicted_mm": [round(float(v) * 1000, 1) for v in p],
                                      "truth_mm": [round(float(v) * 1000, 1) for v in g]}
                                     for t, p, g in zip(sim.types, pred, res.effect)]})
    errors = np.array([[abs(a - b) for a, b in zip(o["predicted_mm"], o["truth_mm"])] for r in rows for o in r["objects"]])
    out = {"run": str(run_dir), **stage_record(Path(run_dir), ck, {"run": str(run_dir), "cases": list(CASES)}),
           "cases": rows, "mean_abs_error_mm": dict(zip("xyz", np.round(errors.mean(0), 1).tolist()))}
    atomic_write_json(Path(run_dir) / "table1.json", out)
    return out


def format_table1(result: dict) -> str:
    """Predictions, then ground truth, one line per case, as in the paper."""
    fmt = lambda v: "(" + ", ".join(f"{x:.0f}" for x in v) + ")"  # noqa: E731
    types = [o["type"] for o in result["cases"][0]["objects"]]
    lines = [f"{'':8}" + "".join(f"{t:>22}" for t in types)]
    for key, title in (("predicted_mm", "Predictions"), ("truth_mm", "Ground truth")):
        lines.append(title)
        for i, r in enumerate(result["cases"], 1):
            lines.append(f"Case {i}  " + "".join(f"{fmt(o[key]):>22}" for o in r["objects"]))
    return "\n".join(lines)
