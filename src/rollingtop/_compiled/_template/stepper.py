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
    EV_PREV_G,
    EV_PREV_T,
    FINISHED,
    G_OLD,
    H_ABS,
    INTERRUPTED,
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
    RUNNING,
    SAFETY,
    STEP_TOO_SMALL,
    STEPS,
    T_CONTACT_LOST,
    T_END,
    T_MAX_RATIO,
    TOO_MANY_REJECTED,
    T,
    dip_predicted,
    reset_track,
    update_track,
)
from rollingtop._compiled._dop853_dense import dense_eval
from rollingtop._compiled._dop853_stages import scaled_errors, step_stage
from rollingtop._compiled._flags import read_flag
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
from rollingtop._jit import loop, spliced
from rollingtop._types import FloatArray, IntArray, Workspace

#: Whether :func:`run_rows` holds integrals by projection: ``True`` in the instance
#: ``stepper_held``. numba prunes a branch on a global constant before typing: a plain run never
#: compiles it.
HELD = False
#: Whether :func:`run_rows` locates the zeros of an event function (:func:`.dense.step_events`):
#: ``True`` in the instances ``stepper_events`` and ``stepper_held``; pruned like ``HELD``.
EVENTS = False


@spliced
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
    finite: :func:`run_rows` then stops at once, with ``NOT_FINITE`` for a non-finite ``y`` or
    ``f``, else (the norm overflows: a tiny ``atol`` or huge values) with ``STEP_TOO_SMALL``.
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
        # a non-finite state or derivative, or one that overflows: no step; ``run_rows`` reports it
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


@spliced
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
    ctrl: FloatArray,
    counts: IntArray,
    track: FloatArray,
) -> None:
    """Prepare a run from ``y`` at ``t_eval[0]``: derivative ``f``, reaction tracking, initial
    step, the first sample ``out[0]``; fills ``ctrl``, ``counts`` and ``track`` (shapes
    (``N_CTRL``,), (``N_COUNTS``,), (``N_TRACK``,)) for :func:`run_rows`."""
    nc = rhs(code, p, y, f, ws)
    reset_track(track)
    N0, T0 = reaction(nc, y, ws)
    update_track(track, t_eval[0], N0, T0)
    track[LAST_NORMAL] = N0
    t0, t_end = t_eval[0], t_eval[-1]
    h0 = initial_step(code, p, y, f, t_end, t0, rtol, atol, ytmp, ynew, ws)
    ctrl[T] = t0
    ctrl[H_ABS] = h0
    ctrl[T_END] = t_end
    ctrl[RTOL] = rtol
    ctrl[ATOL] = atol
    # the event function where events are located (pruned from the plain copy, which locates
    # none: 1.0, the value of no event, without compiling the event functions into it)
    ctrl[G_OLD] = event_value(ev_code, code, y) if EVENTS else 1.0
    ctrl[EV_PREV_T] = np.nan
    ctrl[EV_PREV_G] = np.nan
    for i in range(N_COUNTS):
        counts[i] = 0
    counts[NFEV] = 2
    for i in range(y.shape[0]):
        out[0, i] = y[i]
    counts[NEXT_SAMPLE] = 1


