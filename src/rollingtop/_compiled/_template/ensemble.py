"""The parallel ensemble kernel of one contact model: many trajectories in parallel on all cores
(numba ``prange``), each with its own adaptive steps and work arrays.

The driver (threads, the stop flag, progress):
:func:`rollingtop.integrate.ensemble.integrate_batch`.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled._flags import STOP_POLL_STEPS, read_flag
from rollingtop._compiled._kernel import new_workspace
from rollingtop._compiled._template.stepper import run, start
from rollingtop._jit import compiled
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray


@compiled()
def integrate_one(
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
    ev_spec = np.zeros(2, dtype=np.int64)
    # the event code read from the array: a literal 0 would compile a second start
    ctrl, counts, track = start(code, p, y, f, t_eval, rtol, atol, ev_spec[0], out, ytmp, ynew,
                                ws)  # fmt: skip
    ev_t = np.zeros(1)
    ev_y = np.zeros((1, n))
    while True:
        if read_flag(stop) != 0:
            status = dop.INTERRUPTED
            break
        budget = min(STOP_POLL_STEPS, max_steps - counts[dop.STEPS])
        status = run(code, p, y, f, ctrl, counts, track, t_eval, out, ev_spec, ev_t, ev_y,
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
    for k in prange(Y0.shape[0]):
        if read_flag(stop) != 0:
            stats[k, 0] = dop.INTERRUPTED
        else:
            integrate_one(codes[k], P[k], Y0[k], t_eval, rtol, atol, max_steps, out[k],
                           final[k], stats[k], stop)  # fmt: skip
