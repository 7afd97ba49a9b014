"""Compiled batches of one contact model: Poincare crossings of many trajectories, and the chaos
indicators of many initial states: serial ``nogil`` loops over their rows (one stepper with its
own work arrays per trajectory), run in parallel chunk by chunk on threads by
:func:`rollingtop.integrate._threads.run_rows`. Their constants:
:mod:`rollingtop._compiled._section`."""

from __future__ import annotations

import numpy as np

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled._events import W_TAU
from rollingtop._compiled._flags import STOP_POLL_STEPS, read_flag
from rollingtop._compiled._kernel import new_workspace
from rollingtop._compiled._section import NO_CROSSING, POLISH_DT, POLISH_ITERATIONS
from rollingtop._compiled._template.dynamics import project, rhs
from rollingtop._compiled._template.events import event_value
from rollingtop._compiled._template.stepper import run_rows
from rollingtop._compiled._template.tangent import run_indicators
from rollingtop._jit import compiled, kernel
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray, Workspace


@kernel
def polish_crossing(
    code: int, p: FloatArray, y: FloatArray, f: FloatArray, ytmp: FloatArray, ws: Workspace
) -> float:
    """Newton corrections ``dt = -g / g'`` of a crossing ``y`` located on the dense output
    (in place, along the flow ``y += dt y'``, then projected), so that the state lies on the
    section to round-off; returns the total time shift. The bisection leaves ``|g|`` at the
    interpolant's error (``~rtol``); the shift is of that size, and the state's own error (the
    integration's) is unchanged."""
    shift = 0.0
    for _ in range(POLISH_ITERATIONS):
        g = event_value(W_TAU, code, y)
        rhs(code, p, y, f, ws)
        for i in range(N_STATE):
            ytmp[i] = y[i] + POLISH_DT * f[i]
        g1 = event_value(W_TAU, code, ytmp)
        for i in range(N_STATE):
            ytmp[i] = y[i] - POLISH_DT * f[i]
        g2 = event_value(W_TAU, code, ytmp)
        dg = (g1 - g2) / (2.0 * POLISH_DT)
        if g == 0.0 or dg == 0.0:
            break
        dt = -g / dg
        for i in range(N_STATE):
            y[i] += dt * f[i]
        project(code, p, y, ws)
        shift += dt
    return shift


@compiled()
def section_one(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    t_max: float,
    rtol: float,
    atol: float,
    max_steps: int,
    max_gap: int,
    ev_t: FloatArray,
    ev_y: FloatArray,
    stats: FloatArray,
    stop: IntArray,
) -> None:
    """Upward zeros of the ``W_TAU`` event along one trajectory until ``len(ev_t)`` are found,
    ``t_max`` is reached, ``max_steps`` steps are taken or ``max_gap`` steps pass without a
    crossing (status ``NO_CROSSING``). ``stats``: :data:`SECTION_STATS`."""
    n = N_STATE
    K = np.zeros((16, n))
    ynew = np.zeros(n)
    ytmp = np.zeros(n)
    y_old = np.zeros(n)
    Fd = np.zeros((7, n))
    ws = new_workspace()
    # one row of the stepper's loop (``run_rows``), started by its first call
    codes = np.full(1, code, dtype=np.int64)
    P = np.empty((1, p.shape[0]))
    P[0] = p
    Y = np.empty((1, n))
    Y[0] = y0
    F = np.zeros((1, n))
    CTRL = np.zeros((1, dop.N_CTRL))
    COUNTS = np.zeros((1, dop.N_COUNTS), dtype=np.int64)
    TRACK = np.zeros((1, dop.N_TRACK))
    STATUS = np.zeros(1, dtype=np.int64)
    t_eval = np.array([0.0, t_max])
    out = np.zeros((1, 2, n))
    ev_spec = np.array([W_TAU, 1, 1], dtype=np.int64)  # rising zeros; dips located
    no_codes = np.zeros(0, dtype=np.int64)  # no projection onto the integrals here
    no_targets = np.zeros(0)
    no_work = np.zeros((1, 8))
    counts, ctrl, track, f = COUNTS[0], CTRL[0], TRACK[0], F[0]
    wanted = ev_t.shape[0]
    last_events, last_steps = 0, 0
    while True:
        if read_flag(stop) != 0:
            status = dop.INTERRUPTED
            break
        budget = min(STOP_POLL_STEPS // 10, max_steps - counts[dop.STEPS])
        run_rows(
            codes,
            P,
            Y,
            F,
            CTRL,
            COUNTS,
            TRACK,
            t_eval,
            out,
            rtol,
            atol,
            ev_spec,
            ev_t,
            ev_y,
            counts[dop.STEPS] + budget,
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
            STATUS,
            stop,
        )
        status = STATUS[0]
        if counts[dop.N_EVENTS] >= wanted:
            status = dop.FINISHED
            break
        if status != dop.BUDGET_EXHAUSTED or counts[dop.STEPS] >= max_steps:
            break
        if counts[dop.N_EVENTS] > last_events:
            last_events, last_steps = counts[dop.N_EVENTS], counts[dop.STEPS]
        elif counts[dop.STEPS] - last_steps >= max_gap:
            status = NO_CROSSING
            break
    for m in range(min(counts[dop.N_EVENTS], wanted)):
        ev_t[m] += polish_crossing(code, p, ev_y[m], f, ytmp, ws)
    stats[0] = status
    stats[1] = min(counts[dop.N_EVENTS], wanted)
    stats[2] = counts[dop.STEPS]
    stats[3] = ctrl[dop.T]
    stats[4] = track[dop.MIN_NORMAL]


@compiled(nogil=True)
def section_batch(
    codes: IntArray,
    p: FloatArray,
    Y0: FloatArray,
    t_max: float,
    rtol: float,
    atol: float,
    max_steps: int,
    max_gap: int,
    ev_t: FloatArray,
    ev_y: FloatArray,
    stats: FloatArray,
    stop: IntArray,
) -> None:
    """:func:`section_one` for every row of ``Y0`` (shape (K, 18)); ``ev_t`` (K, N) and
    ``ev_y`` (K, N, 18) receive the crossings, ``stats`` (K, 5)."""
    for k in range(Y0.shape[0]):
        if read_flag(stop) != 0:
            stats[k, 0] = dop.INTERRUPTED
        else:
            section_one(
                codes[k],
                p,
                Y0[k],
                t_max,
                rtol,
                atol,
                max_steps,
                max_gap,
                ev_t[k],
                ev_y[k],
                stats[k],
                stop,
            )


@compiled(nogil=True)
def indicator_batch(
    codes: IntArray,
    p: FloatArray,
    Y0: FloatArray,
    D0: FloatArray,
    t_samples: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    out: FloatArray,
    stats: FloatArray,
    s_stop: float,
    stop: IntArray,
) -> None:
    """:func:`.tangent.run_indicators` for every row of ``Y0`` with tangent
    ``D0`` (both (K, 18)); ``out`` (K, n, 3), ``stats`` (K, 4). A trajectory not yet started
    when ``stop[0]`` is set is marked ``INTERRUPTED``."""
    states = np.zeros((0, N_STATE))
    for k in range(Y0.shape[0]):
        if read_flag(stop) != 0:
            stats[k, 0] = dop.INTERRUPTED
        else:
            run_indicators(
                codes[k],
                p,
                Y0[k],
                D0[k],
                t_samples,
                rtol,
                atol,
                max_steps,
                out[k],
                states,
                stats[k],
                s_stop,
            )
