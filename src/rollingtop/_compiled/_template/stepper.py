"""Compiled DOP853 stepper of one contact model, with after-step projection, dense output and
reaction monitoring.

The method is Dormand & Prince's explicit Runge-Kutta pair of order 8(5,3) with its 7th-order
continuous extension (Hairer, Norsett & Wanner, *Solving ODEs I*, Sec. II.10), with the step-size
control of Hairer's ``dop853.f`` as also used by ``scipy.integrate.DOP853``: the error norm
combines the 5th- and 3rd-order estimates, safety factor 0.9, step ratio in [0.2, 10]. Why a
stepper of our own, its status codes and control arrays: :mod:`rollingtop._compiled._dop853`.

Everything here takes bare arrays and runs in numba's nopython mode; see
:func:`rollingtop.integrate.driver.integrate` for the validated entry point. The stepping
functions allocate nothing and are compiled without reference counting (``_nrt=False``); the
stages come from generated code (:mod:`rollingtop._compiled._dop853_stages`), the dense output
and the roots located on it from :mod:`.dense`.
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._compiled._dop853 import (
    ATOL,
    BUDGET_EXHAUSTED,
    ERROR_EXPONENT,
    EV_CODE,
    EV_DIPS,
    FINISHED,
    H_ABS,
    LAST_NORMAL,
    MAX_FACTOR,
    MAX_RATIO,
    MAX_REJECTED_IN_A_ROW,
    MIN_FACTOR,
    MONITOR_EVALS,
    N_COUNTS,
    NEXT_SAMPLE,
    NFEV,
    NOT_FINITE,
    PREV_NORMAL,
    PREV_T,
    PROJ_DEFERRED,
    PROJ_PASSES,
    PROJECTION_FAILED,
    REJECTED,
    RTOL,
    SAFETY,
    STEP_TOO_SMALL,
    STEPS,
    T_CONTACT_LOST,
    T_END,
    T_MAX_RATIO,
    TOO_MANY_REJECTED,
    T,
    dip_predicted,
    new_track,
    update_track,
)
from rollingtop._compiled._dop853_dense import dense_eval
from rollingtop._compiled._dop853_stages import scaled_errors, stage
from rollingtop._compiled._kernel import reaction
from rollingtop._compiled._template._dispatch import INLINE_RHS
from rollingtop._compiled._template.dense import (
    dip_minimum,
    normal_root,
    prepare_dense,
    step_events,
)
from rollingtop._compiled._template.dynamics import project, rhs, rhs_inline
from rollingtop._compiled._template.events import event_value
from rollingtop._compiled._template.invariants import WORK_ROWS, project_integrals
from rollingtop._jit import compiled, loop
from rollingtop._types import FloatArray, IntArray, Workspace

#: Whether :func:`run` holds integrals by projection: ``True`` in the instance ``stepper_held``.
#: numba prunes a branch on a global constant before typing: a plain run never compiles it.
HELD = False
#: Whether :func:`run` locates the zeros of an event function (:func:`.dense.step_events`):
#: ``True`` in the instances ``stepper_events`` and ``stepper_held``; pruned like ``HELD``.
EVENTS = False


@compiled()
def initial_step(
    code: int,
    p: FloatArray,
    y: FloatArray,
    f: FloatArray,
    t_end: float,
    t0: float,
    rtol: float,
    atol: float,
    ytmp: FloatArray,
    ftmp: FloatArray,
    ws: Workspace,
) -> float:
    """Starting step size (Hairer, Norsett & Wanner, Sec. II.4), as in SciPy.

    NaN (and no evaluation of the right-hand side) when the scaled norm of ``y`` or ``f`` is not
    finite: :func:`run` then stops at once, with ``NOT_FINITE`` for a non-finite ``y`` or ``f``,
    else (the norm overflows: a tiny ``atol`` or huge values) with ``STEP_TOO_SMALL``.
    """
    n = y.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d0 += (y[i] / sc) ** 2
        d1 += (f[i] / sc) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    if not (math.isfinite(d0) and math.isfinite(d1)):
        # a non-finite state or derivative, or one that overflows: no step; ``run`` reports it
        return math.nan
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, t_end - t0)
    for i in range(n):
        ytmp[i] = y[i] + h0 * f[i]
    rhs(code, p, ytmp, ftmp, ws)
    d2 = 0.0
    for i in range(n):
        sc = atol + abs(y[i]) * rtol
        d2 += ((ftmp[i] - f[i]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, t_end - t0)


@compiled()
def start(
    code: int,
    p: FloatArray,
    y: FloatArray,
    f: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    ev_code: int,
    out: FloatArray,
    ytmp: FloatArray,
    ynew: FloatArray,
    ws: Workspace,
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Prepare a run from ``y`` at ``t_eval[0]``: derivative ``f``, reaction tracking, initial
    step, the first sample ``out[0]``. Returns ``(ctrl, counts, track)`` for :func:`run`."""
    nc = rhs(code, p, y, f, ws)
    track = new_track()
    N0, T0 = reaction(nc, y, ws)
    update_track(track, t_eval[0], N0, T0)
    track[LAST_NORMAL] = N0
    t0, t_end = t_eval[0], t_eval[-1]
    h0 = initial_step(code, p, y, f, t_end, t0, rtol, atol, ytmp, ynew, ws)
    ctrl = np.array([t0, h0, t_end, rtol, atol, event_value(ev_code, code, y), np.nan, np.nan])
    counts = np.zeros(N_COUNTS, dtype=np.int64)
    counts[NFEV] = 2
    for i in range(y.shape[0]):
        out[0, i] = y[i]
    counts[NEXT_SAMPLE] = 1
    return ctrl, counts, track


