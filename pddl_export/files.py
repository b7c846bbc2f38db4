"""Atomic writes and content hashes: the one implementation every package uses.

It lives in the lowest package of the data flow (`pddl_export` imports nothing from `search` or
`symlearn`), so the pure packages and `symlearn` share it without an import cycle.

    >>> p = atomic_write_text(Path(tmp) / "a.txt", "hi")  # doctest: +SKIP
    >>> sha256_file(p)[:8]                                 # doctest: +SKIP
    '8f434346'
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import BinaryIO, Mapping


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def sha256_file(path: str | os.PathLike) -> str:
    """Hex SHA-256 of a file's content, read in 1 MiB chunks."""
    with open(path, "rb") as f:
        return sha256_stream(f)


def sha256_stream(f: BinaryIO) -> str:
    """Hex SHA-256 of what is left to read of an open binary file, in 1 MiB chunks (the file stays open)."""
    h = hashlib.sha256()
    for chunk in iter(lambda: f.read(1 << 20), b""):
        h.update(chunk)
    return h.hexdigest()


def _write_temp(path: Path, data: bytes) -> str:
    """`data` in a fresh temp file beside `path` (`.NAME.XXXX.tmp`), fsynced; its name. A failed write leaves no
    temp file behind."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with _removed_on_failure(tmp):
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp creates 0600; outputs are meant to be read by others
    return tmp


@contextlib.contextmanager
def _removed_on_failure(tmp: str):
    """Remove the temp file `tmp` if the block fails (whatever ends it, a KeyboardInterrupt too)."""
    try:
        yield
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write to a temp file beside `path`, fsync, then rename: readers never see half a file,
    and a failed write leaves no temp file behind."""
    path = Path(path)
    tmp = _write_temp(path, data)
    with _removed_on_failure(tmp):
        os.replace(tmp, path)
    return path


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"))


def finite_or_null(obj):
    """obj with every non-finite float (NaN, infinities: undefined metrics) replaced by None, so it is strict JSON."""
    if isinstance(obj, dict):
        return {k: finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_null(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def json_text(obj) -> str:
    """Strict JSON text (NaN and infinities are refused), as every JSON file is written."""
    return json.dumps(obj, indent=2, allow_nan=False) + "\n"


def atomic_write_json(path: str | os.PathLike, obj) -> Path:
    """Strict JSON (NaN and infinities are refused), written atomically."""
    return atomic_write_text(path, json_text(obj))


def _data(content: str | bytes) -> bytes:
    return content.encode("utf-8") if isinstance(content, str) else content


def atomic_write_files(files: Mapping[str | os.PathLike, str | bytes]) -> list[Path]:
    """Several files replaced as one unit: each is written whole and fsynced to a temp file beside its path before
    any is renamed into place, so a write that fails (a full disk, an error) leaves every old file as it was. The
    renames that follow need no space; should one fail, the files already replaced are put back (the old ones are
    kept as hard links until all stand). Only a kill between the renames (microseconds) can leave a mix."""
    staged: list[tuple[str, Path]] = []
    backups: dict[Path, str] = {}
    try:
        for path, content in files.items():
            staged.append((_write_temp(Path(path), _data(content)), Path(path)))
        for _, path in staged:  # the old files, to put back should a rename fail
            if path.is_file() and not path.is_symlink():
                fd, backups[path] = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".old")
                os.close(fd)
                os.unlink(backups[path])
                os.link(path, backups[path])
        done: list[Path] = []
        try:
            for tmp, path in staged:
                os.replace(tmp, path)
                done.append(path)
        except BaseException:
            for path in done:
                if path in backups:
                    os.replace(backups.pop(path), path)
                else:
                    os.unlink(path)
            raise
    finally:
        for leftover in [tmp for tmp, _ in staged] + list(backups.values()):
            if os.path.lexists(leftover):
                os.unlink(leftover)
    return [path for _, path in staged]


def atomic_write_folder(path: str | os.PathLike, files: Mapping[str, str | bytes]) -> Path:
    """A whole folder written at once: its files (relative name -> content; a name may hold subfolders) go into a
    temp folder beside `path`, each fsynced, which is then renamed into place. A folder already at `path` is moved
    aside first and removed once the new one stands, so no stale file of it stays beside the new ones and no
    reader sees a mix; a failure leaves the old folder as it was and no temp folder. (A kill between the two renames
    leaves no folder at `path` and the old one as `.NAME.XXXX.old` beside it.)"""
    path = Path(path)
    for name in files:
        rel = Path(name)
        if rel.is_absolute() or not rel.parts or any(part in ("", ".", "..") for part in rel.parts):
            raise ValueError(f"{name!r} is not a file name inside {path}")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
    old: Path | None = None
    try:
        for name, content in files.items():
            atomic_write_bytes(tmp / name, _data(content))
        for folder in [tmp, *(p for p in tmp.rglob("*") if p.is_dir())]:
            os.chmod(folder, 0o755)  # mkdtemp creates 0700; outputs are meant to be read by others
        if os.path.lexists(path):
            old = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".old"))
            os.replace(path, old)  # onto the empty folder just made
        try:
            os.replace(tmp, path)
        except BaseException:
            if old is not None:
                os.replace(old, path)
                old = None
            raise
    finally:
        for leftover in (tmp, old):
            if leftover is not None and os.path.lexists(leftover):
                _remove(leftover)
    return path


def _remove(path: Path) -> None:
    """A file, link or folder tree, gone."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        os.unlink(path)
