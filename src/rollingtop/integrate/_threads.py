"""Run a compiled batch kernel over the rows of its arrays on several threads.

The batch kernels (the ensemble's, the section's, the chaos indicators') are serial loops over
their rows, compiled with ``nogil=True``: this module hands them chunks of rows from a
:class:`concurrent.futures.ThreadPoolExecutor`, and the chunks run in parallel, each without the
GIL. It is numba's own recipe for multithreading compiled code (its documentation's
"Multi-threading" example) and replaces ``prange``: a ``parallel=True`` batch cost 2.5 to 3.5 s
more to compile per model (7 packages: 18 s of every first run), and numba's default split of
the loop into one block per thread left cores idle when trajectories differ in cost; chunks
taken on demand keep every thread busy to the end.

The calling thread waits in short slices (:data:`WAIT_SLICE`), so that its signal handlers run
(Python runs them in the main thread only, between bytecodes). On any exception there (Ctrl-C,
SIGTERM, an error in a progress callback) or in a chunk, it raises the stop flag that every
trajectory polls each ``STOP_POLL_STEPS`` accepted steps, cancels the chunks not yet started,
waits for those running, and re-raises: the kernels stop within milliseconds, whatever the
length of a trajectory.
"""

from __future__ import annotations

import concurrent.futures
import math
import os
import time
from collections.abc import Callable, Collection
from typing import Any

import numpy as np

from rollingtop._jit import call
from rollingtop._types import IntArray

__all__ = ["run_rows", "thread_count", "WAIT_SLICE"]

#: Seconds the calling thread waits for the chunks at a time (its signal handlers run between).
WAIT_SLICE = 0.05
#: At most this many chunks per thread: a chunk is enlarged beyond the caller's size for a very
#: large batch, so that the queue of pending chunks stays small.
CHUNKS_PER_THREAD = 64


def thread_count(threads: int | None) -> int:
    """Threads a batch uses: ``threads``, at most numba's thread count (``NUMBA_NUM_THREADS``,
    by default the CPUs), else numba's thread count."""
    import numba  # loaded with the kernels that run on these threads

    # numba.config sets its options at run time (no stubs)
    most: int = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
    most = max(1, int(most or os.cpu_count() or 1))
    return most if threads is None else max(1, min(int(threads), most))


def run_rows(
    batch: Callable[..., None],
    args: tuple[Any, ...],
    rows: Collection[int],
    n: int,
    *,
    threads: int | None = None,
    chunk: int = 1,
    poll: Callable[[int], None] | None = None,
) -> tuple[float, int]:
    """Call the compiled ``batch(*args, stop)`` on consecutive chunks of the ``n`` rows of the
    arguments at the positions ``rows`` (each chunk gets views of those, the other arguments
    whole), on :func:`thread_count` threads.

    Parameters
    ----------
    batch : compiled function
        A serial ``nogil`` loop over the rows it is given; it polls the int64 flag ``stop``
        (shape (1,)) and leaves a row it has not started marked as interrupted.
    args : tuple
        Its arguments but ``stop``. Those at ``rows`` have ``n`` rows; the kernel writes its
        results into them, so each must be a view of (or the) array the caller reads.
    rows : collection of int
        Positions in ``args`` of the per-row arrays.
    threads : int, optional
        Threads (:func:`thread_count`).
    chunk : int
        Rows per call of ``batch``; enlarged to keep at most :data:`CHUNKS_PER_THREAD` per
        thread.
    poll : callable, optional
        ``poll(done)`` in the calling thread after each wait of :data:`WAIT_SLICE` seconds, with
        the rows whose chunks have finished.

    Returns
    -------
    seconds : float
        Wall time of the run.
    threads : int
        Threads used.
    """
    stop: IntArray = np.zeros(1, dtype=np.int64)
    n_threads = min(thread_count(threads), max(1, n))
    size = max(1, int(chunk), math.ceil(n / (CHUNKS_PER_THREAD * n_threads)))
    positions = set(rows)

    def run(lo: int, hi: int) -> int:
        part = tuple(a[lo:hi] if i in positions else a for i, a in enumerate(args))
        call(batch, *part, stop)
        return hi - lo

    start = time.perf_counter()
    done = 0
    pool = concurrent.futures.ThreadPoolExecutor(n_threads, thread_name_prefix="rollingtop")
    try:
        pending = {pool.submit(run, lo, min(n, lo + size)) for lo in range(0, n, size)}
        while pending:
            finished, pending = concurrent.futures.wait(
                pending, WAIT_SLICE, concurrent.futures.FIRST_EXCEPTION
            )
            for future in finished:
                done += future.result()  # a chunk's exception is raised here
            if poll is not None:
                poll(done)
    except BaseException:
        stop[0] = 1  # every running trajectory sees it within STOP_POLL_STEPS steps
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return time.perf_counter() - start, n_threads
