"""What the learned symbols are: counts, coverage, prototypes (the paper's Figures 4 and 5), purity.

Every training object's pre-state crop is encoded deterministically. For each symbol: how often
it occurs, the average depth crop and mean image position of its objects, how pure it is with
respect to object type and to 'moved when picked' (whether an object that the action's pick
location lands on actually moved).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pddl_export.symbolic import code_str, codes_from_bits
from symlearn.data.dataset import InteractionData, data_fingerprint, load_split
from symlearn.learning.checkpoint import analysis_device, load_effect_model, stage_record
from symlearn.learning.models import AttentiveDeepSym
from symlearn.provenance import atomic_write_json, atomic_write_png
from symlearn.symbolic.transition_data import SymbolReader, symbol_reader
from symlearn.world import LOCATIONS, N_LOCATIONS, OBJECT_SIZE, ObjectType

MOVED_M = 0.01
FREQUENT_MIN_COUNT = 100  # a symbol is frequent from this many training objects (analyse_symbols' default)


def encode_codes(model: AttentiveDeepSym | SymbolReader, depth: np.ndarray, origin: np.ndarray,
                 mask: np.ndarray) -> np.ndarray:
    """(N, K, S, S) depth crops -> (N, K) integer codes (eval-mode threshold, and location bits if the reader
    has them); padding gets -1."""
    return np.where(mask, codes_from_bits(symbol_reader(model).encode(depth, origin, mask).round()), -1)


def picked_objects(data: InteractionData) -> np.ndarray:
    """(N, K) bool: the action's pick location lies on the object's top (a stick counts along its length)."""
    pick = data.action.astype(int) // N_LOCATIONS
    loc = np.array(LOCATIONS)[pick]  # (N, 2)
    pos = data.pre_pose[..., :2]  # (N, K, 2)
    half_y = np.where(data.obj_type == ObjectType.STICK, OBJECT_SIZE[ObjectType.STICK][1] / 2, 0.025)
    return data.mask & (np.abs(pos[..., 0] - loc[:, None, 0]) < 0.03) & (np.abs(pos[..., 1] - loc[:, None, 1]) < half_y + 0.005)


def analyse_symbols(run_dir: Path, data_dir: Path, symbol: str | None = None,
                    min_count: int = FREQUENT_MIN_COUNT) -> dict:
    """Write RUN/symbols.json (with config, seed, versions, input hashes), symbols.png and symbol_examples.png."""
    run_dir = Path(run_dir)
    model, ck = load_effect_model(run_dir, device=analysis_device())
    bits = ck.config.bits
    data = load_split(Path(data_dir), "train")
    codes = encode_codes(model, data.pre_depth, data.pre_origin, data.mask)
    real = data.mask
    flat = codes[real]
    uniq, counts = np.unique(flat, return_counts=True)
    order = np.argsort(-counts, kind="stable")
    uniq, counts = uniq[order], counts[order]
    cover95 = int(np.searchsorted(np.cumsum(counts) / counts.sum(), 0.95) + 1)
    moved = np.linalg.norm(data.effect, axis=-1) > MOVED_M
    picked = picked_objects(data)
    crop = data.pre_depth.shape[-1]
    centre = data.pre_origin.astype(np.float64) + crop / 2  # (N, K, 2) rows, cols
    rows = []
    for c, n in zip(uniq, counts):
        sel = codes == c
        cube = float((data.obj_type[sel] == ObjectType.CUBE).mean())
        pk = sel & picked
        mv = float(moved[pk].mean()) if pk.any() else None
        rows.append({"code": code_str(int(c), bits), "count": int(n),
                     "mean_x_px": round(float(centre[sel][:, 1].mean()), 1),
                     "mean_y_px": round(float(centre[sel][:, 0].mean()), 1),
                     "cube_fraction": round(cube, 3), "type_purity": round(max(cube, 1 - cube), 3),
                     "times_picked": int(pk.sum()),
                     "moved_when_picked": None if mv is None else round(mv, 3),
                     "moved_purity": None if mv is None else round(max(mv, 1 - mv), 3)})
    w = counts / counts.sum()
    config = {"run": str(run_dir), "data": str(data_dir), "symbol": symbol, "min_count": min_count}
    result = {"run": str(run_dir), **stage_record(run_dir, ck, config), "data_fingerprint": data_fingerprint(Path(data_dir)),
              "n_objects": int(real.sum()), "n_distinct": int(len(uniq)),
              "n_symbols_for_95pct": cover95, "frequent_min_count": min_count,
              "weighted_type_purity": round(float(sum(r["type_purity"] * wi for r, wi in zip(rows, w))), 3),
              "symbols": rows}
    picked_rows = [r for r in rows if r["moved_purity"] is not None]
    if picked_rows:
        pw = np.array([r["times_picked"] for r in picked_rows], float)
        result["weighted_moved_purity"] = round(float(np.dot([r["moved_purity"] for r in picked_rows], pw) / pw.sum()), 3)
    frequent = [r for r in rows if r["count"] >= min_count] or rows[:1]
    _plot_prototypes(run_dir / "symbols.png", data, codes, frequent, bits)
    chosen = symbol or _default_example_symbol(frequent)
    result["example_symbol"] = chosen
    _plot_examples(run_dir / "symbol_examples.png", data, codes, chosen, bits)
    atomic_write_json(run_dir / "symbols.json", result)
    return result


def _default_example_symbol(frequent: list[dict]) -> str:
    """The frequent symbol whose objects most reliably stay put when picked ('not graspable'), as Figure 5."""
    cands = [r for r in frequent if r["times_picked"] >= 10]
    if not cands:
        return frequent[0]["code"]
    return min(cands, key=lambda r: r["moved_when_picked"])["code"]


def _plot_prototypes(path: Path, data, codes, frequent, bits) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(frequent)
    cols = min(7, n)
    rows_n = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows_n, cols, figsize=(2.0 * cols, 2.3 * rows_n), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, r in zip(axes.flat, frequent):
        c = int(r["code"], 2)
        crops = data.pre_depth[codes == c].astype(np.float32)
        ax.imshow(np.where(crops > 0, 2.0 - crops, 0).mean(0), cmap="viridis")
        ax.set_title(f"{r['code']}\nn={r['count']} x={r['mean_x_px']:.0f} y={r['mean_y_px']:.0f}", fontsize=7)
    fig.suptitle("Average depth crop per frequent symbol (height above the far plane)")
    fig.tight_layout()
    atomic_write_png(fig, path, dpi=110)
    plt.close(fig)


def _plot_examples(path: Path, data, codes, symbol: str, bits: int, n: int = 12) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if len(symbol) != bits or set(symbol) - {"0", "1"}:
        raise ValueError(f"symbol {symbol!r} is not a {bits}-bit string")
    idx = np.argwhere(codes == int(symbol, 2))[:n]
    fig, axes = plt.subplots(2, int(np.ceil(max(len(idx), 1) / 2)), figsize=(12, 4), squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (i, k) in zip(axes.flat, idx):
        ax.imshow(data.pre_depth[i, k].astype(np.float32), cmap="viridis")
        t = ObjectType(int(data.obj_type[i, k])).name.lower()
        ax.set_title(f"{t}, {data.pre_pixels[i, k]} px", fontsize=8)
    fig.suptitle(f"Examples of symbol {symbol} ({len(np.argwhere(codes == int(symbol, 2)))} objects)")
    fig.tight_layout()
    atomic_write_png(fig, path, dpi=100)
    plt.close(fig)

