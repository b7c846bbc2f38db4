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
from symlearn.provenance import atomic_write_json, atomic_write_png
from symlearn.sim.scenarios import SCENARIO_BY_NAME

CASES = ("table1_case1", "table1_case2", "table1_case3")
# The paper's Table I (mm), objects in our scenario order (stick, first cube, second cube); the paper's columns are
# green cube, orange stick, red cube, and its green / red cubes are our first / second cube.
PAPER_TABLE1 = {
    "predicted_mm": [[[-2, 192, -2], [3, 6, -2], [4, -9, -1]],
                     [[-17, 196, 1], [3, 8, 0], [-10, 180, -5]],
                     [[4, 159, 8], [-3, 210, -45], [-30, 131, -20]]],
    "truth_mm": [[[0, 180, 0], [0, 0, 0], [0, 0, 0]],
                 [[0, 180, 0], [0, 0, 0], [-1, 176, 0]],
                 [[3, 180, 0], [102, 177, -75], [2, 176, 0]]],
}
MOVED_MM = 100  # an object "moved" if it went at least this far along y
STILL_MM = 20  # and "stayed" if its predicted displacement is within this of zero
RIDER_TOL_MM = 50  # a rider's predicted y within this of the truth
ATTENTION_FIGURE = "table1_attention.png"  # RUN/table1_attention.png: the three cases' attention maps


def judge_object(obj: dict) -> dict:
    """The Table I criteria for one object: motion right (moved >= 100 mm in y, or within 20 mm of still),
    and for a cube that rides, predicted y within 50 mm of the truth."""
    pred, truth = np.asarray(obj["predicted_mm"]), np.asarray(obj["truth_mm"])
    moved = abs(truth[1]) >= MOVED_MM
    motion_ok = bool(np.sign(pred[1]) == np.sign(truth[1]) and abs(pred[1]) >= MOVED_MM) if moved \
        else bool(np.linalg.norm(pred) <= STILL_MM)
    out = {"moved": bool(moved), "motion_right": motion_ok}
    if moved and obj["type"] != "stick":
        out["rider_y_within_50mm"] = bool(abs(pred[1] - truth[1]) <= RIDER_TOL_MM)
    return out


def summarize_criteria(cases: list[dict]) -> dict:
    """Whether every object's motion is right and every rider's y is within tolerance, over all cases."""
    judged = [o["criteria"] for c in cases for o in c["objects"]]
    riders = [j["rider_y_within_50mm"] for j in judged if "rider_y_within_50mm" in j]
    return {"motion_right": all(j["motion_right"] for j in judged),
            "objects_motion_right": f"{sum(j['motion_right'] for j in judged)}/{len(judged)}",
            "riders_within_50mm": all(riders), "riders_right": f"{sum(riders)}/{len(riders)}"}


@torch.no_grad()
def predict_scene(model, ck, crops: np.ndarray, origins: np.ndarray, action_id: int,
                  held: int = -1) -> tuple[np.ndarray, np.ndarray | None]:
    """One observed scene's crops (k, S, S) and origins (k, 2) -> predicted effects (k, 3) in metres, and each
    layer's attention (layers, k, k), row i the weights object i puts on each object (averaged over heads; None for
    a model without attention). held: the index of the object the action grasps, read by models that take the
    action per object. The scene is encoded once for both."""
    depth = torch.from_numpy(crops.astype(np.float16).astype(np.float32))[None]  # as stored in the data set
    x = model_inputs(depth, torch.from_numpy(origins.astype(np.float32))[None])  # (1, k, 3, S, S)
    mask = torch.ones(1, crops.shape[0], dtype=torch.bool)
    actions, held_t = torch.tensor([action_id]), torch.tensor([held])
    model.eval()
    codes, _ = model.encode(x, mask)
    effects = model.decode(codes, mask, actions, held_t)[0].numpy() * ck.effect_std + ck.effect_mean
    maps = model.attention_maps(codes, mask, actions, held_t)
    return effects, None if maps is None else maps[:, 0].numpy()


def rider_attention(case: dict) -> list[dict]:
    """For each rider of a case (a cube that truly moved with the stick, which is object 0), the weight its token
    puts on the stick's in each layer: what attention would have to carry for the rider to move with it."""
    maps = case.get("attention")
    if not maps:
        return []
    return [{"object": i, "on_stick": [round(float(layer[i][0]), 3) for layer in maps],
             "on_itself": [round(float(layer[i][i]), 3) for layer in maps]}
            for i, obj in enumerate(case["objects"])
            if i > 0 and obj["type"] == "cube" and obj["truth_mm"][1] >= MOVED_MM]


