"""What a data set folder is, shared by its writer (symlearn.sim.collect) and its reader (symlearn.data.dataset).

The writer owns the format: `collect` stamps every manifest with DATA_KIND and FORMAT_VERSION and checks a
manifest it resumes with check_shard_entries, and `symlearn.data.dataset` reads the same definitions from
here. They live in the simulator's package, not the reader's, so that imports run one way (sim, then data):
the stage that produces the data never imports the stages that consume it. See docs/DATA_FORMAT.md.
"""
from __future__ import annotations

from pathlib import Path
from typing import BinaryIO

from pddl_export.bounded_json import JsonFileError, open_regular_file
from pddl_export.files import sha256_stream

FORMAT_VERSION = 1
DATA_KIND = "symlearn-interaction-data"
SPLITS = ("train", "val", "test")
MAX_SHARD_BYTES = 4 << 30  # a shard of 250 samples (the default) is a few MB; 4 GiB is far beyond any setting


class DataError(ValueError):
    """A data set that is missing, foreign, incomplete or corrupted."""


def open_shard(path: Path) -> BinaryIO:
    """A shard opened for reading (close it: `with open_shard(p) as f`), refused in one line naming the file
    (DataError) unless it is a regular file of at most MAX_SHARD_BYTES: a FIFO in a shard's place would
    block a plain open (resume, training) forever, a device would be read without end.
    The open-and-check is pddl_export.bounded_json's (non-blocking open, fstat on the descriptor)."""
    try:
        return open_regular_file(path, MAX_SHARD_BYTES, "data shard")
    except JsonFileError as e:
        raise DataError(str(e)) from None


def shard_sha256(path: Path) -> str:
    """Hex SHA-256 of a shard file, opened by open_shard (DataError for anything but a regular file)."""
    with open_shard(path) as f:
        return sha256_stream(f)


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
