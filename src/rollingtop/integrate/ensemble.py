"""Ensembles: many trajectories integrated in parallel on all cores (numba ``prange``).

Each trajectory keeps its own adaptive steps (the same compiled stepper as a single run, with its
own work arrays); memory is bounded by what is kept: final states, statistics, and samples only
when asked for.

The parallel kernel runs in a worker thread without the GIL, while the calling thread waits in
short slices (:data:`WAIT_SLICE`), so that its signal handlers run (Python runs them in the main
thread only, between bytecodes). On any exception there (Ctrl-C, SIGTERM, an error in the
progress callback) it raises a stop flag, which every trajectory polls each
:data:`STOP_POLL_STEPS` accepted steps, waits for the worker, and re-raises: the kernel stops
within milliseconds, whatever the length of a trajectory. Polling only splits the stepper's loop
into calls, which does not change the steps.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any, cast

import numba
import numpy as np
from numba import prange, types
from numba.extending import intrinsic
from numpy.typing import ArrayLike

from rollingtop._jit import call, compiled
from rollingtop._types import FloatArray, IntArray
from rollingtop.dynamics._kernel import new_workspace
from rollingtop.dynamics._layout import N_PARAMS, N_STATE, WARMUP_PARAMS
from rollingtop.integrate import _dop853 as dop

__all__ = ["integrate_batch", "compile_ensemble"]

#: Trajectories per call of the parallel kernel when a progress callback is given.
BATCH = 256
#: Trajectories per chunk handed to a thread. numba's default splits the loop into one
#: contiguous block per thread up front; trajectories differ in cost (a grid of initial states
#: runs from cheap to dear), so small chunks taken on demand keep every core busy to the end.
CHUNK = 4
#: Accepted steps of a trajectory between two looks at the stop flag (about a millisecond).
STOP_POLL_STEPS = 1000
#: Seconds the calling thread waits for the worker at a time (its signal handlers run between).
WAIT_SLICE = 0.05


@intrinsic
def _read_flag_intrinsic(typingctx: Any, flag: types.Type) -> Any:
    """``flag[0]`` of an int64 array, by an atomic (relaxed) load: another thread sets it while
    a compiled loop runs, and a plain load could be hoisted out of that loop by the compiler.

    The arguments are numba's typing context and the argument's numba type; the result is the
    signature and the code generator (``None``: not an int64 array)."""
    if not (isinstance(flag, types.Array) and flag.dtype == types.int64):
        return None

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        array = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.load_atomic(array.data, "monotonic", 8)

    return types.int64(flag), codegen


#: What :func:`_read_flag_intrinsic` is in compiled code. numba's stubs type an intrinsic's call
#: with its typing function's parameters (the typing context included) and as never returning.
_read_flag = cast(Callable[[IntArray], int], _read_flag_intrinsic)


@compiled()
def _integrate_one(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    out: FloatArray,
    final: FloatArray,
    stats: FloatArray,
    stop: IntArray,
) -> None:
    """Integrate one trajectory; ``out`` (len(t_eval), 18) samples, ``final`` (18,) state,
    ``stats`` (6,): status (``dop.FINISHED``, a failure code, ``dop.BUDGET_EXHAUSTED`` for
    ``max_steps`` accepted steps, ``dop.INTERRUPTED`` when ``stop[0]`` was set), steps,
    rejected, rhs evaluations, min normal force, max friction ratio."""
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
    while True:
        if _read_flag(stop) != 0:
            status = dop.INTERRUPTED
            break
        budget = min(STOP_POLL_STEPS, max_steps - counts[dop.STEPS])
        status = dop.run(code, p, y, f, ctrl, counts, track, t_eval, out, ev_spec, ev_t, ev_y,
                         budget, K, ynew, ytmp, y_old, Fd, ws)  # fmt: skip
        if status != dop.BUDGET_EXHAUSTED or counts[dop.STEPS] >= max_steps:
            break
    for i in range(n):
        final[i] = y[i]
    stats[0] = status
    stats[1] = counts[dop.STEPS]
    stats[2] = counts[dop.REJECTED]
    stats[3] = counts[dop.NFEV]
    stats[4] = track[dop.MIN_NORMAL]
    stats[5] = track[dop.MAX_RATIO]


@compiled(parallel=True, nogil=True)
def _batch(
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
    for k in prange(Y0.shape[0]):
        if _read_flag(stop) != 0:
            stats[k, 0] = dop.INTERRUPTED
        else:
            _integrate_one(codes[k], P[k], Y0[k], t_eval, rtol, atol, max_steps, out[k],
                           final[k], stats[k], stop)  # fmt: skip


_compiled = False


def compile_ensemble() -> float:
    """Compile (or load from the cache) the parallel kernel; seconds spent (0 when done)."""
    global _compiled
    if _compiled:
        return 0.0
    start = time.perf_counter()
    y = np.zeros((1, N_STATE))
    y[0, 6:15] = (1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8)
    P = np.array([WARMUP_PARAMS])
    call(_batch, np.zeros(1, dtype=np.int64), P, y, np.array([0.0, 1e-3]), 1e-6, 1e-9, 10,
           np.zeros((1, 2, N_STATE)), np.zeros((1, N_STATE)), np.zeros((1, 6)),
           np.zeros(1, dtype=np.int64))  # fmt: skip
    _compiled = True
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
        Kernel code of each trajectory.
    params : ndarray, shape (N, 9)
        Body parameters of each trajectory.
    states : ndarray, shape (N, 18)
        Constraint-consistent initial states.
    t_eval : ndarray, shape (n,)
        Sample times shared by all (``[t0, t_end]`` keeps only the ends).
    threads : int, optional
        Threads to use (default: numba's, all cores).
    progress : callable, optional
        ``progress(done, N)`` now and then as batches of :data:`BATCH` trajectories finish
        (called in the calling thread), and ``progress(N, N)`` at the end.

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
        :data:`STOP_POLL_STEPS` steps and the exception propagates; no result is returned.
    """
    states = np.ascontiguousarray(states, dtype=float)
    N = states.shape[0]
    codes = np.ascontiguousarray(codes, dtype=np.int64)
    params = np.ascontiguousarray(params, dtype=float)
    if params.shape != (N, N_PARAMS) or codes.shape != (N,):  # the kernels do not check reads
        raise ValueError(f"params must have shape ({N}, {N_PARAMS}) and codes ({N},), got "
                         f"{params.shape} and {codes.shape}")  # fmt: skip
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    out = np.full((N, t_eval.size, N_STATE), np.nan)
    final = np.full((N, N_STATE), np.nan)
    stats = np.zeros((N, 6))
    # numba's thread count is per thread: the worker takes the caller's (or ``threads``)
    n_threads = numba.get_num_threads()
    if threads is not None:
        # numba.config sets its options at run time (no stubs)
        max_threads: int = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
        n_threads = max(1, min(int(threads), max_threads))
    step = N if progress is None else BATCH
    stop = np.zeros(1, dtype=np.int64)
    done = [0]  # trajectories finished, written by the worker
    failure: list[BaseException] = []

    def work() -> None:
        try:
            numba.set_num_threads(n_threads)
            for lo in range(0, N, step):
                hi = min(N, lo + step)
                with numba.parallel_chunksize(CHUNK):
                    call(_batch, codes[lo:hi], params[lo:hi], states[lo:hi], t_eval, rtol, atol,
                           max_steps, out[lo:hi], final[lo:hi], stats[lo:hi], stop)  # fmt: skip
                if stop[0]:
                    return
                done[0] = hi
        except BaseException as exc:  # pragma: no cover - re-raised in the calling thread
            failure.append(exc)

    start = time.perf_counter()
    worker = threading.Thread(target=work, name="rollingtop-ensemble", daemon=True)
    worker.start()
    reported = 0
    try:
        while worker.is_alive():
            worker.join(WAIT_SLICE)
            if progress is not None and reported < done[0] < N:
                reported = done[0]
                progress(reported, N)
    except BaseException:
        stop[0] = 1  # every trajectory sees it within STOP_POLL_STEPS steps
        worker.join()
        raise
    wall = time.perf_counter() - start
    if failure:
        raise failure[0]
    if progress is not None:
        progress(N, N)
    return out, final, stats, wall
