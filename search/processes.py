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

A caller that cannot clean up (SIGKILL, the OOM killer, a Ray worker force-exited) is covered by
its watchdog: a small process, started with the first registration and nobody's child, that keeps
a copy of the registry sent through a pipe whose only write end the caller holds. End of file,
which the kernel gives when the caller is gone however it ended, makes it kill the registered
groups (the planners' own children, such as Fast Downward's translator and search, included) and
remove the registered folders.

    >>> with planner_guard(), temp_dir("symlearn-fd-") as tmp:                 # doctest: +SKIP
    ...     rc, out, err, timed_out = run_group([binary, "--search", s], "task", 10.0, cwd=tmp)
"""
from __future__ import annotations

import atexit
import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
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
    """Track a live planner process group until unregister_group (OSError if the watchdog cannot start)."""
    _track("group", pgid, True)


def unregister_group(pgid: int) -> None:
    """Stop tracking a process group (after it was waited for or killed)."""
    _track("group", pgid, False)


def cleanup() -> None:
    """Kill every registered process group and remove every registered temporary folder."""
    with _lock:
        groups, temps = list(_GROUPS), list(_TEMPS)
    for pgid in groups:
        kill_group(pgid)
    for path in temps:
        shutil.rmtree(path, ignore_errors=True)
    for pgid in groups:
        unregister_group(pgid)
    for path in temps:
        _track("temp", path, False)


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


# The watchdog's program (sys.executable -I -S, in a session of its own, deaf to the termination signals). It forks
# and its first process ends, so it is nobody's child: a kill of its caller's children (Ray's, when a worker exits)
# misses it. It reads the caller's registry changes, one JSON line [kind, added, value] each; end of file means the
# caller is gone, however it ended (SIGKILL included), and it kills the groups and removes the folders held then.
_WATCHDOG = """\
import json, os, signal, sys
for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
    signal.signal(s, signal.SIG_IGN)
if os.fork():
    os._exit(0)
held = {"group": set(), "temp": set()}
for line in sys.stdin.buffer:
    try:
        kind, added, value = json.loads(line)
        (held[kind].add if added else held[kind].discard)(value)
    except (ValueError, KeyError, TypeError):
        pass
def kill():
    for pgid in held["group"]:
        for k in (os.killpg, os.kill):
            try:
                k(pgid, signal.SIGKILL)
            except OSError:
                pass
import shutil
kill()
for path in held["temp"]:
    shutil.rmtree(path, ignore_errors=True)
kill()
"""
_watchdog: dict[str, int] = {}  # this process's watchdog: "pid" (the process it watches), "fd" (the pipe's write end)


def _start_watchdog() -> None:
    """Start this process's watchdog (OSError if it cannot): the only clean-up a caller killed by SIGKILL gets."""
    read, write = os.pipe()  # not inherited across exec: this process holds the only write end
    try:
        first = subprocess.Popen([sys.executable, "-I", "-S", "-c", _WATCHDOG, str(os.getpid())], stdin=read,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd="/", start_new_session=True)
        if first.wait() != 0:  # it ends once the watchdog is forked off
            raise OSError(f"the planner watchdog could not start (exit code {first.returncode})")
    except BaseException:
        os.close(write)
        raise
    finally:
        os.close(read)
    os.set_blocking(write, False)  # a watchdog that stopped reading must not stall the planner calls
    _watchdog.update(pid=os.getpid(), fd=write)


def _tell_watchdog(kind: str, added: bool, value: int | str) -> None:
    """Pass one registry change on to this process's watchdog, started by the first addition (under _lock)."""
    if _watchdog.get("pid") != os.getpid():
        if not added:
            return
        _start_watchdog()
    with contextlib.suppress(OSError):  # one short write: atomic on a pipe; a watchdog killed from outside is gone
        os.write(_watchdog["fd"], (json.dumps([kind, added, value]) + "\n").encode())


def _drop_inherited_watchdog() -> None:
    """In a forked child: close the parent's pipe, so the parent's death still reaches its watchdog at once."""
    fd = _watchdog.pop("fd", None)
    _watchdog.pop("pid", None)
    if fd is not None:
        with contextlib.suppress(OSError):
            os.close(fd)


def _track(kind: str, value: int | str, added: bool) -> None:
    """Add a process group ("group") or a temporary folder ("temp") to the registry or drop it, here and in the
    watchdog."""
    with _lock:
        registry = _GROUPS if kind == "group" else _TEMPS
        (registry.add if added else registry.discard)(value)
        _tell_watchdog(kind, added, value)


@contextlib.contextmanager
def temp_dir(prefix: str) -> Iterator[Path]:
    """A fresh temporary folder, removed on exit, by the signal path, at interpreter exit and by the watchdog."""
    path = tempfile.mkdtemp(prefix=prefix)
    try:
        _track("temp", path, True)
        yield Path(path)
    finally:
        shutil.rmtree(path, ignore_errors=True)
        _track("temp", path, False)


def run_group(args: Sequence[str], stdin_text: str, timeout_s: float, *, cwd: Path,
              after_start: Callable[[int], None] | None = None) -> tuple[int | None, str, str, bool]:
    """Run an argument list (no shell) in its own process group with a wall-clock limit.

    Returns (exit code, stdout, stderr, timed out); at the limit, and on any exception, the
    whole group is killed, and this process's watchdog kills it if this process dies first (SIGKILL
    included). OSError if the program, or the watchdog, cannot be started.
    """
    proc = subprocess.Popen(list(map(str, args)), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd, start_new_session=True)
    try:
        register_group(proc.pid)
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


MEMORY_LIMIT_MB = 4096  # a planner process's address space, by default


def limit_memory(pid: int, mb: int) -> None:
    """Cap the address space of a started process (after the start, so Python can vfork); a no-op off Linux or
    once it has ended."""
    try:
        import resource

        resource.prlimit(pid, resource.RLIMIT_AS, (mb << 20, mb << 20))
    except (ImportError, AttributeError, OSError, ProcessLookupError):  # not Linux, or it already ended
        pass


atexit.register(cleanup)
os.register_at_fork(after_in_child=_drop_inherited_watchdog)
