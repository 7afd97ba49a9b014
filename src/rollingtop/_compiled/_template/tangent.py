"""Compiled tangent (variational) dynamics of one contact model, integrated with the motion, for
chaos indicators.

The augmented state, the finite-difference tangent dynamics, the projection and renormalisation
are described in :mod:`rollingtop._compiled._tangent`, which holds the pieces that do not depend on
the model; the functions here call the model's right-hand side and projection
(:mod:`.dynamics`), so they are compiled per model. The validated entry point is
:mod:`rollingtop.chaos.lyapunov`.
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled._dop853_stages import scaled_errors, step_stage
from rollingtop._compiled._kernel import new_workspace
from rollingtop._compiled._tangent import (
    ATOL,
    DELTA,
    H_ABS,
    LOG_SUM,
    N_AUG,
    N_ERR,
    NFEV,
    NORM,
    REACHED_VERTICAL,
    REJECTED,
    RTOL,
    STEPS,
    TANGENT_TOL,
    TIME,
    W_MEGNO,
    Z_MEGNO,
    T,
    fd_scale,
    renormalise,
    signed_tilt,
)
from rollingtop._compiled._template.dynamics import project, rhs
from rollingtop._compiled._template.stepper import initial_step
from rollingtop._jit import compiled, kernel
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray, Workspace


@kernel
def aug_rhs(
    code: int,
    p: FloatArray,
    z: FloatArray,
    dz: FloatArray,
    ytmp: FloatArray,
    f1: FloatArray,
    f2: FloatArray,
    ws: Workspace,
) -> None:
    """``dz = z'`` of the augmented system (three evaluations of the model's rhs)."""
    y = z[0:N_STATE]
    rhs(code, p, y, dz[0:N_STATE], ws)
    e = fd_scale(y, z[DELTA:])
    if e == 0.0:
        for i in range(N_STATE):
            dz[DELTA + i] = 0.0
    else:
        for i in range(N_STATE):
            ytmp[i] = y[i] + e * z[DELTA + i]
        rhs(code, p, ytmp, f1, ws)
        for i in range(N_STATE):
            ytmp[i] = y[i] - e * z[DELTA + i]
        rhs(code, p, ytmp, f2, ws)
        for i in range(N_STATE):
            dz[DELTA + i] = (f1[i] - f2[i]) / (2.0 * e)
    dd = 0.0
    nn = 0.0
    for i in range(NORM):
        dd += z[DELTA + i] * dz[DELTA + i]
        nn += z[DELTA + i] * z[DELTA + i]
    t = z[TIME]
    dz[W_MEGNO] = 0.0 if nn == 0.0 else t * dd / nn
    dz[Z_MEGNO] = 0.0 if t <= 0.0 else 2.0 * z[W_MEGNO] / t
    dz[TIME] = 1.0


@kernel
def project_tangent(
    code: int,
    p: FloatArray,
    y: FloatArray,
    d: FloatArray,
    y1: FloatArray,
    y2: FloatArray,
    ws: Workspace,
) -> None:
    """``d`` in place onto the tangent space of the constraint manifold at ``y`` (on it): the
    central difference of :func:`project` along ``d``; ``y1, y2`` are scratch."""
    e = fd_scale(y, d)
    if e == 0.0:
        return
    for i in range(N_STATE):
        y1[i] = y[i] + e * d[i]
        y2[i] = y[i] - e * d[i]
    project(code, p, y1, ws)
    project(code, p, y2, ws)
    for i in range(N_STATE):
        d[i] = (y1[i] - y2[i]) / (2.0 * e)


@kernel
def advance(
    code: int,
    p: FloatArray,
    z: FloatArray,
    fz: FloatArray,
    ctrl: FloatArray,
    counts: IntArray,
    t_end: float,
    K: FloatArray,
    znew: FloatArray,
    ztmp: FloatArray,
    scratch: FloatArray,
    ws: Workspace,
    s_stop: float,
    step_limit: int,
) -> int:
    """Advance the augmented state ``z`` (derivative ``fz``) to ``t_end`` exactly.

    Parameters
    ----------
    code : int
        Kernel code of the contact model.
    p : ndarray, shape (9,)
        Body parameters.
    z, fz : ndarray, shape (N_AUG,)
        Augmented state (``delta`` of unit norm, on the tangent space) and its derivative.
    ctrl : ndarray, shape (5,)
        ``t, h_abs, rtol, atol, log_sum``; updated.
    counts : ndarray of int64, shape (3,)
        Accepted steps, rejected steps, model rhs evaluations; updated.
    K, znew, ztmp : ndarray, shapes (16, N_AUG), (N_AUG,), (N_AUG,)
        Work arrays.
    scratch : ndarray, shape (4, 18)
        Work array (difference quotients and projections).
    ws : tuple
        Kernel workspace.
    s_stop : float
        Nonzero: stop (:data:`REACHED_VERTICAL`) after a step through the vertical, where the
        signed distance ``sigma = (gamma, tau x e3)`` of the axis from it, with the carried
        direction ``tau`` (:mod:`rollingtop.contact.parallel`), changes sign.
    step_limit : int
        Stop (``dop.BUDGET_EXHAUSTED``, resumable) before a step once ``counts`` holds this many
        accepted steps: every call ends after a bounded amount of work.

    Returns
    -------
    status : int
        ``dop.FINISHED``, ``dop.BUDGET_EXHAUSTED``, ``dop.STEP_TOO_SMALL``, ``dop.NOT_FINITE``,
        ``dop.TOO_MANY_REJECTED`` (the codes of :mod:`rollingtop._compiled._dop853`) or
        :data:`REACHED_VERTICAL`.
    """
    t = ctrl[T]
    h_abs = ctrl[H_ABS]
    rtol = ctrl[RTOL]
    atol = ctrl[ATOL]
    tangent_tol = max(rtol, TANGENT_TOL)
    f1, f2, y1, y2 = scratch[0], scratch[1], scratch[2], scratch[3]
    sigma_before = signed_tilt(z)
    while t < t_end:
        if counts[STEPS] >= step_limit:
            ctrl[T] = t
            ctrl[H_ABS] = h_abs
            return dop.BUDGET_EXHAUSTED
        # ten units in the last place of the time reached or of the target, whichever is
        # larger: near t = 0 the former alone would let steps of 1e-300 count as progress
        far = max(abs(t), abs(t_end))
        min_step = 10.0 * abs(np.nextafter(far, np.inf) - far)
        rejected = 0
        while True:
            if not h_abs >= min_step:
                ctrl[T] = t
                ctrl[H_ABS] = h_abs
                return dop.STEP_TOO_SMALL
            t_new = min(t + h_abs, t_end)
            h = t_new - t
            for i in range(N_AUG):
                K[0, i] = fz[i]
            for s in range(1, 12):
                step_stage(K, s, z, h, ztmp)
                aug_rhs(code, p, ztmp, K[s], y1, f1, f2, ws)
            step_stage(K, int(np.int64(12)), z, h, znew)  # not a literal: one compile
            aug_rhs(code, p, znew, K[12], y1, f1, f2, ws)
            counts[NFEV] += 36
            err5, err3 = K[13], K[14]  # free: no dense output here
            scaled_errors(K, z[0:N_ERR], znew[0:N_ERR], rtol, atol, err5, err3)
            e5 = 0.0
            e3 = 0.0
            for i in range(N_ERR):
                if i >= DELTA:  # delta, of unit norm: its error relative to the norm
                    sc = (atol + max(abs(z[i]), abs(znew[i])) * rtol) / tangent_tol
                    err5[i] *= sc
                    err3[i] *= sc
                e5 += err5[i] * err5[i]
                e3 += err3[i] * err3[i]
            err = 0.0 if (e5 == 0.0 and e3 == 0.0) else h * e5 / math.sqrt((e5 + 0.01 * e3) * N_ERR)
            if err < 1.0:
                factor = (
                    dop.MAX_FACTOR
                    if err == 0.0
                    else min(dop.MAX_FACTOR, dop.SAFETY * err**dop.ERROR_EXPONENT)
                )
                if rejected > 0:
                    factor = min(1.0, factor)
                # from the step taken, which a sample time may have shortened: scaling the
                # proposed one instead let it grow without bound over many short steps, and a
                # rejection then could not bring it below the distance to the sample
                h_abs = h * factor
                break
            h_abs = h * (
                dop.MIN_FACTOR
                if not math.isfinite(err)
                else max(dop.MIN_FACTOR, dop.SAFETY * err**dop.ERROR_EXPONENT)
            )
            counts[REJECTED] += 1
            rejected += 1
            if rejected >= dop.MAX_REJECTED_IN_A_ROW:
                ctrl[T] = t
                ctrl[H_ABS] = h_abs
                return dop.NOT_FINITE if not math.isfinite(err) else dop.TOO_MANY_REJECTED
        for i in range(N_AUG):
            z[i] = znew[i]
            fz[i] = K[12, i]
        y = z[0:N_STATE]
        project(code, p, y, ws)
        project_tangent(code, p, y, z[DELTA:N_ERR], y1, y2, ws)
        scale = renormalise(z, ctrl)
        # the tangent part of the derivative is linear in delta: scaled with it (the
        # projections move y and delta by truncation-sized amounts, as in the plain stepper)
        for i in range(N_STATE):
            fz[DELTA + i] *= scale
        for i in range(N_AUG):
            if not math.isfinite(z[i]) or not math.isfinite(fz[i]):
                ctrl[T] = t_new
                return dop.NOT_FINITE
        if scale == 0.0:
            ctrl[T] = t_new
            return dop.NOT_FINITE
        t = t_new
        counts[STEPS] += 1
        if s_stop != 0.0:
            sigma = signed_tilt(z)
            if sigma * sigma_before < 0.0:
                ctrl[T] = t
                ctrl[H_ABS] = h_abs
                return REACHED_VERTICAL
            sigma_before = sigma
    ctrl[T] = t
    ctrl[H_ABS] = h_abs
    return dop.FINISHED


@compiled()
def start_indicators(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    d0: FloatArray,
    t_end: float,
    z: FloatArray,
    fz: FloatArray,
    ctrl: FloatArray,
) -> None:
    """Set up the augmented state ``z`` (``y0``, then ``d0`` projected onto the tangent space
    and normalised), its derivative ``fz`` and ``ctrl`` (``t = 0``, the plain integrator's
    initial step towards ``t_end``, ``rtol`` and ``atol`` as given in ``ctrl[2:4]``)."""
    ws = new_workspace()
    znew = np.zeros(N_AUG)
    ztmp = np.zeros(N_AUG)
    scratch = np.zeros((4, N_STATE))
    for i in range(N_AUG):
        z[i] = 0.0
    for i in range(N_STATE):
        z[i] = y0[i]
        z[DELTA + i] = d0[i]
    ctrl[T] = 0.0
    project_tangent(code, p, z[0:N_STATE], z[DELTA:N_ERR], scratch[2], scratch[3], ws)
    renormalise(z, ctrl)
    ctrl[LOG_SUM] = 0.0
    aug_rhs(code, p, z, fz, scratch[2], scratch[0], scratch[1], ws)
    # the initial step of the plain integrator, from the motion alone
    ctrl[H_ABS] = initial_step(
        code,
        p,
        z[0:N_STATE].copy(),
        fz[0:N_STATE].copy(),
        t_end,
        0.0,
        ctrl[RTOL],
        ctrl[ATOL],
        znew[0:N_STATE],
        ztmp[0:N_STATE],
        ws,
    )


@compiled(nogil=True)
def indicators_chunk(
    code: int,
    p: FloatArray,
    z: FloatArray,
    fz: FloatArray,
    ctrl: FloatArray,
    counts: IntArray,
    t_samples: FloatArray,
    k0: int,
    step_limit: int,
    out: FloatArray,
    states: FloatArray,
    stats: FloatArray,
    s_stop: float,
) -> int:
    """Continue the run set up by :func:`start_indicators` from sample ``k0`` until every
    sample is written, a failure, or ``step_limit`` accepted steps in ``counts``
    (``stats[0] = dop.BUDGET_EXHAUSTED``: call again from the returned sample). Writes the
    samples' ``out`` and ``states`` rows (see :func:`run_indicators`) and ``stats``; returns
    the next sample to reach."""
    ws = new_workspace()
    K = np.zeros((16, N_AUG))
    znew = np.zeros(N_AUG)
    ztmp = np.zeros(N_AUG)
    scratch = np.zeros((4, N_STATE))
    status = dop.FINISHED
    k = k0
    while k < t_samples.shape[0]:
        status = advance(
            code,
            p,
            z,
            fz,
            ctrl,
            counts,
            t_samples[k],
            K,
            znew,
            ztmp,
            scratch,
            ws,
            s_stop,
            step_limit,
        )
        if status != dop.FINISHED:
            break
        t = ctrl[T]
        out[k, 0] = ctrl[LOG_SUM] / t
        out[k, 1] = 2.0 * z[W_MEGNO] / t
        out[k, 2] = z[Z_MEGNO] / t
        if k < states.shape[0]:
            for i in range(N_STATE):
                states[k, i] = z[i]
        k += 1
    stats[0] = status
    stats[1] = counts[STEPS]
    stats[2] = counts[REJECTED]
    stats[3] = counts[NFEV]
    return k


@compiled()
def run_indicators(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    d0: FloatArray,
    t_samples: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    out: FloatArray,
    states: FloatArray,
    stats: FloatArray,
    s_stop: float,
) -> None:
    """Integrate the augmented system from ``(y0, d0)`` at ``t = 0`` through ``t_samples``, in
    one call (the batches of :mod:`.chaos`; a single run goes through :func:`start_indicators`
    and :func:`indicators_chunk` to return to Python between chunks).

    Parameters
    ----------
    y0 : ndarray, shape (18,)
        Constraint-consistent state.
    d0 : ndarray, shape (18,)
        Initial tangent vector (projected onto the tangent space and normalised here).
    t_samples : ndarray, shape (n,)
        Increasing positive sample times.
    max_steps : int
        Accepted steps at most (``stats[0] = dop.BUDGET_EXHAUSTED`` when reached).
    out : ndarray, shape (n, 3)
        Filled with ``lambda(t) = sum ln|delta| / t``, ``Y(t) = 2 W / t``, ``<Y>(t) = Z / t``
        (NaN after a failure).
    states : ndarray, shape (n, 18)
        The state at each sample time (only the first ``min(n, len(states))``; may be empty).
    stats : ndarray, shape (4,)
        Status, accepted steps, rejected steps, model rhs evaluations.
    s_stop : float
        See :func:`advance`.
    """
    z = np.zeros(N_AUG)
    fz = np.zeros(N_AUG)
    ctrl = np.array([0.0, 0.0, rtol, atol, 0.0])
    counts = np.zeros(3, dtype=np.int64)
    for k in range(t_samples.shape[0]):
        for j in range(3):
            out[k, j] = np.nan
    start_indicators(code, p, y0, d0, t_samples[-1], z, fz, ctrl)
    indicators_chunk(
        code, p, z, fz, ctrl, counts, t_samples, 0, max_steps, out, states, stats, s_stop
    )
