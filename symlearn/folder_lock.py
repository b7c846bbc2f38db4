"""One writer at a time: an advisory lock (fcntl.flock) on a lock file that names its holder's pid.

A long command takes the lock of what it writes before any work: `collect`, `problems` and
`pipeline` lock their --out folder (FOLDER/.symlearn.lock), `benchmark` its --out file
(OUT.lock beside it, as OUT.rows.jsonl). A second writer is refused at once, naming the
holder's pid, instead of computing everything twice and racing on the same files. The kernel
drops the lock when its holder ends, even by SIGKILL, so a lock file left by a killed run
never blocks the resume; a released lock's file is removed, and so is a folder the lock
created that is still empty (a refusal leaves nothing behind).

    >>> with folder_lock(Path("data/paper")):        # doctest: +SKIP
    ...     collect_shards()
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import os
from pathlib import Path
from typing import Iterator

LOCK_NAME = ".symlearn.lock"  # in a locked folder; readers of a folder's files skip it
MAX_PID_BYTES = 32  # what is read of a lock file to name its holder


class LockHeld(ValueError):
    """Another process holds the lock: a one-line refusal (exit code 2 on the command line)."""


def _holder(fd: int) -> str:
    """The pid written in an open lock file, or 'unknown'."""
    try:
        text = os.pread(fd, MAX_PID_BYTES, 0).decode("ascii", errors="replace").strip()
    except OSError:
        return "unknown"
    return text if text.isdigit() else "unknown"


def _acquire(lock_path: Path, what: Path) -> int:
    """An open descriptor holding the exclusive lock of lock_path; LockHeld if another process holds it."""
    while True:
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC | getattr(os, "O_NOFOLLOW", 0), 0o644)
        except OSError as e:
            if e.errno == errno.ELOOP:
                raise LockHeld(f"{lock_path} is a symbolic link; remove it (symlearn writes its pid there)") from None
            raise
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise LockHeld(f"{what} is being written by another symlearn process (pid {holder}, lock {lock_path}); "
                           f"wait for it to end, or choose another --out") from None
        # the holder we raced with may have removed the file on release: hold the lock of the file at the path
        try:
            st, mine = os.stat(lock_path, follow_symlinks=False), os.fstat(fd)
            if (st.st_dev, st.st_ino) == (mine.st_dev, mine.st_ino):
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)


@contextlib.contextmanager
def locked(lock_path: Path, what: Path | None = None) -> Iterator[Path]:
    """Hold the lock at lock_path (created, with this pid in it) while inside; LockHeld names a live holder."""
    lock_path = Path(lock_path)
    fd = _acquire(lock_path, Path(what) if what is not None else lock_path)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield lock_path
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock_path)  # while still held: a waiting opener sees another inode and retries
        os.close(fd)


@contextlib.contextmanager
def folder_lock(folder: Path) -> Iterator[Path]:
    """Hold FOLDER/.symlearn.lock while inside (the folder is created if missing, and removed again if it is
    empty on the way out). A path that exists and is not a folder is a ValueError."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"--out {folder} is a file, not a folder")
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        with locked(folder / LOCK_NAME, folder):
            yield folder
    finally:
        if created:
            with contextlib.suppress(OSError):
                folder.rmdir()  # only if nothing was written: a refusal leaves no empty folder behind
