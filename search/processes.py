"""Planner child processes that never outlive their call: own process groups, deadlines, signal clean-up.

Every planner process (a search binary, a unified-planning worker) runs as the leader of its
own process group, registered here while it lives, with its temporary folders. A call kills
its group at the deadline and in `finally`; while any planner runs, SIGTERM, SIGINT and SIGHUP
to this (main) process kill every registered group and remove the registered folders before
the signal takes its usual course (the previous handler, or the default action), and an
`atexit` hook does the same at interpreter exit. A signal the caller ignores (SIG_IGN: `nohup`
ignores SIGHUP, a shell's background job SIGINT) stays ignored: no handler is put in its place.
A planner call ended by a signal is never a result: when the caller's own handler lets the
program go on, the call raises PlannerInterrupted; a planner process killed from outside
(SIGKILL, SIGTERM, SIGINT, SIGHUP, SIGQUIT; not a crash such as SIGSEGV) is reported with
`extra["killed_by_signal"]` (see `external_signal`), which the benchmark refuses to record.

    >>> with planner_guard(), temp_dir("symlearn-fd-") as tmp:                 # doctest: +SKIP
    ...     rc, out, err, timed_out = run_group([binary, "--search", s], "task", 10.0, cwd=tmp)
"""
from __future__ import annotations

import atexit
import contextlib
import os
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

_GROUPS: set[int] = set()  # process-group ids (= leader pids) of the live planner processes
_TEMPS: set[str] = set()  # temporary folders of the running planner calls
_SIGNALS = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGINT", "SIGHUP") if hasattr(signal, n))
_previous: dict[int, Any] = {}  # signal -> the handler before planner_guard installed ours
_depth = 0  # nesting depth of planner_guard in the main thread
_lock = threading.RLock()
# signals that end a process from outside (a user, a supervisor, the OOM killer), as opposed to its own crash
_EXTERNAL = {getattr(signal, n) for n in ("SIGKILL", "SIGTERM", "SIGINT", "SIGHUP", "SIGQUIT") if hasattr(signal, n)}


class PlannerInterrupted(KeyboardInterrupt):
    """A signal ended a planner call: its planners were killed, so there is no result to report or record.

    A KeyboardInterrupt, so `except Exception` (and search/execution's error-to-status conversions)
    let it through; the CLI ends with "interrupted; re-run the same command to resume".
    """

    def __init__(self, signum: int, message: str = "") -> None:
        super().__init__(message or f"planners stopped by {signal.Signals(signum).name}")
        self.signum = signum


def external_signal(returncode: int | None) -> int | None:
    """The signal number when a process's return code says it was killed from outside, else None (crashes too)."""
    if returncode is None or returncode >= 0:
        return None
    return -returncode if -returncode in _EXTERNAL else None


