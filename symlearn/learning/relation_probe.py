"""What each learned relation was found to mean: its bits against relations read from the simulator's poses.

An analysis, never an input of the learned route: the probe computes, from the data set's true poses
(`pre_pose`, `obj_type`, recorded for analysis only), two relations a person would name, and scores every
relation head of a trained relational model against them over the pairs of a split:

- `at(o, l)`: object o's centre lies within AT_M of table location l (horizontally); `nearest(o, l)`: l is the
  table location nearest o's centre (every object has one, also one standing off the locations);
- `covers(o, l)`: table location l lies within o's footprint (its extents turned by its yaw, plus a margin):
  a pick at l would meet o, if nothing stood on it there (a far-row stick covers two or three locations);
- `on(a, b)`: object a rests on object b: a's bottom within CONTACT_M of b's top and a's centre over b's
  footprint (b's extents turned by its yaw, plus a margin).

For a head k and a kind of pair (object-location, object-object), `holds_given` is P(r_k = 1 | relation)
and `given_holds` is P(relation | r_k = 1); a head "means" a relation when both are high. Each unary bit is
scored the same way against properties of one object (UNARY_PROPERTIES): its kind, whether it spans two or more
locations, whether it rests on an object, whether one rests on it, whether it stands in the far row.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np
import torch

from symlearn.learning.relational_training import EntitySplit, entity_split, load_relational
from symlearn.world import LOCATIONS, OBJECT_SIZE, ObjectType

AT_M = 0.05
CONTACT_M = 0.02
FOOTPRINT_MARGIN_M = 0.01
_HALF = {t.value: np.array(OBJECT_SIZE[t]) / 2 for t in ObjectType}


def yaw_of(quat: np.ndarray) -> np.ndarray:
    """Yaw (rad) of (..., 4) xyzw quaternions."""
    x, y, z, w = np.moveaxis(quat, -1, 0)
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def oracle_at(pose: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N, K, L) bool: object centre within AT_M of each location."""
    d = np.linalg.norm(pose[..., None, :2] - np.array(LOCATIONS)[None, None], axis=-1)
    return (d < AT_M) & mask[..., None]


def oracle_nearest(pose: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N, K, L) bool: the location nearest each object's centre (one per real object)."""
    d = np.linalg.norm(pose[..., None, :2] - np.array(LOCATIONS)[None, None], axis=-1)
    return (np.arange(len(LOCATIONS))[None, None] == d.argmin(-1)[..., None]) & mask[..., None]


