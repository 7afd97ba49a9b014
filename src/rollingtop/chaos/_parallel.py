"""Compiled batches of the chaos tools, run on all cores (numba ``prange``) from a worker thread.

As :mod:`rollingtop.integrate.ensemble` does: the parallel kernel runs without the GIL in a
worker thread while the calling thread waits in short slices, so that its signal handlers run;
on any exception there a stop flag is raised, which every trajectory polls, and the exception
propagates once the worker has stopped.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from rollingtop._jit import call
from rollingtop._types import IntArray
from rollingtop.integrate.ensemble import WAIT_SLICE

__all__ = ["run_threaded", "thread_count"]


def thread_count(threads: int | None) -> int:
    """Threads a batch uses: ``threads`` (at most numba's), else numba's current number."""
    import numba  # on first use: importing it is a sixth of a second

    if threads is None:
        return int(numba.get_num_threads())
    # numba.config sets its options at run time (no stubs)
    most: int = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
    return max(1, min(int(threads), most))


def run_threaded(
    batch: Callable[..., None],
    args: tuple[Any, ...],
    threads: int | None,
    poll: Callable[[], None] | None = None,
) -> tuple[float, int]:
    """Call the compiled ``batch(*args, stop)`` in a worker thread; returns the seconds it took
    and the threads used. ``stop`` is an int64 flag array the kernel polls; ``poll()``, if
    given, is called in the calling thread after each wait of ``WAIT_SLICE`` seconds (to report
    progress from what the kernel has written so far)."""
    import numba  # on first use: importing it is a sixth of a second

    stop: IntArray = np.zeros(1, dtype=np.int64)
    n_threads = thread_count(threads)
    failure: list[BaseException] = []

    def work() -> None:
        try:
            numba.set_num_threads(n_threads)
            with numba.parallel_chunksize(1):
                call(batch, *args, stop)
        except BaseException as exc:  # pragma: no cover - re-raised in the calling thread
            failure.append(exc)

    start = time.perf_counter()
    worker = threading.Thread(target=work, name="rollingtop-chaos", daemon=True)
    worker.start()
    try:
        while worker.is_alive():
            worker.join(WAIT_SLICE)
            if poll is not None:
                poll()
    except BaseException:
        stop[0] = 1
        worker.join()
        raise
    if failure:
        raise failure[0]
    return time.perf_counter() - start, n_threads
