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
from collections.abc import Callable
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled import by_package, for_code, packages_of
from rollingtop._jit import call
from rollingtop._layout import N_PARAMS, N_STATE
from rollingtop._types import FloatArray, IntArray
from rollingtop.contact import DEFAULT_MODEL, ContactModel
from rollingtop.integrate._held import none_held
from rollingtop.integrate._rows import Rows, loop_args, work_arrays
from rollingtop.integrate._threads import run_rows
from rollingtop.integrate.driver import compile_code

__all__ = ["integrate_batch", "compile_ensemble", "compile_ensemble_code"]

#: Trajectories per chunk handed to a thread (:func:`rollingtop.integrate._threads.run_rows`):
#: trajectories differ in cost (a grid of initial states runs from cheap to dear), so small
#: chunks taken on demand keep every core busy to the end.
CHUNK = 4

_lock = threading.Lock()


def compile_ensemble(model: str | ContactModel = DEFAULT_MODEL, *, variants: bool = False) -> float:
    """Compile (or load from the cache) the compiled loop ``model``'s ensembles run -- a single
    run's, :func:`rollingtop.integrate.driver.compile_kernels` -- and no other model's; seconds
    spent (0 when done in this process). ``variants``: also its variants' (their own
    compiled package, :data:`rollingtop._compiled.GROUPS`)."""
    return sum(_compile_package(kernels) for kernels in packages_of(model, variants=variants))


def compile_ensemble_code(code: int) -> float:
    """:func:`compile_ensemble` for the package that runs kernel code ``code``; seconds spent.
    An ensemble runs the single run's compiled loop (:func:`.driver.compile_code`), so after a
    single run of the package there is nothing left to compile."""
    return _compile_package(for_code(int(code)))


def _compile_package(kernels: ModuleType) -> float:
    with _lock:  # Dask runs tasks in threads: one compilation of a package per process
        return compile_code(kernels._dispatch.CODES[0])


def _batch(kernels: ModuleType) -> Callable[..., None]:
    """The batch that :func:`rollingtop.integrate._threads.run_rows` calls on each chunk of
    trajectories of ``kernels``' package: their rows and work arrays, then the plain stepper's
    compiled loop over them (``stepper.run_rows``, without the GIL), each run to its end or
    ``max_steps`` accepted steps, the stop flag read every ``STOP_POLL_STEPS`` steps; then the final
    states and statistics."""
    from rollingtop._compiled._flags import STOP_POLL_STEPS  # here: _flags imports numba

    run_rows = kernels.stepper.run_rows

    def batch(
        codes: IntArray,
        P: FloatArray,
        Y0: FloatArray,
        t_eval: FloatArray,
        rtol: float,
        atol: float,
        max_steps: int,
        out: FloatArray,
        final: FloatArray,
        stats: FloatArray,
        stop: IntArray,
    ) -> None:
        row = Rows.of(Y0)
        w = work_arrays()
        events = (_EV_SPEC, _NO_EVENTS, _NO_EVENT_STATES)
        call(run_rows, *loop_args(codes, P, row, t_eval, out, (rtol, atol), events,
                                  (max_steps, STOP_POLL_STEPS), w, _NO_HELD, stop))  # fmt: skip
        started = row.COUNTS[:, dop.NEXT_SAMPLE] > 0  # a row left by a stop keeps NaN
        final[started] = row.Y[started]
        stats[:, 0] = row.STATUS
        stats[started, 1] = row.COUNTS[started, dop.STEPS]
        stats[started, 2] = row.COUNTS[started, dop.REJECTED]
        stats[started, 3] = row.COUNTS[started, dop.NFEV]
        stats[started, 4] = row.TRACK[started, dop.MIN_NORMAL]
        stats[started, 5] = row.TRACK[started, dop.MAX_RATIO]

    return batch


#: The arguments of the compiled loop that an ensemble does not use (read only): no event
#: (the normal force's minima inside steps located, as a single run does), no integral held.
_EV_SPEC = np.array([0, 0, 1], dtype=np.int64)
_NO_EVENTS = np.empty(1)
_NO_EVENT_STATES = np.empty((1, N_STATE))
_NO_HELD = none_held()  # the single run's types


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
            _batch(kernels),
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
