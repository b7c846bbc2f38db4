"""Ray, the optional engine that runs collection shards and benchmark rows past one machine.

Ray is an extra (`pip install symlearn[ray]`) and is imported only here, inside functions, so the
package works without it. `ray_session` joins a cluster (`address`), reuses a Ray this process already
started (tests start one for many calls), or starts a local one of `num_cpus` CPUs; it shuts down only
what it started. `as_finished` hands task results back as they finish with at most `window` tasks in
flight, so the object store never holds more than `window` results, and cancels what is left when the
caller stops early (an error, Ctrl-C): the driver writes every result, so a kill loses only unfinished
tasks and the local engine's resume finishes the job. Ray itself keeps its session files under its own
temp folder (/tmp/ray by default); see docs/SCALING.md.

    >>> with ray_session(None, num_cpus=2) as ray:                                    # doctest: +SKIP
    ...     for key, value in as_finished(ray, square, [(i, (i,)) for i in range(4)], window=2):
    ...         print(key, value)
"""
from __future__ import annotations

import contextlib
import signal
import threading
from typing import Any, Callable, Iterable, Iterator

ENGINES = ("local", "ray")
INSTALL_HINT = "pip install symlearn[ray]"


class EngineError(RuntimeError):
    """An engine that cannot be used here (Ray not installed, a bad engine name or address)."""


class EngineInterrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM reached the driver of a Ray session: the session's tasks are cancelled and the Ray it
    started is shut down. Without a message, so the CLI ends as on a local engine's Ctrl-C, with 128 + signum."""

    def __init__(self, signum: int) -> None:
        super().__init__()
        self.signum = signum


def _interrupter(received: list[int]) -> Callable[[int, Any], None]:
    """A session's handler of SIGINT and SIGTERM: it notes the signal in `received` (ray.wait turns the exception
    into a plain KeyboardInterrupt), ignores later ones, so they cannot cut the clean-up short, and raises
    EngineInterrupted."""
    def interrupt(signum: int, frame: Any) -> None:
        received.append(signum)
        for s in (signal.SIGINT, signal.SIGTERM):
            signal.signal(s, signal.SIG_IGN)
        raise EngineInterrupted(signum)

    return interrupt


def _set_handlers(handlers: dict, interrupt: Callable[[int, Any], None] | None) -> None:
    """Put back the caller's handlers (signal -> handler) or, with `interrupt`, a session's: the caller's own handler
    or SIG_IGN as it was, else `interrupt` (for SIG_DFL and Python's default SIGINT handler)."""
    for s, h in handlers.items():
        own = h == signal.SIG_IGN or (callable(h) and h is not signal.default_int_handler)
        if interrupt is not None:
            signal.signal(s, h if own else interrupt)
        elif h is not None:  # None: a handler not set from Python, which cannot be put back
            signal.signal(s, h)


def check_engine(engine: str, address: str | None = None) -> None:
    """Refuse an unknown engine, an address without Ray, or Ray when it is not installed; one line each."""
    if engine not in ENGINES:
        raise EngineError(f"unknown engine {engine!r}; known: {', '.join(ENGINES)}")
    if address is not None and engine != "ray":
        raise EngineError(f"address {address!r} joins a Ray cluster; it needs the ray engine (--ray ADDRESS)")
    if engine == "ray":
        import_ray()


def import_ray():
    """The `ray` module, or an EngineError saying how to install it (the import is the first Ray work done)."""
    try:
        import ray
    except ImportError:
        raise EngineError(f"--ray needs Ray, which is not installed; {INSTALL_HINT}") from None
    return ray


@contextlib.contextmanager
def ray_session(address: str | None, num_cpus: int) -> Iterator[Any]:
    """Yield the `ray` module, connected: to `address` (a cluster's head, "auto" for the local node's cluster),
    to the Ray this process already started, or to a new local Ray of `num_cpus` CPUs. What it started it shuts down.
    """
    ray = import_ray()
    if ray.is_initialized():
        yield ray
        return
    kwargs: dict = {"address": address} if address else {"num_cpus": num_cpus}
    main = threading.current_thread() is threading.main_thread()
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)} if main else {}
    received: list[int] = []  # the signals this session's handler caught
    try:
        ray.init(include_dashboard=False, log_to_driver=False, configure_logging=False, **kwargs)
    except (ConnectionError, ValueError, RuntimeError) as e:
        where = f"the Ray cluster at {address!r}" if address else "a local Ray"
        raise EngineError(f"could not start or join {where}: {str(e).splitlines()[0] if str(e) else type(e).__name__}"
                          ) from None
    finally:
        # ray.init makes SIGTERM a sys.exit, and Ray's core a logged abort (exit code 134): a handler the caller
        # set (collect's, which ends in a resumable CollectInterrupted) is put back, and where it had none, SIGINT
        # and SIGTERM raise EngineInterrupted. Either way the stack unwinds: tasks are cancelled (a Ray worker
        # killed in a planner call: search.processes' watchdog ends the planner), Ray shut down.
        _set_handlers(handlers, _interrupter(received) if ray.is_initialized() else None)
    try:
        yield ray
    except KeyboardInterrupt as e:
        if received and not isinstance(e, EngineInterrupted):
            raise EngineInterrupted(received[0]) from None
        raise
    finally:
        ray.shutdown()
        _set_handlers(handlers, None)


def as_finished(ray, task: Callable, jobs: Iterable[tuple[Any, tuple]], window: int,
                options: dict | None = None) -> Iterator[tuple[Any, Any]]:
    """Run `task(*args)` as a Ray task for each (key, args) of `jobs`, at most `window` at once; yield (key, result)
    in the order they finish. A task's error is raised here; stopping early (an error, Ctrl-C, the caller closing the
    generator) cancels every task still in flight."""
    remote = ray.remote(task).options(**(options or {"num_cpus": 1}))
    pending: dict = {}
    jobs = iter(jobs)
    try:
        while True:
            while len(pending) < max(1, window):
                job = next(jobs, None)
                if job is None:
                    break
                key, args = job
                pending[remote.remote(*args)] = key
            if not pending:
                return
            ready, _ = ray.wait(list(pending), num_returns=1)
            ref = ready[0]
            key = pending.pop(ref)
            try:
                result = ray.get(ref)
            except ray.exceptions.RayTaskError as e:  # the task's own error, without Ray's traceback text
                cause = getattr(e, "cause", None)
                raise (cause if isinstance(cause, Exception) else e) from None
            yield key, result
    finally:
        for ref in pending:
            with contextlib.suppress(Exception):
                ray.cancel(ref, force=True)