@loop
def run(
    code: int,
    p: FloatArray,
    y: FloatArray,
    f: FloatArray,
    ctrl: FloatArray,
    counts: IntArray,
    track: FloatArray,
    t_eval: FloatArray,
    out: FloatArray,
    ev_spec: IntArray,
    ev_t: FloatArray,
    ev_y: FloatArray,
    budget: int,
    K: FloatArray,
    ynew: FloatArray,
    ytmp: FloatArray,
    y_old: FloatArray,
    Fd: FloatArray,
    ws: Workspace,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
) -> int:
    """Advance ``(t, y)`` towards ``ctrl[T_END]``, writing dense samples at ``t_eval`` into ``out``.

    Parameters
    ----------
    code : int
        Contact model code.
    p : ndarray, shape (9,)
        Body parameters.
    y, f : ndarray, shape (18,)
        Current state (projected) and its derivative; updated in place.
    ctrl : ndarray, shape (8,)
        ``t, h_abs, t_end, rtol, atol, g_old`` (event function at ``t``), and the time and
        event function at the previous step end (``EV_PREV_T, EV_PREV_G``); updated.
    counts : ndarray of int64, shape (8,)
        Next sample index, accepted steps, rejected steps, right-hand-side evaluations, events
        found (also those beyond the capacity of ``ev_t``), the projection's passes, the steps
        at which it left a nonlinear integral for the next ones, and the right-hand sides spent
        on the normal force inside steps.
    track : ndarray, shape (5,)
        Reaction tracking (see :func:`new_track`), updated at every accepted step.
    t_eval : ndarray, shape (n_samples,)
        Increasing sample times within ``[t0, t_end]``.
    out : ndarray, shape (n_samples, 18)
        Samples, each projected onto the constraints.
    ev_spec : ndarray of int64, shape (3,)
        Event function code (:mod:`rollingtop._compiled._events`, 0 for none) and direction
        (+1: rising zeros only, -1: falling, 0: both), then 1 to locate the normal force's
        minima inside steps (0: the reactions are monitored at step ends, and a loss of contact
        located where a step ends with a negative normal force). Located only by the copies compiled
        with ``EVENTS = True`` (``stepper_events``, ``stepper_held``): the plain stepper
        ignores a code, so callers pick the copy (the driver does).
    ev_t, ev_y : ndarray, shapes (capacity,) and (capacity, 18)
        Times and projected states of the located events.
    budget : int
        Maximum number of accepted steps in this call (the caller resumes for progress output).
    K, ynew, ytmp, y_old, Fd, ws
        Work arrays: stages ``(16, 18)``, three states, dense-output coefficients ``(7, 18)`` and
        the kernel workspace.
    icodes, targets, pw : ndarrays, shapes (k,), (k,), ``invariants.WORK_SHAPE``
        The integrals held by projection after every accepted step (codes of
        :mod:`rollingtop._compiled._integrals`; ``k = 0``: none), their values, and the
        projection's work array (:func:`.invariants.project_integrals`).

    Returns
    -------
    status : int
        ``FINISHED``, ``BUDGET_EXHAUSTED``, ``STEP_TOO_SMALL``, ``NOT_FINITE``,
        ``TOO_MANY_REJECTED`` or ``PROJECTION_FAILED``. Every call ends: after at most
        ``budget`` accepted steps, each preceded by fewer than :data:`MAX_REJECTED_IN_A_ROW`
        rejected attempts. Splitting a run into calls does not change its steps.
    """
    n = y.shape[0]
    t = ctrl[T]
    h_abs = ctrl[H_ABS]
    t_end = ctrl[T_END]
    rtol = ctrl[RTOL]
    atol = ctrl[ATOL]
    n_samples = t_eval.shape[0]
    for i in range(n):
        if not math.isfinite(y[i]) or not math.isfinite(f[i]):
            return NOT_FINITE
    taken = 0
    while t < t_end:
        if taken >= budget:
            ctrl[T] = t
            ctrl[H_ABS] = h_abs
            return BUDGET_EXHAUSTED
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        rejected = 0  # attempts rejected in a row
        while True:
            if not h_abs >= min_step:  # also a NaN step
                ctrl[T] = t
                ctrl[H_ABS] = h_abs
                return STEP_TOO_SMALL
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            for i in range(n):
                K[0, i] = f[i]
            for s in range(1, 12):
                stage(K, s, y, h, ytmp)
                if INLINE_RHS:
                    rhs_inline(code, p, ytmp, K[s], ws)
                else:
                    rhs(code, p, ytmp, K[s], ws)
            # new point: the 13th stage's combination is the solution's (first same as last)
            stage(K, int(np.int64(12)), y, h, ynew)  # not a literal: one compile of stage
            nc_new = rhs(code, p, ynew, K[12], ws)
            counts[NFEV] += 12
            # 5th- and 3rd-order error estimates, in Fd[0] and Fd[1] (free until the dense output
            # of an accepted step is prepared)
            err5, err3 = Fd[0], Fd[1]
            scaled_errors(K, y, ynew, rtol, atol, err5, err3)
            e5 = 0.0
            e3 = 0.0
            for i in range(n):
                e5 += err5[i] * err5[i]
                e3 += err3[i] * err3[i]
            if e5 == 0.0 and e3 == 0.0:
                err = 0.0
            else:
                err = h * e5 / math.sqrt((e5 + 0.01 * e3) * n)
            if not math.isfinite(err):
                h_abs *= MIN_FACTOR
                counts[REJECTED] += 1
                rejected += 1
                if rejected >= MAX_REJECTED_IN_A_ROW:
                    ctrl[T] = t
                    ctrl[H_ABS] = h_abs
                    return NOT_FINITE
            elif err < 1.0:
                factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
                if rejected > 0:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
                counts[REJECTED] += 1
                rejected += 1
                if rejected >= MAX_REJECTED_IN_A_ROW:
                    ctrl[T] = t
                    ctrl[H_ABS] = h_abs
                    return TOO_MANY_REJECTED
        # Contact reaction at the new point, from the last stage (FSAL), before ws is reused.
        N, T_force = reaction(nc_new, ynew, ws)
        # Dense output over [t, t_new] for the samples that fall in it.
        dense_ready = False
        k = counts[NEXT_SAMPLE]
        if k < n_samples and t_eval[k] <= t_new:
            prepare_dense(code, p, K, y, ynew, h, ytmp, Fd, ws)
            counts[NFEV] += 3
            dense_ready = True
            while k < n_samples and t_eval[k] <= t_new:
                dense_eval(Fd, y, (t_eval[k] - t) / h, out[k])
                project(code, p, out[k], ws)
                if HELD:  # the samples on the level too
                    if project_integrals(code, p, out[k], icodes, targets, pw, ws) < 0:
                        ctrl[T] = t_new
                        return PROJECTION_FAILED
                    if pw[WORK_ROWS - 1, 7] > 0.0:  # a sample off the level is counted too
                        counts[PROJ_DEFERRED] += 1
                k += 1
            counts[NEXT_SAMPLE] = k
        # Accept: project onto the constraints. The derivative at the new point is the last
        # stage (first same as last): the projection moves the state by round-off-sized amounts
        # (truncation error at most), far below what would change the next step.
        for i in range(n):
            y_old[i] = y[i]
            y[i] = ynew[i]
            f[i] = K[12, i]
        project(code, p, y, ws)
        if HELD:
            passes = project_integrals(code, p, y, icodes, targets, pw, ws)
            if passes < 0:
                ctrl[T] = t_new
                return PROJECTION_FAILED
            counts[PROJ_PASSES] += passes
            if pw[WORK_ROWS - 1, 7] > 0.0:
                counts[PROJ_DEFERRED] += 1
        for i in range(n):
            if not math.isfinite(y[i]) or not math.isfinite(f[i]):
                ctrl[T] = t_new
                return NOT_FINITE
        N_old = track[LAST_NORMAL]
        if N < 0.0 and math.isnan(track[T_CONTACT_LOST]) and N_old >= 0.0:
            # first loss of contact: locate N = 0 inside the step on the dense output
            if not dense_ready:
                prepare_dense(code, p, K, y_old, ynew, h, ytmp, Fd, ws)
                counts[NFEV] += 3
                dense_ready = True
            track[T_CONTACT_LOST] = normal_root(code, p, Fd, y_old, t, h, ytmp, K[13], ws)
            counts[NFEV] += 60
        elif ev_spec[EV_DIPS] != 0 and dip_predicted(
            track[PREV_T], track[PREV_NORMAL], t, N_old, t_new, N
        ):
            # a minimum of the normal force inside the step: found on the dense output, with
            # its loss of contact if it dips below zero between two positive ends
            if not dense_ready:
                prepare_dense(code, p, K, y_old, ynew, h, ytmp, Fd, ws)
                counts[MONITOR_EVALS] += 3
                dense_ready = True
            found = K[14]  # stages 14-16 are free once the dense output is built
            counts[MONITOR_EVALS] += dip_minimum(code, p, Fd, y_old, t, h, ytmp, K[13], ws, found)
            if not math.isnan(found[2]) and math.isnan(track[T_CONTACT_LOST]):
                track[T_CONTACT_LOST] = found[2]
            update_track(track, found[0], found[1], 0.0)
            if found[3] > track[MAX_RATIO]:
                track[MAX_RATIO], track[T_MAX_RATIO] = found[3], found[4]
        track[PREV_T], track[PREV_NORMAL] = t, N_old
        track[LAST_NORMAL] = N
        update_track(track, t_new, N, T_force)
        if EVENTS and ev_spec[EV_CODE] != 0:
            dense_ready = step_events(
                code,
                p,
                K,
                Fd,
                y_old,
                ynew,
                t,
                h,
                y,
                ctrl,
                counts,
                ev_spec,
                ev_t,
                ev_y,
                ytmp,
                ws,
                dense_ready,
            )
        t = t_new
        counts[STEPS] += 1
        taken += 1
    ctrl[T] = t
    ctrl[H_ABS] = h_abs
    return FINISHED
