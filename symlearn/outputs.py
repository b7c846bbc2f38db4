"""Output paths a user names, checked before any work: what may be written there, and what may be replaced.

A command checks every output path it was given before it starts: a file output must not be an
existing folder (nor lie under a file), a folder output must not be an existing file, two outputs
of one call must not be one path, and an existing file is replaced only when it is what the
command itself writes there (a GIF for a GIF, a benchmark result for a benchmark result), never
another file a user did not ask to replace, such as a run's transition.pt. Each refusal is one
ValueError line naming the flag and the path (exit code 2 on the command line).

    >>> gif = file_output(Path("runs/paper/plan.gif"), "--record", kind="a GIF", magic=GIF_MAGIC)  # doctest: +SKIP
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

GIF_MAGIC = (b"GIF87a", b"GIF89a")
PNG_MAGIC = (b"\x89PNG\r\n\x1a\n",)


def _head(path: Path, n: int) -> bytes:
    with open(path, "rb") as f:
        return f.read(n)


def _under_a_file(path: Path) -> Path | None:
    """The nearest existing ancestor of path when it is not a folder (then nothing can be written under it)."""
    for parent in path.parents:
        if parent.exists():
            return None if parent.is_dir() else parent
    return None


def file_output(path: Path, flag: str, *, kind: str, magic: tuple[bytes, ...] = (),
                is_own: Callable[[Path], bool] | None = None) -> Path:
    """Check a file the command will write: not a folder, not under a file, and, if it exists, one of its own
    kind (starting with one of `magic`, or accepted by `is_own`); returns the path. ValueError otherwise."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{flag} {path} is a folder; give the path of {kind} file")
    blocker = _under_a_file(path)
    if blocker is not None:
        raise ValueError(f"{flag} {path} cannot be written: {blocker} is a file, not a folder")
    if path.is_symlink() or path.exists():
        if not path.is_file() or path.is_symlink():
            raise ValueError(f"{flag} {path} exists and is not a regular file; refusing to replace it")
        try:
            own = ((magic and _head(path, max(map(len, magic))).startswith(magic))
                   or (is_own is not None and is_own(path)))
        except OSError as e:
            raise ValueError(f"{flag} {path} exists and cannot be read ({e.strerror}); refusing to replace it") from None
        if not own:
            raise ValueError(f"{flag} {path} exists and is not {kind}; refusing to replace it "
                             f"(remove it, or choose another path)")
    return path


def folder_output(path: Path, flag: str) -> Path:
    """Check a folder the command will write into: not an existing file, nor under one; returns the path."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} {path} is a file; give a folder")
    blocker = _under_a_file(path)
    if blocker is not None:
        raise ValueError(f"{flag} {path} cannot be made: {blocker} is a file, not a folder")
    return path


def distinct_outputs(outputs: dict[str, Path]) -> None:
    """Refuse two outputs of one call on one path (label -> path; compared resolved, so x.png and ./x.png meet)."""
    seen: dict[str, str] = {}
    for label, path in outputs.items():
        key = os.path.realpath(path)
        if key in seen:
            raise ValueError(f"{seen[key]} and {label} would both be written to {path}; give them different paths")
        seen[key] = label