def footprint_contains(pose: np.ndarray, types: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(N, K, P) bool: each of P points (x, y) lies within the object's footprint turned by its yaw, plus
    FOOTPRINT_MARGIN_M; `points` (P, 2) the same in every scene, or (N, P, 2) per scene."""
    half = np.where(types[..., None] == ObjectType.STICK, _HALF[1], _HALF[0])  # (N, K, 3)
    points = np.broadcast_to(points, (pose.shape[0], *points.shape[-2:]))
    yaw = yaw_of(pose[..., 3:])[..., None]
    dx = points[:, None, :, 0] - pose[..., None, 0]
    dy = points[:, None, :, 1] - pose[..., None, 1]
    c, s = np.cos(yaw), np.sin(yaw)
    u, v = c * dx + s * dy, -s * dx + c * dy  # the point in the object's frame
    return (np.abs(u) < half[..., None, 0] + FOOTPRINT_MARGIN_M) & (np.abs(v) < half[..., None, 1] + FOOTPRINT_MARGIN_M)


def oracle_covers(pose: np.ndarray, types: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N, K, L) bool: each table location within the object's footprint."""
    return footprint_contains(pose, types, np.array(LOCATIONS)) & mask[..., None]


def oracle_on(pose: np.ndarray, types: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N, K, K) bool: [a, b] when object a rests on object b."""
    half = np.where(types[..., None] == ObjectType.STICK, _HALF[1], _HALF[0])  # (N, K, 3)
    bottom = pose[..., 2] - half[..., 2]
    top = pose[..., 2] + half[..., 2]
    touch = np.abs(bottom[:, :, None] - top[:, None, :]) < CONTACT_M
    over = footprint_contains(pose, types, pose[..., :2]).transpose(0, 2, 1)  # [a, b]: a's centre over b
    k = pose.shape[1]
    pair = mask[:, :, None] & mask[:, None, :] & ~np.eye(k, dtype=bool)[None]
    return touch & over & pair


UNARY_PROPERTIES = ("stick", "spans", "on_object", "supports", "far_row")


def unary_properties(pose: np.ndarray, types: np.ndarray, mask: np.ndarray) -> dict[str, np.ndarray]:
    """(N, K) bool per property of UNARY_PROPERTIES, from the true poses (analysis only)."""
    on = oracle_on(pose, types, mask)
    covers = oracle_covers(pose, types, mask)
    return {"stick": (types == ObjectType.STICK) & mask, "spans": (covers.sum(-1) >= 2) & mask,
            "on_object": on.any(2) & mask, "supports": on.any(1) & mask,
            "far_row": (pose[..., 0] > 0.65) & mask}


@torch.no_grad()
def symbol_bits(model, split: EntitySplit, windows: torch.Tensor,
                batch_size: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """The model's bits on a split's pre-states (evaluation: thresholded), from one pass: unary (N, K, bits) and
    relational (N, R, E, E), bool."""
    codes, rels = [], []
    for a in range(0, len(split), batch_size):
        idx = torch.arange(a, min(a + batch_size, len(split)))
        obj, mask, loc, _ = split.inputs(idx, windows)
        c, _, r, _, _ = model.symbols(obj, mask, loc)
        codes.append(c.bool().numpy())
        rels.append(r.bool().numpy())
    return np.concatenate(codes), np.concatenate(rels)


def score(bits: np.ndarray, truth: np.ndarray, valid: np.ndarray) -> dict:
    """P(bit | truth), P(truth | bit) and P(bit) over the valid pairs."""
    b, t = bits[valid], truth[valid]
    return {"holds_given": round(float(b[t].mean()), 4) if t.any() else None,
            "given_holds": round(float(t[b].mean()), 4) if b.any() else None,
            "rate": round(float(b.mean()), 4), "pairs": int(valid.sum()), "true_pairs": int(t.sum())}


def probe(run_dir: Path, roots: Sequence[Path], split: str = "val") -> dict:
    """Score every relation head of RUN/relations.pt on a split of the data sets `roots`."""
    from symlearn.data.dataset import load_split

    model, blob = load_relational(run_dir)
    windows_np = blob["windows"].numpy()
    k = int(blob["max_objects"])
    datas = [load_split(Path(r), split) for r in roots]
    data, _, _ = entity_split(datas, windows_np, k, blob["mean"].numpy(), blob["std"].numpy())
    pose = np.concatenate([np.pad(d.pre_pose, [(0, 0), (0, k - d.pre_pose.shape[1]), (0, 0)]) for d in datas])
    types = np.concatenate([np.pad(d.obj_type, [(0, 0), (0, k - d.obj_type.shape[1])], constant_values=-1)
                            for d in datas])
    mask = data.mask.numpy()
    codes, bits = symbol_bits(model, data, torch.from_numpy(windows_np.astype(np.float32)))
    at, on = oracle_at(pose, mask), oracle_on(pose, types, mask)
    n_loc = len(LOCATIONS)
    obj_loc_valid = np.broadcast_to(mask[..., None], at.shape)
    obj_obj_valid = mask[:, :, None] & mask[:, None, :] & ~np.eye(k, dtype=bool)[None]
    heads = []
    for h in range(bits.shape[1]):
        ol, oo = bits[:, h, :k, k:k + n_loc], bits[:, h, :k, :k]
        lo = bits[:, h, k:k + n_loc, :k].transpose(0, 2, 1)
        heads.append({"head": h,
                      "object_location": {"at": score(ol, at, obj_loc_valid),
                                          "nearest": score(ol, oracle_nearest(pose, mask), obj_loc_valid),
                                          "covers": score(ol, oracle_covers(pose, types, mask), obj_loc_valid)},
                      "location_object": {"at": score(lo, at, obj_loc_valid)},
                      "object_object": {"on": score(oo, on, obj_obj_valid),
                                        "under": score(oo, on.transpose(0, 2, 1), obj_obj_valid)}})
    props = unary_properties(pose, types, mask)
    unary = [{"bit": b, **{name: score(codes[..., b], truth, mask) for name, truth in props.items()}}
             for b in range(codes.shape[-1])]
    return {"run": str(run_dir), "data": [str(r) for r in roots], "split": split, "heads": heads, "unary": unary}


def format_probe(res: dict) -> str:
    """The probe as a table: per head, P(bit | relation) and P(relation | bit) for each pair kind."""
    lines = [f"{'head':>4}  {'pairs':<16} {'relation':<6} {'P(bit|rel)':>10} {'P(rel|bit)':>10} {'P(bit)':>7}"]
    for h in res["heads"]:
        for kind in ("object_location", "location_object", "object_object"):
            for name, s in h[kind].items():
                f = lambda v: "-" if v is None else f"{v:.3f}"  # noqa: E731
                lines.append(f"{h['head']:>4}  {kind:<16} {name:<6} {f(s['holds_given']):>10} "
                             f"{f(s['given_holds']):>10} {s['rate']:>7.3f}")
    lines.append(f"{'bit':>4}  " + " ".join(f"{p + ' P(b|p) P(p|b)':>24}" for p in UNARY_PROPERTIES))
    for u in res.get("unary", []):
        f = lambda v: "    -" if v is None else f"{v:.3f}"  # noqa: E731
        lines.append(f"{'u' + str(u['bit']):>4}  " + " ".join(f"{f(u[p]['holds_given']):>17} "
                                                             f"{f(u[p]['given_holds'])}" for p in UNARY_PROPERTIES))
    return "\n".join(lines)
