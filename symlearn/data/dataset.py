"""Reading a collected data set back: manifest checks, checksums, splits, fingerprints.

Everything loads with numpy alone (`allow_pickle=False`); see docs/DATA_FORMAT.md.

    >>> data = load_split(Path("data/paper"), "train")     # doctest: +SKIP
    >>> data_fingerprint(Path("data/paper"))                # names the exact shards  # doctest: +SKIP
"""
from __future__ import annotations

import zipfile
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Sequence

import numpy as np

from pddl_export.bounded_json import JsonFileError, read_json_file
from pddl_export.files import sha256_stream
from symlearn.provenance import sha256_bytes
# the format is the writer's (collect); re-exported here, where readers have always found it
from symlearn.sim.data_format import (DATA_KIND, FORMAT_VERSION, SPLITS, DataError, check_shard_entries,  # noqa: F401
                                      open_shard)

ARRAY_NAMES = ("pre_depth", "post_depth", "pre_origin", "post_origin", "pre_pixels", "post_pixels",
               "action", "effect", "n_objects", "obj_type", "pre_pose", "post_pose", "grasped",
               "episode", "step")


@dataclass(frozen=True)
class InteractionData:
    """Samples of one split, objects padded to K; see docs/DATA_FORMAT.md for each array."""

    pre_depth: np.ndarray  # (N, K, S, S) float16, metres, 0 off the object
    post_depth: np.ndarray  # (N, K, S, S) float16
    pre_origin: np.ndarray  # (N, K, 2) int16 crop top-left (row, col) in the 256x256 image
    post_origin: np.ndarray  # (N, K, 2) int16
    pre_pixels: np.ndarray  # (N, K) int32 visible pixels
    post_pixels: np.ndarray  # (N, K) int32
    action: np.ndarray  # (N,) int8 in 0..35 = pick * 6 + release
    effect: np.ndarray  # (N, K, 3) float32 metres, zero for padding
    n_objects: np.ndarray  # (N,) int8
    obj_type: np.ndarray  # (N, K) int8: 0 cube, 1 stick, -1 padding (analysis only)
    pre_pose: np.ndarray  # (N, K, 7) float32 xyz + quaternion xyzw (analysis only)
    post_pose: np.ndarray  # (N, K, 7) float32
    grasped: np.ndarray  # (N,) int8 index of the object held, -1 for none
    episode: np.ndarray  # (N,) int32, unique across shards once loaded
    step: np.ndarray  # (N,) int16 index in the episode

    def __post_init__(self) -> None:
        n = self.action.shape[0]
        for f in fields(self):
            if getattr(self, f.name).shape[0] != n:
                raise DataError(f"array {f.name} has {getattr(self, f.name).shape[0]} rows, expected {n}")

    def __len__(self) -> int:
        return int(self.action.shape[0])

    @property
    def mask(self) -> np.ndarray:
        """(N, K) bool: which object slots are real."""
        return np.arange(self.effect.shape[1])[None, :] < self.n_objects[:, None]


def load_manifest(root: Path, require_complete: bool = True) -> dict:
    """The manifest of a data set, refusing missing, foreign, old-format or unfinished ones."""
    root = Path(root)
    path = root / "manifest.json"
    if not path.exists():
        raise DataError(f"no data set at {root} (manifest.json missing); run 'symlearn collect' first")
    try:
        m = read_json_file(path, what="data set manifest")
    except JsonFileError as e:
        raise DataError(str(e)) from None
    if not isinstance(m, dict) or m.get("kind") != DATA_KIND:
        raise DataError(f"{root} is not a symlearn interaction data set ({path} has no kind {DATA_KIND!r})")
    if m.get("format_version") != FORMAT_VERSION:
        raise DataError(f"{root} has data format version {m.get('format_version')!r}, "
                        f"this symlearn reads version {FORMAT_VERSION}")
    check_shard_entries(path, m)
    if require_complete and not m.get("complete"):
        raise DataError(f"{root} is an unfinished collection; re-run the same 'symlearn collect' to finish it")
    return m