def kill_group(pgid: int) -> None:
    """SIGKILL the process group `pgid` and its leader (a leader not yet in its own group included)."""
    for kill in (os.killpg, os.kill):
        try:
            kill(pgid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass


def register_group(pgid: int) -> None:
    """Track a live planner process group until unregister_group."""
    with _lock:
        _GROUPS.add(pgid)


def unregister_group(pgid: int) -> None:
    """Stop tracking a process group (after it was waited for or killed)."""
    with _lock:
        _GROUPS.discard(pgid)


def cleanup() -> None:
    """Kill every registered process group and remove every registered temporary folder."""
    with _lock:
        groups, temps = list(_GROUPS), list(_TEMPS)
        _GROUPS.clear()
        _TEMPS.clear()
    for pgid in groups:
        kill_group(pgid)
    for path in temps:
        shutil.rmtree(path, ignore_errors=True)


def forget_inherited() -> None:
    """In a forked child: drop the parent's registry and signal handlers (they are the parent's to run)."""
    global _depth
    with _lock:
        _GROUPS.clear()
        _TEMPS.clear()
        _previous.clear()
        _depth = 0
    for sig in _SIGNALS:
        signal.signal(sig, signal.SIG_DFL)


def _on_signal(signum: int, frame: Any) -> None:
    """Kill the planners, remove their folders, then let the signal do what it did before planner_guard.

    If that handler lets the program go on, the interrupted call raises PlannerInterrupted: its
    planners are dead, and what they left must not pass for a result.
    """
    cleanup()
    previous = _previous.get(signum, signal.SIG_DFL)
    _restore()
    if callable(previous):
        previous(signum, frame)  # e.g. Python's SIGINT handler: KeyboardInterrupt
        raise PlannerInterrupted(signum)
    signal.signal(signum, signal.SIG_DFL)  # previous is SIG_DFL (or None: a handler not set from Python)
    os.kill(os.getpid(), signum)


def _restore() -> None:
    """Put back the handlers planner_guard replaced."""
    global _depth
    for sig, handler in list(_previous.items()):
        with contextlib.suppress(ValueError, TypeError):
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
    _previous.clear()
    _depth = 0


@contextlib.contextmanager
def planner_guard() -> Iterator[None]:
    """While inside (main thread only; elsewhere a no-op), termination signals first kill the registered planners."""
    global _depth
    main = threading.current_thread() is threading.main_thread()
    if main:
        if _depth == 0:
            for sig in _SIGNALS:
                previous = signal.getsignal(sig)
                if previous == signal.SIG_IGN:  # the caller ignores it (nohup, a background job): so do we
                    continue
                _previous[sig] = previous
                signal.signal(sig, _on_signal)
        _depth += 1
    try:
        yield
    finally:
        if main and _depth > 0:
            _depth -= 1
            if _depth == 0:
                _restore()


@contextlib.contextmanager
def temp_dir(prefix: str) -> Iterator[Path]:
    """A fresh temporary folder, removed on exit, by the signal path and at interpreter exit."""
    path = tempfile.mkdtemp(prefix=prefix)
    with _lock:
        _TEMPS.add(path)
    try:
        yield Path(path)
    finally:
        shutil.rmtree(path, ignore_errors=True)
        with _lock:
            _TEMPS.discard(path)


def run_group(args: Sequence[str], stdin_text: str, timeout_s: float, *, cwd: Path,
              after_start: Callable[[int], None] | None = None) -> tuple[int | None, str, str, bool]:
    """Run an argument list (no shell) in its own process group with a wall-clock limit.

    Returns (exit code, stdout, stderr, timed out); at the limit, and on any exception, the
    whole group is killed. OSError if the program cannot be started.
    """
    proc = subprocess.Popen(list(map(str, args)), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd, start_new_session=True)
    register_group(proc.pid)
    try:
        if after_start is not None:
            after_start(proc.pid)
        try:
            out, err = proc.communicate(stdin_text, timeout=max(timeout_s, 1e-3))
        except subprocess.TimeoutExpired:
            kill_group(proc.pid)
            out, err = proc.communicate()
            return None, out or "", err or "", True
        return proc.returncode, out, err, False
    finally:
        kill_group(proc.pid)  # members left behind by the leader; no-op when all are gone
        if proc.poll() is None:
            proc.wait()
        unregister_group(proc.pid)


class DeadlineExceeded(BaseException):
    """Raised inside `within` when its time is up."""


def within(fn: Callable[[], Any], seconds: float) -> Any:
    """fn() interrupted by DeadlineExceeded after `seconds` (SIGALRM: main thread only; elsewhere unbounded).

    An fn that returns after its time is a DeadlineExceeded too: the alarm can fall where Python only reports an
    exception (a finalizer that fn's garbage runs; seen in unified-planning's parser) and fn goes on to its end."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        return fn()
    if seconds <= 0:
        raise DeadlineExceeded()

    def _alarm(signum: int, frame: Any) -> None:
        raise DeadlineExceeded()

    previous = signal.signal(signal.SIGALRM, _alarm)
    old_timer = signal.setitimer(signal.ITIMER_REAL, seconds)
    t0 = time.monotonic()
    try:
        result = fn()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if old_timer[0] > 0:  # someone else's alarm: re-arm it with what is left of it
            signal.setitimer(signal.ITIMER_REAL, max(old_timer[0] - (time.monotonic() - t0), 1e-3), old_timer[1])
    if time.monotonic() - t0 >= seconds:
        raise DeadlineExceeded()
    return result


atexit.register(cleanup)
