"""Compiled tangent (variational) dynamics integrated with the motion, for chaos indicators.

The augmented state is ``z = (y, delta, W, Z, t)``, shape :data:`N_AUG`: the state ``y``
(:mod:`rollingtop._layout`), a tangent vector ``delta`` of the same layout, the MEGNO
integrals ``W = int_0^t (delta' . delta / |delta|^2) s ds`` and ``Z = int_0^t Y(s) ds`` with
``Y = 2 W / t`` (Cincotta & Simo 2000, *Astron. Astrophys. Suppl.* 147, 205), and the time ``t``
itself (``t' = 1``: the Runge-Kutta stages see their own times). It is advanced by the same
DOP853 pair as the motion (:mod:`rollingtop._compiled._dop853`: the generated stages and error
estimates; the error norm covers ``y`` and ``delta``).

**Tangent dynamics.** ``delta' = Df(y) delta`` is the directional derivative of the compiled
right-hand side (:func:`rollingtop._compiled._template.dynamics.rhs`, compiled per contact
model) by a central difference, ``(f(y + e delta) - f(y - e delta)) / (2 e)``
with ``e |delta|_inf = FD_STEP max(1, |y|_inf)`` (over ``v, w`` and the frame), ``FD_STEP =
eps^(1/3)``: truncation and round-off errors balance at a relative error near ``eps^(2/3) ~
4e-11``. Exact forward-mode differentiation would need a dual-number version of every model's
compiled rows and closed forms (and of the models still to come); the difference needs nothing
per model, and an error of ``1e-10`` relative in ``delta'`` changes a Lyapunov exponent by far
less than its finite-time fluctuations. The constraint manifold is invariant under the vector
field (the rhs keeps ``d/dt (J u) = 0`` and the frame orthonormal), so ``Df`` maps its tangent
space to itself.

**Projection and renormalisation.** After every accepted step the state is projected onto the
constraint manifold (:func:`rollingtop._compiled._template.dynamics.project`, as the plain
integrator does)
and ``delta`` onto the manifold's tangent space there, by the linearised projection
``(P(y + e delta) - P(y - e delta)) / (2 e)`` (the derivative of a projection onto a manifold,
at a point of it, is a projection onto its tangent space; a Newton-Schulz step's derivative at
an orthogonal frame is the skew part). Then ``delta`` is renormalised to unit length and
``ln |delta|`` added to a running sum: ``lambda(t) = sum / t`` is the finite-time maximal
Lyapunov exponent. ``|delta|`` is the Euclidean norm over the first :data:`NORM` components
(``v, w, alpha, beta, gamma``): the horizontal position and ``psi_nu`` are left out (the position
never acts back on the motion).

Everything takes bare arrays; the validated entry point is :mod:`rollingtop.chaos.lyapunov`.
This module holds the layout and the pieces that do not depend on the model; the integration
itself calls the model's right-hand side and is compiled per model
(:mod:`rollingtop._compiled._template.tangent`).
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._compiled import _dop853 as dop
from rollingtop._jit import kernel
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray

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
#: determined through it: ``Vertical.determined`` of the contact model).
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
def fd_scale(y: FloatArray, d: FloatArray) -> float:
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
def signed_tilt(z: FloatArray) -> float:
    """``sigma = gamma1 tau2 - gamma2 tau1``: the tilt of the axis with the sign of the side of
    the vertical it is on, for the carried ``tau = sin(psi_nu) alpha - cos(psi_nu) beta``
    (continuous through a passage, where ``sigma`` changes sign)."""
    c, s = math.cos(z[17]), math.sin(z[17])
    t1 = s * z[6] - c * z[9]
    t2 = s * z[7] - c * z[10]
    sigma: float = z[12] * t2 - z[13] * t1
    return sigma