@loop
def run_rows(
    codes: IntArray,
    P: FloatArray,
    Y: FloatArray,
    F: FloatArray,
    CTRL: FloatArray,
    COUNTS: IntArray,
    TRACK: FloatArray,
    t_eval: FloatArray,
    OUT: FloatArray,
    rtol0: float,
    atol0: float,
    ev_spec: IntArray,
    ev_t: FloatArray,
    ev_y: FloatArray,
    limit: int,
    poll: int,
    K: FloatArray,
    ynew: FloatArray,
    ytmp: FloatArray,
    y_old: FloatArray,
    Fd: FloatArray,
    ws: Workspace,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    STATUS: IntArray,
    stop: IntArray,
) -> None:
    """Advance each row of ``Y`` towards its ``CTRL[k, T_END]``, writing dense samples at
    ``t_eval`` into its ``OUT[k]``: the stepper's loop, the entry point of every run. Python
    calls it, a single run with one row and a limit a chunk of steps ahead (it resumes the row:
    splitting a run into calls does not change its steps), an ensemble with rows of trajectories
    run to their end on threads (it releases the GIL, ``nogil``).

    Parameters
    ----------
    codes : ndarray of int64, shape (rows,)
        Each row's kernel code (one of this package's).
    P : ndarray, shape (rows, 9)
        Each row's body parameters.
    Y, F : ndarray, shape (rows, 18)
        Current states (projected) and their derivatives; updated in place.
    CTRL : ndarray, shape (rows, 8)
        ``t, h_abs, t_end, rtol, atol, g_old`` (event function at ``t``), and the time and
        event function at the previous step end (``EV_PREV_T, EV_PREV_G``); updated.
    COUNTS : ndarray of int64, shape (rows, 8)
        Next sample index, accepted steps, rejected steps, right-hand-side evaluations, events
        found (also those beyond the capacity of ``ev_t``), the projection's passes, the steps
        at which it left a nonlinear integral for the next ones, and the right-hand sides spent
        on the normal force inside steps. A row whose next sample index is 0 is started first
        (:func:`start`, with ``rtol0``, ``atol0`` and the event code ``ev_spec[EV_CODE]``).
    TRACK : ndarray, shape (rows, 8)
        Reaction tracking (see :func:`reset_track`), updated at every accepted step.
    t_eval : ndarray, shape (n_samples,)
        Increasing sample times within ``[t0, t_end]``, shared by the rows.
    OUT : ndarray, shape (rows, n_samples, 18)
        Samples, each projected onto the constraints.
    rtol0, atol0 : float
        Tolerances of a row started here (a row resumed keeps those of its ``CTRL``).
    ev_spec : ndarray of int64, shape (3,)
        Event function code (:mod:`rollingtop._compiled._events`, 0 for none) and direction
        (+1: rising zeros only, -1: falling, 0: both), then 1 to locate the normal force's
        minima inside steps (0: the reactions are monitored at step ends, and a loss of contact
        located where a step ends with a negative normal force). Located only by the copies
        compiled with ``EVENTS = True`` (``stepper_events``, ``stepper_held``): the plain
        stepper ignores a code, so callers pick the copy (the driver does).
    ev_t, ev_y : ndarray, shapes (capacity,) and (capacity, 18)
        Times and projected states of the located events (a single run's: one row).
    limit : int
        Accepted steps (in all, ``COUNTS[k, STEPS]``) at which a row stops with
        ``BUDGET_EXHAUSTED``.
    poll : int
        Accepted steps between two reads of ``stop`` (int64, shape (1,)); it is read before
        each row too. Set, the row stops ``INTERRUPTED`` (one not started is left as it was).
    K, ynew, ytmp, y_old, Fd, ws
        Work arrays shared by the rows: stages ``(16, 18)``, three states, dense-output
        coefficients ``(7, 18)`` and the kernel workspace.
    icodes, targets, pw : ndarrays, shapes (k,), (k,), ``invariants.WORK_SHAPE``
        The integrals held by projection after every accepted step (codes of
        :mod:`rollingtop._compiled._integrals`; ``k = 0``: none), their values, and the
        projection's work array (:func:`.invariants.project_integrals`; a single run's).
    STATUS : ndarray of int64, shape (rows,)
        Each row's status: ``FINISHED``, ``BUDGET_EXHAUSTED``, ``INTERRUPTED``,
        ``STEP_TOO_SMALL``, ``NOT_FINITE``, ``TOO_MANY_REJECTED`` or ``PROJECTION_FAILED``.
        Every call ends: each row after at most ``limit`` accepted steps, each preceded by
        fewer than :data:`MAX_REJECTED_IN_A_ROW` rejected attempts.

    One function for both, written out here rather than a function per trajectory called from
    the rows' loop: numba optimises and emits a callee's code again inside each caller, and
    inlining it at numba's level types it again, each about a second of every model's first
    compile.
    """
    n = Y.shape[1]
    for row in range(Y.shape[0]):
        if read_flag(stop) != 0:
            STATUS[row] = INTERRUPTED
            continue
        code, p, y, f, out = codes[row], P[row], Y[row], F[row], OUT[row]
        ctrl, counts, track = CTRL[row], COUNTS[row], TRACK[row]
        if counts[NEXT_SAMPLE] == 0:
            start(code, p, y, f, t_eval, rtol0, atol0, ev_spec[EV_CODE], out, ytmp, ynew, ws,
                  ctrl, counts, track)  # fmt: skip
        t = ctrl[T]
        h_abs = ctrl[H_ABS]
        t_end = ctrl[T_END]
        rtol = ctrl[RTOL]
        atol = ctrl[ATOL]
        n_samples = t_eval.shape[0]
        status = RUNNING
        keep_h = True  # h_abs is left in ctrl unless a step failed after it was accepted
        for i in range(n):
            if not math.isfinite(y[i]) or not math.isfinite(f[i]):
                status = NOT_FINITE
        taken = 0  # accepted steps since the stop flag was read
        while status == RUNNING and t < t_end:
            if counts[STEPS] >= limit:
                status = BUDGET_EXHAUSTED
                break
            if taken >= poll:
                if read_flag(stop) != 0:
                    status = INTERRUPTED
                    break
                taken = 0
            min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
            rejected = 0  # attempts rejected in a row
            while True:
                if not h_abs >= min_step:  # also a NaN step
                    status = STEP_TOO_SMALL
                    break
                t_new = t + h_abs
                if t_new > t_end:
                    t_new = t_end
                h = t_new - t
                for i in range(n):
                    K[0, i] = f[i]
                for s in range(1, 12):
                    step_stage(K, s, y, h, ytmp)
                    if INLINE_RHS:
                        rhs_inline(code, p, ytmp, K[s], ws)
                    else:
                        rhs(code, p, ytmp, K[s], ws)
                # new point: the 13th stage's combination is the solution's (first same as last)
                step_stage(K, int(np.int64(12)), y, h, ynew)  # not a literal: one compile
                nc_new = rhs(code, p, ynew, K[12], ws)
                counts[NFEV] += 12
                # 5th- and 3rd-order error estimates, in Fd[0] and Fd[1] (free until the dense
                # output of an accepted step is prepared)
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
                        status = NOT_FINITE
                        break
                elif err < 1.0:
                    factor = (
                        MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
                    )
                    if rejected > 0:
                        factor = min(1.0, factor)
                    h_abs *= factor
                    break
                else:
                    h_abs *= max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
                    counts[REJECTED] += 1
                    rejected += 1
                    if rejected >= MAX_REJECTED_IN_A_ROW:
                        status = TOO_MANY_REJECTED
                        break
            if status != RUNNING:
                break
            # Contact reaction at the new point, from the last stage (FSAL), before ws is reused.
            N, T_force = reaction(nc_new, ynew, ws)
            # What the step needs of the dense output over [t, t_new]: the samples that fall in
            # it, the first loss of contact located in it, or a minimum of the normal force
            # inside it (found on it, with its loss of contact if it dips below zero between two
            # positive ends). Built at one call site: compiled once into this function.
            N_old = track[LAST_NORMAL]
            k = counts[NEXT_SAMPLE]
            sampled = k < n_samples and t_eval[k] <= t_new
            lost = N < 0.0 and math.isnan(track[T_CONTACT_LOST]) and N_old >= 0.0
            dip = (
                not lost
                and ev_spec[EV_DIPS] != 0
                and dip_predicted(track[PREV_T], track[PREV_NORMAL], t, N_old, t_new, N)
            )
            dense_ready = sampled or lost or dip
            if dense_ready:
                prepare_dense(code, p, K, y, ynew, h, ytmp, Fd, ws)
                if sampled or lost:
                    counts[NFEV] += 3
                else:  # for the dip search alone
                    counts[MONITOR_EVALS] += 3
            if sampled:
                while k < n_samples and t_eval[k] <= t_new:
                    dense_eval(Fd, y, (t_eval[k] - t) / h, out[k])
                    project(code, p, out[k], ws)
                    if HELD:  # the samples on the level too
                        if project_integrals(code, p, out[k], icodes, targets, pw, ws) < 0:
                            status = PROJECTION_FAILED
                            break
                        if pw[WORK_ROWS - 1, 7] > 0.0:  # a sample off the level is counted too
                            counts[PROJ_DEFERRED] += 1
                    k += 1
                if status != RUNNING:
                    t, keep_h = t_new, False  # ctrl[T] is left at the step's end
                    break
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
                    status = PROJECTION_FAILED
                    t, keep_h = t_new, False  # ctrl[T] is left at the step's end
                    break
                counts[PROJ_PASSES] += passes
                if pw[WORK_ROWS - 1, 7] > 0.0:
                    counts[PROJ_DEFERRED] += 1
            for i in range(n):
                if not math.isfinite(y[i]) or not math.isfinite(f[i]):
                    status = NOT_FINITE
            if status != RUNNING:
                t, keep_h = t_new, False  # ctrl[T] is left at the step's end
                break
            if lost:
                # first loss of contact: locate N = 0 inside the step on the dense output
                track[T_CONTACT_LOST] = normal_root(code, p, Fd, y_old, t, h, ytmp, K[13], ws)
                counts[NFEV] += 60
            elif dip:
                found = K[14]  # stages 14-16 are free once the dense output is built
                counts[MONITOR_EVALS] += dip_minimum(
                    code, p, Fd, y_old, t, h, ytmp, K[13], ws, found
                )
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
        if keep_h:
            ctrl[H_ABS] = h_abs
        STATUS[row] = FINISHED if status == RUNNING else status
