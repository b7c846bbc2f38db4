"""What a data set folder is, shared by its writer (symlearn.sim.collect) and its reader (symlearn.data.dataset).

The writer owns the format: `collect` stamps every manifest with DATA_KIND and FORMAT_VERSION and checks a
manifest it resumes with check_shard_entries, and `symlearn.data.dataset` reads the same definitions from
here. They live in the simulator's package, not the reader's, so that imports run one way (sim, then data):
the stage that produces the data never imports the stages that consume it. See docs/DATA_FORMAT.md.
"""
from __future__ import annotations

from pathlib import Path

FORMAT_VERSION = 1
DATA_KIND = "symlearn-interaction-data"
SPLITS = ("train", "val", "test")


class DataError(ValueError):
    """A data set that is missing, foreign, incomplete or corrupted."""


def check_shard_entries(path: Path, m: dict) -> None:
    """Refuse a manifest (read from `path`) whose `shards` list is missing or has a malformed entry."""
    shards = m.get("shards")
    if not isinstance(shards, list):
        raise DataError(f"{path} has no list of shards ('shards' is {type(shards).__name__})")
    for i, e in enumerate(shards):
        problem = _shard_entry_problem(e)
        if problem:
            raise DataError(f"{path}: shard entry {i} {problem}")


def _shard_entry_problem(e) -> str | None:
    """What is wrong with one manifest shard entry, or None."""
    if not isinstance(e, dict):
        return f"is a {type(e).__name__}, not an object"
    for key, kind in (("name", str), ("sha256", str), ("index", int), ("split", str), ("n_samples", int)):
        if not isinstance(e.get(key), kind) or isinstance(e.get(key), bool):
            return f"has no valid {key!r} (found {e.get(key)!r})"
    name = e["name"]
    if name != Path(name).name or not name.endswith(".npz") or name.startswith("."):
        return f"names {name!r}, not a shard file in the data set folder"
    if e["split"] not in SPLITS:
        return f"has split {e['split']!r}, expected one of {', '.join(SPLITS)}"
    return None