def plot_attention(path: Path, cases: list[dict]) -> bool:
    """The attention maps of the three cases as one PNG (a row per case, a column per layer); False when the
    model has none (the no-attention baseline)."""
    if not cases or not all(c.get("attention") for c in cases):
        return False
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    layers = len(cases[0]["attention"])
    fig, axes = plt.subplots(len(cases), layers, figsize=(2.6 * layers + 0.6, 2.5 * len(cases)), squeeze=False)
    for r, case in enumerate(cases):
        labels = [f"{o['type']} {i}" + (" (rider)" if any(x["object"] == i for x in rider_attention(case)) else "")
                  for i, o in enumerate(case["objects"])]
        for layer in range(layers):
            ax = axes[r][layer]
            w = np.asarray(case["attention"][layer], dtype=float)
            ax.imshow(w, vmin=0, vmax=1, cmap="viridis")
            for i in range(w.shape[0]):
                for j in range(w.shape[1]):
                    ax.text(j, i, f"{w[i, j]:.2f}", ha="center", va="center", fontsize=7,
                            color="black" if w[i, j] > 0.5 else "white")
            ax.set_xticks(range(len(labels)), labels, fontsize=6, rotation=30)
            ax.set_yticks(range(len(labels)), labels, fontsize=6)
            ax.set_title(f"case {r + 1}, layer {layer + 1}", fontsize=8)
    fig.suptitle("Table I: attention of each object (row) on each object (column), averaged over heads", fontsize=9)
    fig.tight_layout()
    atomic_write_png(fig, path, dpi=110)
    plt.close(fig)
    return True


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
            res = sim.step(sc.action)  # the grasped object, for models given the action per object
            pred, maps = predict_scene(model, ck, obs.crops, obs.origins, sc.action.id, res.grasped)
            rows.append({"name": name, "description": sc.description,
                         "action": [sc.action.pick, sc.action.release],
                         "objects": [{"type": t.name.lower(),
                                      "predicted_mm": [round(float(v) * 1000, 1) for v in p],
                                      "truth_mm": [round(float(v) * 1000, 1) for v in g]}
                                     for t, p, g in zip(sim.types, pred, res.effect)]})
            for obj in rows[-1]["objects"]:
                obj["criteria"] = judge_object(obj)
            if maps is not None:
                rows[-1]["attention"] = np.round(maps, 3).tolist()
                rows[-1]["rider_attention"] = rider_attention(rows[-1])
    errors = np.array([[abs(a - b) for a, b in zip(o["predicted_mm"], o["truth_mm"])] for r in rows for o in r["objects"]])
    out = {"run": str(run_dir), **stage_record(Path(run_dir), ck, {"run": str(run_dir), "cases": list(CASES)}),
           "cases": rows, "mean_abs_error_mm": dict(zip("xyz", np.round(errors.mean(0), 1).tolist())),
           "criteria": summarize_criteria(rows), "paper": PAPER_TABLE1}
    figure = Path(run_dir) / ATTENTION_FIGURE
    if plot_attention(figure, rows):
        out["attention_figure"] = ATTENTION_FIGURE
    atomic_write_json(Path(run_dir) / "table1.json", out)
    return out


def format_table1(result: dict) -> str:
    """The paper's layout (first cube, stick, second cube): our predictions and the truth, each next to the
    paper's, then whether the motion and rider criteria hold."""
    fmt = lambda v: "(" + ", ".join(f"{x:.0f}" for x in v) + ")"  # noqa: E731
    order = (1, 0, 2)  # the paper's columns: green cube, orange stick, red cube
    lines = [f"{'':9}" + "".join(f"{name:>34}" for name in ("first cube (green)", "stick (orange)", "second cube (red)")),
             f"{'':9}" + f"{'ours':>18}{'paper':>16}" * 3]
    for key, title in (("predicted_mm", "Predictions"), ("truth_mm", "Ground truth")):
        lines.append(title)
        for i, r in enumerate(result["cases"]):
            paper = PAPER_TABLE1[key][i]
            lines.append(f"Case {i + 1}   " + "".join(f"{fmt(r['objects'][j][key]):>18}{fmt(paper[j]):>16}"
                                                    for j in order))
    c = result.get("criteria")
    if c:
        lines.append(f"motion right (moved >= {MOVED_MM} mm in y, or within {STILL_MM} mm of still): "
                     f"{c['objects_motion_right']} objects, {'met' if c['motion_right'] else 'not met'}; "
                     f"riders within {RIDER_TOL_MM} mm in y: {c['riders_right']}, "
                     f"{'met' if c['riders_within_50mm'] else 'not met'}")
    for i, r in enumerate(result["cases"]):
        for rider in r.get("rider_attention", []):
            lines.append(f"case {i + 1}: rider {rider['object']} attends to the stick "
                         f"{' / '.join(f'{w:.2f}' for w in rider['on_stick'])} and to itself "
                         f"{' / '.join(f'{w:.2f}' for w in rider['on_itself'])} (layer by layer)")
    if result.get("attention_figure"):
        lines.append(f"attention maps: {result['attention_figure']}")
    return "\n".join(lines)
