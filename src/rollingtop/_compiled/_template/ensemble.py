"""The ensemble kernel of one contact model: a serial ``nogil`` loop over trajectories, each with
its own adaptive steps and work arrays, run in parallel chunk by chunk on threads
(:func:`rollingtop.integrate._threads.run_rows`).

The driver (threads, the stop flag, progress):
:func:`rollingtop.integrate.ensemble.integrate_batch`.
"""

from __future__ import annotations

import numpy as np

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled._flags import STOP_POLL_STEPS, read_flag
from rollingtop._compiled._kernel import new_workspace
from rollingtop._compiled._template.stepper import run, start
from rollingtop._jit import compiled
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray


@compiled(nogil=True)
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
    """Integrate each row of ``Y0`` (N, 18) with the parameters ``P[k]`` under kernel
    ``codes[k]``; ``out`` (N, len(t_eval), 18) samples, ``final`` (N, 18) states, ``stats``
    (N, 6): status (``dop.FINISHED``, a failure code, ``dop.BUDGET_EXHAUSTED`` for
    ``max_steps`` accepted steps, ``dop.INTERRUPTED`` when ``stop[0]`` was set), steps,
    rejected, rhs evaluations, min normal force, max friction ratio.

    One function, the loop and a trajectory's run together: the stepper's code is optimised
    once more for each compiled function that contains it, so a function per trajectory cost
    a second more of every first run per model."""
    n = N_STATE
    K = np.zeros((16, n))
    ynew = np.zeros(n)
    ytmp = np.zeros(n)
    y_old = np.zeros(n)
    Fd = np.zeros((7, n))
    ws = new_workspace()
    y = np.zeros(n)
    f = np.zeros(n)
    ev_spec = np.zeros(dop.N_EV_SPEC, dtype=np.int64)
    ev_spec[dop.EV_DIPS] = 1  # the normal force's minima inside steps located, as a single run does
    ev_t = np.zeros(1)
    no_codes = np.zeros(0, dtype=np.int64)  # no projection onto the integrals here
    no_targets = np.zeros(0)
    no_work = np.zeros((1, 8))
    ev_y = np.zeros((1, n))
    for k in range(Y0.shape[0]):
        if read_flag(stop) != 0:
            stats[k, 0] = dop.INTERRUPTED
            continue
        for i in range(n):
            y[i] = Y0[k, i]
            f[i] = 0.0
        p = P[k]
        code = codes[k]
        # the event code read from the array: a literal 0 would compile a second start
        ctrl, counts, track = start(
            code, p, y, f, t_eval, rtol, atol, ev_spec[0], out[k], ytmp, ynew, ws
        )
        while True:
            if read_flag(stop) != 0:
                status = dop.INTERRUPTED
                break
            budget = min(STOP_POLL_STEPS, max_steps - counts[dop.STEPS])
            status = run(
                code,
                p,
                y,
                f,
                ctrl,
                counts,
                track,
                t_eval,
                out[k],
                ev_spec,
                ev_t,
                ev_y,
                budget,
                K,
                ynew,
                ytmp,
                y_old,
                Fd,
                ws,
                no_codes,
                no_targets,
                no_work,
            )
            if status != dop.BUDGET_EXHAUSTED or counts[dop.STEPS] >= max_steps:
                break
        for i in range(n):
            final[k, i] = y[i]
        stats[k, 0] = status
        stats[k, 1] = counts[dop.STEPS]
        stats[k, 2] = counts[dop.REJECTED]
        stats[k, 3] = counts[dop.NFEV]
        stats[k, 4] = track[dop.MIN_NORMAL]
        stats[k, 5] = track[dop.MAX_RATIO]
