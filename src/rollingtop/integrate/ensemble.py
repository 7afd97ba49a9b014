"""Ensembles: many trajectories integrated in parallel on all cores (numba ``prange``).

Each trajectory keeps its own adaptive steps (the same compiled stepper as a single run, with its
own work arrays); memory is bounded by what is kept: final states, statistics, and samples only
when asked for.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numba
import numpy as np
from numba import njit, prange

from rollingtop.dynamics._kernel import new_workspace
from rollingtop.dynamics._layout import N_STATE
from rollingtop.integrate import _dop853 as dop

__all__ = ["integrate_batch", "compile_ensemble"]

#: Trajectories per call of the parallel kernel when a progress callback is given.
BATCH = 256
#: Trajectories per chunk handed to a thread. numba's default splits the loop into one
#: contiguous block per thread up front; trajectories differ in cost (a grid of initial states
#: runs from cheap to dear), so small chunks taken on demand keep every core busy to the end.
CHUNK = 4


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _integrate_one(code, p, y0, t_eval, rtol, atol, max_steps, out, final, stats):
    """Integrate one trajectory; ``out`` (len(t_eval), 18) samples, ``final`` (18,) state,
    ``stats`` (6,): status, steps, rejected, rhs evaluations, min normal force, max friction
    ratio."""
    n = N_STATE
    K = np.zeros((16, n))
    ynew = np.zeros(n)
    ytmp = np.zeros(n)
    y_old = np.zeros(n)
    Fd = np.zeros((7, n))
    ws = new_workspace()
    y = y0.copy()
    f = np.zeros(n)
    ctrl, counts, track = dop.start(code, p, y, f, t_eval, rtol, atol, 0, out, ytmp, ynew, ws)
    ev_spec = np.zeros(2, dtype=np.int64)
    ev_t = np.zeros(1)
    ev_y = np.zeros((1, n))
    status = dop.run(code, p, y, f, ctrl, counts, track, t_eval, out, ev_spec, ev_t, ev_y,
                     max_steps, K, ynew, ytmp, y_old, Fd, ws)  # fmt: skip
    for i in range(n):
        final[i] = y[i]
    stats[0] = status
    stats[1] = counts[dop.STEPS]
    stats[2] = counts[dop.REJECTED]
    stats[3] = counts[dop.NFEV]
    stats[4] = track[dop.MIN_NORMAL]
    stats[5] = track[dop.MAX_RATIO]


@njit(cache=True, error_model="numpy", fastmath={"contract"}, parallel=True)
def _batch(codes, P, Y0, t_eval, rtol, atol, max_steps, out, final, stats):
    for k in prange(Y0.shape[0]):
        _integrate_one(codes[k], P[k], Y0[k], t_eval, rtol, atol, max_steps, out[k], final[k],
                       stats[k])  # fmt: skip


_compiled = False


def compile_ensemble() -> float:
    """Compile (or load from the cache) the parallel kernel; seconds spent (0 when done)."""
    global _compiled
    if _compiled:
        return 0.0
    start = time.perf_counter()
    y = np.zeros((1, N_STATE))
    y[0, 6:15] = (1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8)
    P = np.array([[1.0, 1.0, 1.0, 0.1, 0.3, 0.3, 0.5]])
    _batch(np.zeros(1, dtype=np.int64), P, y, np.array([0.0, 1e-3]), 1e-6, 1e-9, 10,
           np.zeros((1, 2, N_STATE)), np.zeros((1, N_STATE)), np.zeros((1, 6)))  # fmt: skip
    _compiled = True
    return time.perf_counter() - start


def integrate_batch(
    codes: np.ndarray,
    params: np.ndarray,
    states: np.ndarray,
    t_eval: np.ndarray,
    *,
    rtol: float,
    atol: float,
    max_steps: int = 10**7,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """Integrate ``N`` trajectories in parallel.

    Parameters
    ----------
    codes : ndarray of int, shape (N,)
        Kernel code of each trajectory.
    params : ndarray, shape (N, 7)
        Body parameters of each trajectory.
    states : ndarray, shape (N, 18)
        Constraint-consistent initial states.
    t_eval : ndarray, shape (n,)
        Sample times shared by all (``[t0, t_end]`` keeps only the ends).
    threads : int, optional
        Threads to use (default: numba's, all cores).
    progress : callable, optional
        ``progress(done, N)`` after each batch of :data:`BATCH` trajectories.

    Returns
    -------
    samples : ndarray, shape (N, n, 18)
    final : ndarray, shape (N, 18)
    stats : ndarray, shape (N, 6)
        Status (0 finished; see :mod:`._dop853`), steps, rejected steps, rhs evaluations, min
        normal force, max friction ratio (monitored at every step).
    wall : float
        Seconds in the compiled kernel.
    """
    states = np.ascontiguousarray(states, dtype=float)
    N = states.shape[0]
    codes = np.ascontiguousarray(codes, dtype=np.int64)
    params = np.ascontiguousarray(params, dtype=float)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    out = np.full((N, t_eval.size, N_STATE), np.nan)
    final = np.full((N, N_STATE), np.nan)
    stats = np.zeros((N, 6))
    previous = numba.get_num_threads()
    if threads is not None:
        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    try:
        start = time.perf_counter()
        step = N if progress is None else BATCH
        for lo in range(0, N, step):
            hi = min(N, lo + step)
            with numba.parallel_chunksize(CHUNK):
                _batch(codes[lo:hi], params[lo:hi], states[lo:hi], t_eval, rtol, atol,
                       max_steps, out[lo:hi], final[lo:hi], stats[lo:hi])  # fmt: skip
            if progress is not None:
                progress(hi, N)
        wall = time.perf_counter() - start
    finally:
        numba.set_num_threads(previous)
    return out, final, stats, wall