def _load_shard(root: Path, entry: dict, verify: bool) -> dict[str, np.ndarray]:
    """One shard's arrays, read from the file opened once (open_shard: a regular file, else refused in one line;
    a FIFO in its place does not block) and, with `verify`, checked against the manifest's checksum first."""
    path = root / entry["name"]
    if not path.exists():
        raise DataError(f"shard {entry['name']} listed in the manifest is missing from {root}")
    with open_shard(path) as f:
        if verify:
            if sha256_stream(f) != entry["sha256"]:
                raise DataError(f"shard {entry['name']} is corrupted or truncated (checksum mismatch)")
            f.seek(0)
        try:
            with np.load(f, allow_pickle=False) as z:
                return {k: z[k] for k in ARRAY_NAMES}
        except (zipfile.BadZipFile, KeyError, ValueError, OSError, EOFError) as e:
            raise DataError(f"shard {entry['name']} cannot be read: {e}") from None


def load_split(root: Path, split: str, verify: bool = True) -> InteractionData:
    """All samples of one split ('train', 'val', 'test' or 'all'), shards in index order."""
    root = Path(root)
    if split not in SPLITS + ("all",):
        raise DataError(f"unknown split {split!r}: expected one of {', '.join(SPLITS)} or all")
    m = load_manifest(root)
    entries = [e for e in sorted(m["shards"], key=lambda e: e["index"]) if split in ("all", e["split"])]
    if not entries:
        raise DataError(f"{root} has no shards in split {split!r}")
    parts = [_load_shard(root, e, verify) for e in entries]
    arrays = {k: np.concatenate([p[k] for p in parts]) for k in ARRAY_NAMES}
    # Episode numbers restart in every shard; make them unique across the split.
    offsets = np.cumsum([0] + [int(p["episode"].max()) + 1 for p in parts[:-1]])
    arrays["episode"] = np.concatenate([p["episode"] + o for p, o in zip(parts, offsets)]).astype(np.int32)
    return InteractionData(**arrays)


def data_fingerprint(root: Path) -> str:
    """Hash of the data set's shard checksums: identifies exactly what a run was trained on."""
    m = load_manifest(root)
    return sha256_bytes("".join(sorted(s["sha256"] for s in m["shards"])).encode())[:16]


def distinct_extra_data(data_dir: Path, extra_data: Sequence[Path | str]) -> tuple[Path, ...]:
    """extra_data as paths; ValueError when a set is given twice or is data_dir itself (a stage would count it twice)."""
    extra = tuple(Path(d) for d in extra_data)
    resolved = [Path(d).resolve() for d in (data_dir, *extra)]
    if len(set(resolved)) != len(resolved):
        raise ValueError(f"extra data sets must differ from each other and from {data_dir}: {list(map(str, extra))}")
    return extra


def data_records(roots: Sequence[Path]) -> list[dict]:
    """Each data set's path and fingerprint, as stages record the extra sets they read."""
    return [{"data": str(d), "data_fingerprint": data_fingerprint(d)} for d in roots]


def effect_statistics(data: InteractionData) -> dict:
    """Objects per sample, mean absolute effect per axis (mm) and the share of objects moved > 1 cm."""
    eff = data.effect[data.mask]
    return {"samples": len(data), "objects": int(data.mask.sum()),
            "objects_per_sample": round(float(data.mask.sum() / max(len(data), 1)), 3),
            "mean_abs_effect_mm": dict(zip("xyz", [round(float(v), 1) for v in np.abs(eff).mean(0) * 1000])),
            "moved_fraction": round(float((np.linalg.norm(eff, axis=1) > 0.01).mean()), 3),
            "grasp_fraction": round(float((data.grasped >= 0).mean()), 3)}


def summarize(root: Path) -> dict:
    """A data set's counts, size on disk and effect statistics over all splits."""
    root = Path(root)
    m = load_manifest(root)
    stats = effect_statistics(load_split(root, "all"))
    size = sum((root / e["name"]).stat().st_size for e in m["shards"])
    return {"path": str(root), "counts": m["counts"], "shards": len(m["shards"]),
            "dropped_samples": sum(e.get("dropped_samples", 0) for e in m["shards"]),
            "size_mb": round(size / 1e6, 1), **stats}
