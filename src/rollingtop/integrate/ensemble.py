"""Ensembles: many trajectories integrated in parallel on all cores (threads running a compiled
``nogil`` kernel chunk by chunk, :mod:`rollingtop.integrate._threads`).

Each trajectory keeps its own adaptive steps (the same compiled stepper as a single run, with its
own work arrays); memory is bounded by what is kept: final states, statistics, and samples only
when asked for.

The kernel runs without the GIL on worker threads, while the calling thread waits in short
slices, so that its signal handlers run (Python runs them in the main thread only, between
bytecodes). On any exception there (Ctrl-C, SIGTERM, an error in the progress callback) it
raises a stop flag, which every trajectory polls each ``STOP_POLL_STEPS`` accepted steps, waits
for the threads, and re-raises: the kernel stops within milliseconds, whatever the length of a
trajectory. Polling only splits the stepper's loop into calls, which does not change the steps.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import by_package, compiling, for_code, packages_of
from rollingtop._jit import call
from rollingtop._layout import N_PARAMS, N_STATE, WARMUP_PARAMS
from rollingtop._types import FloatArray
from rollingtop.contact import DEFAULT_MODEL, ContactModel
from rollingtop.integrate._threads import run_rows

__all__ = ["integrate_batch", "compile_ensemble", "compile_ensemble_code"]

#: Trajectories per chunk handed to a thread (:func:`rollingtop.integrate._threads.run_rows`):
#: trajectories differ in cost (a grid of initial states runs from cheap to dear), so small
#: chunks taken on demand keep every core busy to the end.
CHUNK = 4

_compiled: set[str] = set()
_lock = threading.Lock()


def compile_ensemble(model: str | ContactModel = DEFAULT_MODEL, *, variants: bool = False) -> float:
    """Compile (or load from the cache) ``model``'s parallel kernel, and no other model's;
    seconds spent (0 when done in this process). ``variants``: also its variants' (their own
    compiled package, :data:`rollingtop._compiled.GROUPS`)."""
    return sum(_compile_package(kernels) for kernels in packages_of(model, variants=variants))


def compile_ensemble_code(code: int) -> float:
    """:func:`compile_ensemble` for the package that runs kernel code ``code``; seconds spent
    (the integration's own compile: :func:`integrate_batch` does it, untimed, where needed)."""
    return _compile_package(for_code(int(code)))


def _compile_package(kernels: ModuleType) -> float:
    with _lock:  # Dask runs tasks in threads: one compilation of a package per process
        return _compile_package_locked(kernels)


def _compile_package_locked(kernels: ModuleType) -> float:
    if kernels.PACKAGE in _compiled:
        return 0.0
    start = time.perf_counter()
    y = np.zeros((1, N_STATE))
    y[0, 6:15] = (1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8)
    P = np.array([WARMUP_PARAMS])
    codes = np.full(1, kernels._dispatch.CODES[0], dtype=np.int64)
    with compiling(kernels, "ensemble"):
        call(
            kernels.ensemble.batch,
            codes,
            P,
            y,
            np.array([0.0, 1e-3]),
            1e-6,
            1e-9,
            10,
            np.zeros((1, 2, N_STATE)),
            np.zeros((1, N_STATE)),
            np.zeros((1, 6)),
            np.zeros(1, dtype=np.int64),
        )
    _compiled.add(kernels.PACKAGE)
    return time.perf_counter() - start


def integrate_batch(
    codes: ArrayLike,
    params: ArrayLike,
    states: ArrayLike,
    t_eval: ArrayLike,
    *,
    rtol: float,
    atol: float,
    max_steps: int = 10**7,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """Integrate ``N`` trajectories in parallel.

    Parameters
    ----------
    codes : ndarray of int, shape (N,)
        Kernel code of each trajectory. Trajectories of several models are run model by model,
        each by its own compiled kernel (:func:`compile_ensemble` compiles it first).
    params : ndarray, shape (N, 9)
        Body parameters of each trajectory.
    states : ndarray, shape (N, 18)
        Constraint-consistent initial states.
    t_eval : ndarray, shape (n,)
        Sample times shared by all (``[t0, t_end]`` keeps only the ends).
    threads : int, optional
        Threads to use (default: numba's thread count, ``NUMBA_NUM_THREADS``: all cores).
    progress : callable, optional
        ``progress(done, N)`` now and then as chunks of trajectories finish (called in the
        calling thread), and ``progress(N, N)`` at the end.

    Returns
    -------
    samples : ndarray, shape (N, n, 18)
    final : ndarray, shape (N, 18)
    stats : ndarray, shape (N, 6)
        Status (0 finished, 1 ``max_steps`` accepted steps reached, -1 step size underflow, -2
        non-finite state, -3 too many rejected steps in a row: ``_dop853.STATUS_NAMES``),
        steps, rejected steps, rhs evaluations, min normal force, max friction ratio (monitored
        at every step).
    wall : float
        Seconds in the compiled kernel.

    Raises
    ------
    KeyboardInterrupt
        (or any exception raised in the calling thread while it waits, such as
        :class:`rollingtop._errors.Interrupted` from a signal): the trajectories stop within
        ``STOP_POLL_STEPS`` steps and the exception propagates; no result is returned.
    """
    states = np.ascontiguousarray(states, dtype=float)
    N = states.shape[0]
    codes = np.ascontiguousarray(codes, dtype=np.int64)
    params = np.ascontiguousarray(params, dtype=float)
    if params.shape != (N, N_PARAMS) or codes.shape != (N,):  # the kernels do not check reads
        raise ValueError(
            f"params must have shape ({N}, {N_PARAMS}) and codes ({N},), got "
            f"{params.shape} and {codes.shape}"
        )
    groups = by_package(codes)  # ValueError for an unknown code
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    out = np.full((N, t_eval.size, N_STATE), np.nan)
    final = np.full((N, N_STATE), np.nan)
    stats = np.zeros((N, 6))
    wall = 0.0
    before = 0  # trajectories of the packages already run
    reported = [0]

    def poll(done: int) -> None:
        if progress is not None and reported[0] < before + done < N:
            reported[0] = before + done
            progress(reported[0], N)

    # package by package (a model, or its variants), each by its own compiled kernel (compiled
    # here, in the calling thread, before the threads start)
    for kernels, idx in groups:
        _compile_package(kernels)
        contiguous = idx.size == idx[-1] - idx[0] + 1
        rows = slice(idx[0], idx[-1] + 1) if contiguous else idx
        # a slice is a view the kernel writes into; fancy indexing is a copy, written back
        part = out[rows], final[rows], stats[rows]
        seconds, _ = run_rows(
            kernels.ensemble.batch,
            (codes[rows], params[rows], states[rows], t_eval, rtol, atol, max_steps, *part),
            (0, 1, 2, 7, 8, 9),
            idx.size,
            threads=threads,
            chunk=CHUNK,
            poll=poll,
        )
        wall += seconds
        if not contiguous:
            out[rows], final[rows], stats[rows] = part
        before += idx.size
    if progress is not None:
        progress(N, N)
    return out, final, stats, wall
