"""Compiled tangent (variational) dynamics integrated with the motion, for chaos indicators.

The augmented state is ``z = (y, delta, W, Z, t)``, shape :data:`N_AUG`: the state ``y``
(:mod:`rollingtop.dynamics._layout`), a tangent vector ``delta`` of the same layout, the MEGNO
integrals ``W = int_0^t (delta' . delta / |delta|^2) s ds`` and ``Z = int_0^t Y(s) ds`` with
``Y = 2 W / t`` (Cincotta & Simo 2000, *Astron. Astrophys. Suppl.* 147, 205), and the time ``t``
itself (``t' = 1``: the Runge-Kutta stages see their own times). It is advanced by the same
DOP853 pair as the motion (:mod:`rollingtop.integrate._dop853`: the generated stages and error
estimates; the error norm covers ``y`` and ``delta``).

**Tangent dynamics.** ``delta' = Df(y) delta`` is the directional derivative of the compiled
right-hand side (:func:`rollingtop.dynamics._kernel.rhs`, any registered contact model through
its compiled dispatch) by a central difference, ``(f(y + e delta) - f(y - e delta)) / (2 e)``
with ``e |delta|_inf = FD_STEP max(1, |y|_inf)`` (over ``v, w`` and the frame), ``FD_STEP =
eps^(1/3)``: truncation and round-off errors balance at a relative error near ``eps^(2/3) ~
4e-11``. Exact forward-mode differentiation would need a dual-number version of every model's
compiled rows and closed forms (and of the models still to come); the difference needs nothing
per model, and an error of ``1e-10`` relative in ``delta'`` changes a Lyapunov exponent by far
less than its finite-time fluctuations. The constraint manifold is invariant under the vector
field (the rhs keeps ``d/dt (J u) = 0`` and the frame orthonormal), so ``Df`` maps its tangent
space to itself.

**Projection and renormalisation.** After every accepted step the state is projected onto the
constraint manifold (:func:`rollingtop.dynamics._kernel.project`, as the plain integrator does)
and ``delta`` onto the manifold's tangent space there, by the linearised projection
``(P(y + e delta) - P(y - e delta)) / (2 e)`` (the derivative of a projection onto a manifold,
at a point of it, is a projection onto its tangent space; a Newton-Schulz step's derivative at
an orthogonal frame is the skew part). Then ``delta`` is renormalised to unit length and
``ln |delta|`` added to a running sum: ``lambda(t) = sum / t`` is the finite-time maximal
Lyapunov exponent. ``|delta|`` is the Euclidean norm over the first :data:`NORM` components
(``v, w, alpha, beta, gamma``): the horizontal position and ``psi_nu`` are left out (the position
never acts back on the motion).

Everything takes bare arrays; the validated entry point is :mod:`rollingtop.chaos.lyapunov`.
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._jit import compiled, kernel
from rollingtop._types import FloatArray, IntArray, Workspace
from rollingtop.dynamics._kernel import new_workspace, project, rhs
from rollingtop.dynamics._layout import N_STATE
from rollingtop.integrate import _dop853 as dop
from rollingtop.integrate._dop853_stages import scaled_errors, stage

#: Components of the augmented state: y, delta, W, Z, t.
N_AUG = 2 * N_STATE + 3
#: Offsets in the augmented state.
DELTA, W_MEGNO, Z_MEGNO, TIME = N_STATE, 2 * N_STATE, 2 * N_STATE + 1, 2 * N_STATE + 2
#: Components of the error norm (y and delta).
N_ERR = 2 * N_STATE
#: Components of the tangent norm: v, w, alpha, beta, gamma.
NORM = 15
#: Relative step of the central differences (cube root of the machine epsilon).
FD_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))

#: Tolerance on each component of the unit tangent vector over a step, at least: finer would
#: resolve the round-off of the difference quotients (relative ``~1e-10``) and shorten the steps
#: for nothing; the exponent needs the tangent's direction, not its last digits.
TANGENT_TOL = 1e-8

#: Status of a run stopped where the axis passed through the vertical (a model whose motion is not
#: determined through it: ``ContactModel.determined_through_vertical``).
REACHED_VERTICAL = -4
#: Names of the statuses of :func:`run_indicators`.
STATUS_NAMES = {
    **dop.STATUS_NAMES,
    REACHED_VERTICAL: "reached the vertical, where the motion is not determined",
}

# ctrl: t, h_abs, rtol, atol, sum of ln |delta| at the renormalisations
T, H_ABS, RTOL, ATOL, LOG_SUM = 0, 1, 2, 3, 4
# counts: accepted steps, rejected steps, evaluations of the model's rhs
STEPS, REJECTED, NFEV = 0, 1, 2


@kernel
def _fd_scale(y: FloatArray, d: FloatArray) -> float:
    """Central-difference step ``e`` for direction ``d`` at ``y`` (0 for ``d = 0``), from the
    components the motion depends on: ``v, w`` and the frame, and the carried ``psi_nu`` in
    ``d``. The position and the unwrapped ``psi_nu`` of ``y`` grow without bound along a motion
    and must not set the scale (the step would grow with them)."""
    dn = abs(d[N_STATE - 1])
    ys = 1.0
    for i in range(NORM):
        dn = max(dn, abs(d[i]))
        ys = max(ys, abs(y[i]))
    return 0.0 if dn == 0.0 else FD_STEP * ys / dn


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
    e = _fd_scale(y, z[DELTA:])
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
    code: int, p: FloatArray, y: FloatArray, d: FloatArray, y1: FloatArray, y2: FloatArray,
    ws: Workspace,
) -> None:  # fmt: skip
    """``d`` in place onto the tangent space of the constraint manifold at ``y`` (on it): the
    central difference of :func:`project` along ``d``; ``y1, y2`` are scratch."""
    e = _fd_scale(y, d)
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
def renormalise(z: FloatArray, ctrl: FloatArray) -> float:
    """Scale ``delta`` to unit norm, add ``ln |delta|`` to ``ctrl[LOG_SUM]``; returns the
    factor applied (0 for a zero or non-finite norm, which is left as it is)."""
    nn = 0.0
    for i in range(NORM):
        nn += z[DELTA + i] * z[DELTA + i]
    norm = math.sqrt(nn)
    if not (norm > 0.0 and math.isfinite(norm)):
        return 0.0
    ctrl[LOG_SUM] += math.log(norm)
    for i in range(N_STATE):
        z[DELTA + i] /= norm
    return 1.0 / norm


@kernel
def _signed_tilt(z: FloatArray) -> float:
    """``sigma = gamma1 tau2 - gamma2 tau1``: the tilt of the axis with the sign of the side of
    the vertical it is on, for the carried ``tau = sin(psi_nu) alpha - cos(psi_nu) beta``
    (continuous through a passage, where ``sigma`` changes sign)."""
    c, s = math.cos(z[17]), math.sin(z[17])
    t1 = s * z[6] - c * z[9]
    t2 = s * z[7] - c * z[10]
    sigma: float = z[12] * t2 - z[13] * t1
    return sigma


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

    Returns
    -------
    status : int
        ``dop.FINISHED``, ``dop.STEP_TOO_SMALL``, ``dop.NOT_FINITE``,
        ``dop.TOO_MANY_REJECTED`` (the codes of :mod:`rollingtop.integrate._dop853`) or
        :data:`REACHED_VERTICAL`.
    """
    t = ctrl[T]
    h_abs = ctrl[H_ABS]
    rtol = ctrl[RTOL]
    atol = ctrl[ATOL]
    tangent_tol = max(rtol, TANGENT_TOL)
    f1, f2, y1, y2 = scratch[0], scratch[1], scratch[2], scratch[3]
    sigma_before = _signed_tilt(z)
    while t < t_end:
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
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
                stage(K, s, z, h, ztmp)
                aug_rhs(code, p, ztmp, K[s], y1, f1, f2, ws)
            stage(K, 12, z, h, znew)
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
                factor = dop.MAX_FACTOR if err == 0.0 else min(
                    dop.MAX_FACTOR, dop.SAFETY * err**dop.ERROR_EXPONENT)  # fmt: skip
                if rejected > 0:
                    factor = min(1.0, factor)
                # from the step taken, which a sample time may have shortened: scaling the
                # proposed one instead let it grow without bound over many short steps, and a
                # rejection then could not bring it below the distance to the sample
                h_abs = h * factor
                break
            h_abs = h * (dop.MIN_FACTOR if not math.isfinite(err) else max(
                dop.MIN_FACTOR, dop.SAFETY * err**dop.ERROR_EXPONENT))  # fmt: skip
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
            sigma = _signed_tilt(z)
            if sigma * sigma_before < 0.0:
                ctrl[T] = t
                ctrl[H_ABS] = h_abs
                return REACHED_VERTICAL
            sigma_before = sigma
    ctrl[T] = t
    ctrl[H_ABS] = h_abs
    return dop.FINISHED


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
    """Integrate the augmented system from ``(y0, d0)`` at ``t = 0`` through ``t_samples``.

    Parameters
    ----------
    y0 : ndarray, shape (18,)
        Constraint-consistent state.
    d0 : ndarray, shape (18,)
        Initial tangent vector (projected onto the tangent space and normalised here).
    t_samples : ndarray, shape (n,)
        Increasing positive sample times.
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
    ws = new_workspace()
    K = np.zeros((16, N_AUG))
    znew = np.zeros(N_AUG)
    ztmp = np.zeros(N_AUG)
    scratch = np.zeros((4, N_STATE))
    z = np.zeros(N_AUG)
    fz = np.zeros(N_AUG)
    for i in range(N_STATE):
        z[i] = y0[i]
        z[DELTA + i] = d0[i]
    ctrl = np.array([0.0, 0.0, rtol, atol, 0.0])
    counts = np.zeros(3, dtype=np.int64)
    project_tangent(code, p, z[0:N_STATE], z[DELTA:N_ERR], scratch[2], scratch[3], ws)
    renormalise(z, ctrl)
    ctrl[LOG_SUM] = 0.0
    aug_rhs(code, p, z, fz, scratch[2], scratch[0], scratch[1], ws)
    # the initial step of the plain integrator, from the motion alone
    ctrl[H_ABS] = dop.initial_step(code, p, z[0:N_STATE].copy(), fz[0:N_STATE].copy(),
                                   t_samples[-1], 0.0, rtol, atol, znew[0:N_STATE],
                                   ztmp[0:N_STATE], ws)  # fmt: skip
    status = dop.FINISHED
    for k in range(t_samples.shape[0]):
        for j in range(3):
            out[k, j] = np.nan
    for k in range(t_samples.shape[0]):
        status = advance(code, p, z, fz, ctrl, counts, t_samples[k], K, znew, ztmp, scratch, ws,
                         s_stop)  # fmt: skip
        if status != dop.FINISHED:
            break
        t = ctrl[T]
        out[k, 0] = ctrl[LOG_SUM] / t
        out[k, 1] = 2.0 * z[W_MEGNO] / t
        out[k, 2] = z[Z_MEGNO] / t
        if k < states.shape[0]:
            for i in range(N_STATE):
                states[k, i] = z[i]
        if counts[STEPS] >= max_steps:
            status = dop.BUDGET_EXHAUSTED
            break
    stats[0] = status
    stats[1] = counts[STEPS]
    stats[2] = counts[REJECTED]
    stats[3] = counts[NFEV]
