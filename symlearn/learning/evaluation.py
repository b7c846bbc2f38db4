"""Effect-prediction evaluation on the test split, with ablation rows.

Rows: the trained run, optionally a no-attention run (DeepSym-style), and the mean-effect
predictor (the training set's mean effect for every object). Errors are mean absolute errors per
axis in millimetres over real objects, overall, by number of objects in the scene, and on riders
(objects that moved because they stood on a carried one; `symlearn.data.statistics.rider_mask`),
the relational effect the attention is for. Symbol stability: the share of still objects (moved less
than 1 cm, not held) whose code is the same before and after the action; a code that changes
while its object stays put makes the symbolic state depend on more than the arrangement. Shared
codes: the share of scenes of 2+ objects where two objects hold one code (aliasing between objects).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from symlearn.data.dataset import data_fingerprint, load_split
from symlearn.data.statistics import rider_mask, still_mask
from symlearn.learning.checkpoint import analysis_device, effect_model_sha256, load_effect_model, stage_record
from symlearn.provenance import atomic_write_json
from symlearn.learning.models import AttentiveDeepSym
from symlearn.learning.training import SplitTensors, predict_effects, to_tensors


def _mae_rows(pred_m: np.ndarray, true_m: np.ndarray, mask: np.ndarray, n_objects: np.ndarray,
              riders: np.ndarray) -> dict:
    """MAE in mm per axis overall, by scene size and on riders ((N, K) bool); inputs in metres."""
    err = np.abs(pred_m - true_m) * 1000

    def mae(m):
        return dict(zip("xyz", np.round(err[m].mean(0), 2).tolist())) if m.any() else None

    out = {"effect_mae_mm": mae(mask)}
    out["by_objects"] = {str(k): mae(mask & (n_objects == k)[:, None]) for k in sorted(set(n_objects.tolist()))}
    out["riders"] = {"count": int(riders.sum()), "effect_mae_mm": mae(riders)}
    return out


@torch.no_grad()
def code_stability(model: AttentiveDeepSym, split: SplitTensors, still: np.ndarray, batch_size: int = 256) -> dict:
    """Share of still objects ((N, K) bool) whose code is unchanged by the action, and of scenes where all are.

    Also the share of scenes of 2+ objects where two objects hold the same code: the rules and the
    transition network move such objects alike, so no plan over these symbols parts them again.
    """
    model.eval()
    same, shared, sizes = [], [], []
    device = next(model.parameters()).device
    for i in range(0, len(split), batch_size):
        idx = torch.arange(i, min(i + batch_size, len(split)))
        crops, mask, _, _ = split.batch(idx)
        before, _ = model.encode(crops.to(device), mask.to(device))
        after, _ = model.encode(split.post_crops(idx).to(device), mask.to(device))
        same.append((before == after).all(-1).cpu().numpy())
        both = mask[:, :, None] & mask[:, None, :] & ~torch.eye(mask.shape[1], dtype=torch.bool)  # (B, K, K) pairs
        equal = (before[:, :, None] == before[:, None, :]).all(-1).cpu() & both
        shared.append(equal.flatten(1).any(1).numpy())
        sizes.append(mask.sum(1).numpy())
    same = np.concatenate(same) if same else np.zeros(still.shape, bool)
    shared, sizes = (np.concatenate(x) if x else np.zeros(0) for x in (shared, sizes))
    multi = sizes > 1
    n = int(still.sum())
    return {"still_objects": n, "code_unchanged": round(float(same[still].mean()), 4) if n else None,
            "scenes_all_unchanged": round(float((same | ~still).all(-1).mean()), 4) if len(same) else None,
            "multi_object_scenes": int(multi.sum()),
            "scenes_with_shared_code": round(float(shared[multi].mean()), 4) if multi.any() else None,
            "shared_code_by_objects": {str(k): round(float(shared[sizes == k].mean()), 4)
                                       for k in sorted(set(sizes[multi].astype(int).tolist()))}}


def evaluate(run_dir: Path, data_dir: Path, baseline_run: Path | None = None) -> dict:
    """Write RUN/eval.json (errors, config, seed, versions, model hash, data fingerprint) and return it."""
    run_dir = Path(run_dir)
    model, ck = load_effect_model(run_dir, device=analysis_device())
    test = load_split(data_dir, "test")
    mean, std = ck.effect_mean, ck.effect_std
    t = to_tensors(test, mean, std, with_post=True)
    still = still_mask(test)
    truth = test.effect
    mask, nobj, riders = test.mask, test.n_objects.astype(int), rider_mask(test)

    def denorm(p: torch.Tensor) -> np.ndarray:
        return p.numpy() * std + mean

    config = {"run": str(run_dir), "data": str(data_dir), "baseline_run": None if baseline_run is None else str(baseline_run)}
    result = {"run": str(run_dir), "data": str(data_dir), **stage_record(run_dir, ck, config),
              "data_fingerprint": data_fingerprint(data_dir),
              "trained_on": ck.meta.get("data_fingerprint"), "n_test_samples": len(test),
              "mean_abs_effect_mm": dict(zip("xyz", np.round(np.abs(truth[mask]).mean(0) * 1000, 2).tolist())),
              "mean_abs_effect_by_objects_mm": {
                  str(k): dict(zip("xyz", np.round(np.abs(truth[mask & (nobj == k)[:, None]]).mean(0) * 1000, 2).tolist()))
                  for k in sorted(set(nobj.tolist()))}}
    result.update(_mae_rows(denorm(predict_effects(model, t)), truth, mask, nobj, riders))
    result["code_stability"] = code_stability(model, t, still)
    ablations = {}
    if baseline_run is not None:
        base, bck = load_effect_model(Path(baseline_run), device=analysis_device())
        tb = to_tensors(test, bck.effect_mean, bck.effect_std, with_post=True)
        pb_ = predict_effects(base, tb).numpy() * bck.effect_std + bck.effect_mean
        ablations["no_attention"] = {"run": str(baseline_run), "effect_model_sha256": effect_model_sha256(baseline_run),
                                     **_mae_rows(pb_, truth, mask, nobj, riders),
                                     "code_stability": code_stability(base, tb, still)}
    ablations["mean_effect"] = _mae_rows(np.broadcast_to(mean, truth.shape), truth, mask, nobj, riders)
    result["ablations"] = ablations
    atomic_write_json(run_dir / "eval.json", result)
    return result


def format_table(result: dict) -> str:
    """The evaluation as a text table: one row per model, x/y/z MAE in mm, overall and by scene size."""
    sizes = sorted(result["by_objects"])
    n_riders = result.get("riders", {}).get("count", 0)
    head = (f"{'model':<16}{'x':>8}{'y':>8}{'z':>8}" + "".join(f"   k={k} (x, y, z)" for k in sizes)
            + f"   riders, {n_riders} (x, y, z)")
    lines = [head, "-" * len(head)]

    def fmt(name, rows):
        o = rows["effect_mae_mm"]
        by = "".join(f"   {rows['by_objects'][k]['x']:5.1f} {rows['by_objects'][k]['y']:5.1f} {rows['by_objects'][k]['z']:5.1f}"
                     if rows["by_objects"].get(k) else "   -" for k in sizes)
        r = (rows.get("riders") or {}).get("effect_mae_mm")
        rid = f"   {r['x']:5.1f} {r['y']:5.1f} {r['z']:5.1f}" if r else "   -"
        return f"{name:<16}{o['x']:8.1f}{o['y']:8.1f}{o['z']:8.1f}{by}{rid}"

    lines.append(fmt("attentive", result))
    for name, rows in result["ablations"].items():
        lines.append(fmt(name, rows))
    m = result["mean_abs_effect_mm"]
    lines.append(f"{'mean |effect|':<16}{m['x']:8.1f}{m['y']:8.1f}{m['z']:8.1f}")
    cs = result.get("code_stability")
    if cs and cs["code_unchanged"] is not None:
        lines.append(f"symbol stability: {cs['code_unchanged']:.3f} of {cs['still_objects']} still objects keep their "
                     f"code; {cs['scenes_all_unchanged']:.3f} of scenes keep all of them")
    if cs and cs.get("scenes_with_shared_code") is not None:
        lines.append(f"shared codes: in {cs['scenes_with_shared_code']:.3f} of {cs['multi_object_scenes']} scenes of 2+ "
                     "objects two objects hold the same code (no plan over the symbols can part them); by objects: "
                     + ", ".join(f"{k}: {v:.3f}" for k, v in cs["shared_code_by_objects"].items()))
    return "\n".join(lines)
