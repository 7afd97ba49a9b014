"""A second process for a cold compile: half of a package's kernels compiled beside the rest.

numba compiles one function at a time, in one thread, under a global lock: a model's first run (an
empty cache) spends about 13 s on one core while the machine's others idle. Most of that time goes
to two independent halves of the integrator: the stepper's loop with what it calls (its start, the
stage sums, the dense output, the search for the normal force's dips) and the rest (the right-hand
side, the constraint projection, the samples' diagnostics). So on a cold compile :func:`forked` runs
the rest in a child process -- forked, so it shares this one's imports and starts at once -- while
this process compiles the stepper's loop; the child's functions reach this process through numba's
on-disk cache (:mod:`rollingtop._kernel_cache`), keyed on every source compiled in, so what is
loaded is what would have been compiled. Nothing depends on the child: whatever it did not save in
time is compiled here as before, and its failure is silent.

Why not a pool (``concurrent.futures``, Dask): a spawned interpreter imports numba and the
package again (about 1 s of the 5 s gained), and nothing is returned but files. Why only here:
a fork is safe where this process runs one thread (no lock can be held by a thread the child
lacks), on Linux (macOS's system libraries are not fork-safe), with a writable cache (the
child's only output) and a second CPU. Elsewhere -- a Dask worker, a notebook's kernel, the
workers of :func:`rollingtop.warmup` (:data:`ENV` is set there: they already fill the CPUs) --
the package compiles in this process alone, as before.
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Hashable
from typing import Any

from rollingtop._jit import caching_disabled

__all__ = [
    "ENV",
    "cached",
    "eligible",
    "join",
    "may_fork",
    "running",
    "start",
    "stop",
    "stop_others",
]

#: Environment variable: ``0`` compiles in one process always (the benchmarks' sequential
#: reference; :func:`rollingtop.warmup`'s workers).
ENV = "ROLLINGTOP_COMPILE_HELPER"
#: Seconds this process waits, after its own half, for the child to save the other half (about
#: as long as this process's half): a child still compiling by then is stopped, and what it has
#: not saved is compiled here.
WAIT = 60.0
#: Seconds between two looks at the child while waiting.
POLL = 0.01
#: The signals blocked across the fork (:func:`start`).
_SIGNALS = {signal.SIGINT, signal.SIGTERM}


def _cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        return os.cpu_count() or 1


def may_fork() -> bool:
    """Whether a helper may be forked here at all (module docstring): Linux, one thread, two
    CPUs or more, :data:`ENV` not ``0``. Cheap: numba is not loaded."""
    return (
        os.environ.get(ENV, "1") != "0"
        and sys.platform.startswith("linux")
        and hasattr(os, "fork")
        and threading.active_count() == 1
        and _cpus() >= 2
        and not caching_disabled()
    )


def eligible(dispatcher: Any) -> bool:
    """Whether a cold compile of ``dispatcher`` may fork a helper here: :func:`may_fork`, and an
    on-disk cache for the dispatcher (none: no folder could be written, or saving failed in this
    process)."""
    from numba.core.caching import NullCache

    return may_fork() and not isinstance(dispatcher._cache, NullCache)


def cached(dispatcher: Any, sig: tuple[Any, ...]) -> bool:
    """Whether ``dispatcher``'s overload for the argument types ``sig`` is in memory, or in
    numba's on-disk cache (its index names an entry: nothing is loaded, so the functions load
    in the order they did without a helper -- the order decides, in the last bits, which copy
    of a callee a loaded caller links to); ``False`` means a compile is ahead."""
    if tuple(sig) in dispatcher.overloads:
        return True
    cache = dispatcher._cache
    key = cache._index_key(sig, dispatcher.targetctx.codegen())
    return key in cache._cache_file._load_index()


def _child(work: Callable[[], None]) -> None:
    """The child: ``work``, silently (its output and log records would interleave with the
    parent's), then exit without the parent's cleanup (``os._exit``: no atexit handlers, no
    flushed buffers). Entered with SIGINT and SIGTERM blocked (:func:`start`)."""
    status = 1
    try:
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # Ctrl-C ends it at once
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        logging.disable(logging.CRITICAL)  # the compile notice's record is the parent's
        work()
        status = 0
    finally:
        os._exit(status)


#: The children in flight, by the key of the compile they help (a package and its stepper copy).
_children: dict[Hashable, int] = {}


def _stop(pid: int) -> None:
    """Stop the child ``pid`` and reap it; a child already reaped elsewhere (SIGCHLD ignored,
    another waiter) is not signalled: its pid may be another process's by now."""
    try:
        if os.waitpid(pid, os.WNOHANG)[0] == pid:
            return  # it had finished
    except ChildProcessError:
        return
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGKILL)  # not reaped: still our child, whatever its state
    with contextlib.suppress(ChildProcessError):
        os.waitpid(pid, 0)


def _stop_all() -> None:
    """At exit: a child still compiling is stopped (what it saved stays; the rest compiles when
    a run needs it)."""
    for key in list(_children):
        _stop(_children.pop(key))


def start(key: Hashable, work: Callable[[], None]) -> bool:
    """Run ``work`` in a forked child, the helper of the compile ``key``; whether one was
    started (not when the fork fails: a process limit, memory). Call only where
    :func:`eligible`, and while :func:`running` is false for ``key``."""
    # no signal handler may run between the fork and the child's own (it would unwind the
    # parent's frames in the child): SIGINT and SIGTERM wait until each side is ready
    signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
    try:
        with warnings.catch_warnings():  # Python >= 3.12 warns of a library's native threads
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:  # pragma: no cover - the child never returns here (coverage cannot see it)
            _child(work)
    except OSError:
        return False
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)
    if not _children:
        atexit.register(_stop_all)  # unregistered when the last child is reaped
    _children[key] = pid
    return True


def running(key: Hashable) -> bool:
    """Whether a helper of the compile ``key`` was started and not yet joined."""
    return key in _children


def _reaped(key: Hashable) -> None:
    del _children[key]
    if not _children:
        atexit.unregister(_stop_all)


def join(key: Hashable) -> None:
    """Wait for the helper of ``key`` (at most :data:`WAIT` seconds, then it is stopped)."""
    pid = _children[key]
    deadline = time.monotonic() + WAIT
    try:
        while time.monotonic() < deadline:
            try:
                if os.waitpid(pid, os.WNOHANG)[0] == pid:
                    return
            except ChildProcessError:  # reaped elsewhere (SIGCHLD ignored): it has ended
                return
            time.sleep(POLL)
        _stop(pid)
    except BaseException:  # Ctrl-C while waiting: the child is stopped at once
        _stop(pid)
        raise
    finally:
        _reaped(key)


def stop(key: Hashable) -> None:
    """Stop the helper of ``key`` at once (its caller failed or was interrupted)."""
    if key in _children:
        _stop(_children[key])
        _reaped(key)


def stop_others(key: Hashable) -> None:
    """Stop every helper but that of ``key`` (a run of another package: two helpers and this
    process would share two CPUs three ways)."""
    for other in [k for k in _children if k != key]:
        stop(other)
