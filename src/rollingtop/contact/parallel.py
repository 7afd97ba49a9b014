"""The companion model: no slip *across* the horizontal projection of the symmetry axis.

Kilin & Ivanova, "The Problem of the Rolling Motion of a Dynamically Symmetric Spherical Top with
One Nonholonomic Constraint", Rus. J. Nonlin. Dyn. 19(4), 2023 (doi:10.20537/nd231201): contact
is kept, ``f1 = (vp, gamma) = 0``, and the contact point does not slip along
``tau = e3 x gamma / s`` (``s = sqrt(1 - gamma3^2)``), ``(vp, tau) = 0``; it slips freely along
``nu = (e3 - gamma3 gamma) / s``, the horizontal projection of the axis. The free velocity
component is ``v_nu = (v, nu)``. The reaction along ``tau`` has a torque about the vertical
(``a3 s lambda``) and about the axis (``-R s lambda``), so neither the area nor the Lagrange
integral survives; energy and, for a dynamically symmetric body, Jellett's integral do (any
force at the contact point keeps Jellett's; ``rollingtop verify``).

**The pole is generic.** Unlike the meridian model, whose motions reach the vertical only on the
pole levels ``C1 = +-M3``, an open set of states of this model reaches ``gamma3 = +-1`` in finite
time: the axis arrives at the vertical with finite speed (``s' = -gamma3 w_tau``, ``w_tau != 0``)
along a straight line through the pole, and the constraint direction ``tau`` turns at a finite
rate ``K = psi' = -w_n / s`` (``w_n = (w, n)``, ``n = e3 x tau``) that tends to a limit ``K*``
fixed by the state alone. With ``sigma = -(gamma, n)`` (``s`` with a sign that changes at the
passage) the exact identity ``w_n = -K sigma`` gives

    K' = -(w_n'(K) + K sigma'(K)) / sigma,

where ``w_n'`` and ``sigma'`` depend on ``K`` through the reaction (the constraint row's bias
contains ``tau'``). The numerator is affine in ``K`` and vanishes at ``K*``; near the pole
``K - K* ~ C |sigma|^q`` with ``q`` fixed by the state (measured 0.6 to 15 on first arrivals
of random states), so where ``q > 0`` every trajectory that approaches funnels into ``K*``:
the motion loses its memory of ``C`` there, which is the local picture of the missing invariant
measure. The reactions stay finite (the
reaction along ``tau`` tends to the value at which the numerator vanishes). *After* the pole the
equations admit the whole family ``K - K* = C' |sigma|^q``: the motion is not determined by the
state at the pole. Measured: at some poles ``q < 0`` (``K`` diverges integrably, the axis
still arrives), and after the first passage trajectories computed at ``rtol = 1e-10, 1e-11,
1e-12`` differ by O(1) within one time unit although they agree to 1e-11 before it; energy and
Jellett's integral stay conserved to the tolerance through every passage (they hold for any
reaction at the contact point).

rollingtop carries the direction in the state's ``psi_nu`` (the azimuth of
``nu = cos(psi_nu) alpha + sin(psi_nu) beta``, ``tau = nu x gamma``) at the rate
``K = -w_n / sigma`` computed in the carried frame, which keeps ``tau`` perpendicular to the axis
and is regular where ``sigma`` passes through zero at a passage; within ``BLEND_S`` of the pole
it blends smoothly into ``K*`` (:func:`carried_rate`, :func:`pole_rate`), so the integrator
meets no ``0/0`` and no jump. Which continuation it then follows is decided by round-off: the
model's equations do not decide it. Away from the pole (``s > RESYNC_S``) the carried azimuth
relaxes towards the axis azimuth modulo ``pi`` (rate :data:`RELAX`) instead of being reset to it:
a reset would move the velocity onto another constraint in one jump and change the energy (by up
to 2e-4 after a passage where ``K`` diverges, measured), whereas any direction that moves
smoothly with the state keeps the constraint ideal and the energy conserved. After each passage
``psi_nu = psi + pi``, as for the meridian model's pole variants.

**Vertical start.** At ``gamma = (0, 0, +-1)`` the axis leaves the vertical along
``gamma' = gamma x w``; ``nu`` is the direction it leaves in (the meridian model's rule,
:func:`rollingtop.contact.meridian.vertical_direction`), ``nu = alpha`` when ``w1 = w2 = 0``.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline, kernel
from rollingtop._types import ComplexArray, Float3, Float6, FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, contact_arm
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import (
    contact_arm_rate,
    contact_row,
    free_forces,
    normal_row,
    row_bias,
)
from rollingtop.contact.meridian import tau_nu, vertical_direction

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: Scale of ``sigma`` below which the rate of the carried direction blends into the pole rate
#: ``K*``: ``psi_nu' = -w_n / sigma + c (K* - (-w_n / sigma))`` with the weight
#: ``c = BLEND_S^2 / (sigma^2 + BLEND_S^2) (1 - sigma^2 / POLE_RATE_S^2)^2`` (module docstring).
BLEND_S = 1e-11
#: Beyond this ``|sigma|`` the weight is 0 (and the pole rate is not computed).
POLE_RATE_S = 1e-4
#: Above this ``s`` the carried ``psi_nu`` relaxes towards the axis azimuth modulo ``pi`` (at the
#: rate :data:`RELAX`; below it the axis azimuth is too close to undefined to steer by).
RESYNC_S = 0.05
#: Rate (per unit time) at which the carried azimuth relaxes towards the axis azimuth modulo
#: ``pi`` beyond ``RESYNC_S``; the offset it removes is round-off, or what a passage left.
RELAX = 1.0


@inline
def tau_carried(y: FloatArray) -> Float3:
    """``tau = nu x gamma`` with the carried ``nu = cos(psi_nu) alpha + sin(psi_nu) beta``:
    ``tau = sin(psi_nu) alpha - cos(psi_nu) beta``."""
    c, s = math.cos(y[17]), math.sin(y[17])
    return s * y[6] - c * y[9], s * y[7] - c * y[10], s * y[8] - c * y[11]


@inline
def tau_rate(y: FloatArray, t1: float, t2: float, t3: float, rate: float) -> Float3:
    """``tau' = psi_nu' (gamma x tau) + tau x w`` of a carried direction turning at ``rate``."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    return (
        rate * (g2 * t3 - g3 * t2) + t2 * w3 - t3 * w2,
        rate * (g3 * t1 - g1 * t3) + t3 * w1 - t1 * w3,
        rate * (g1 * t2 - g2 * t1) + t1 * w2 - t2 * w1,
    )


@inline
def _spin_rate(
    p: FloatArray, y: FloatArray, t1: float, t2: float, t3: float, td1: float, td2: float,
    td3: float,
) -> Float3:  # fmt: skip
    """``w'`` under the rows ``(vp, gamma) = 0`` and ``(vp, t) = 0`` with ``t' = td``: the
    2x2 multiplier system of :mod:`rollingtop._compiled._kernel`, written out for the pole rate
    (which needs ``w'`` at two trial rates, and is also used by :func:`rows`, where there is no
    workspace to run :func:`rollingtop.contact._closed.rhs_contact` in)."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = free_forces(p, y)
    gd1, gd2, gd3 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3, g1 * w2 - g2 * w1
    a1, a2, a3_ = r2 * g3 - r3 * g2, r3 * g1 - r1 * g3, r1 * g2 - r2 * g1
    b1, b2, b3 = r2 * t3 - r3 * t2, r3 * t1 - r1 * t3, r1 * t2 - r2 * t1
    A11 = (g1 * g1 + g2 * g2 + g3 * g3) * im + a1 * a1 * i1 + a2 * a2 * i2 + a3_ * a3_ * i3
    A12 = (g1 * t1 + g2 * t2 + g3 * t3) * im + a1 * b1 * i1 + a2 * b2 * i2 + a3_ * b3 * i3
    A22 = (t1 * t1 + t2 * t2 + t3 * t3) * im + b1 * b1 * i1 + b2 * b2 * i2 + b3 * b3 * i3
    c1 = -row_bias(y, r1, r2, r3, rd1, rd2, rd3, g1, g2, g3, gd1, gd2, gd3) - (
        (g1 * f1 + g2 * f2 + g3 * f3) * im + a1 * f4 * i1 + a2 * f5 * i2 + a3_ * f6 * i3
    )
    c2 = -row_bias(y, r1, r2, r3, rd1, rd2, rd3, t1, t2, t3, td1, td2, td3) - (
        (t1 * f1 + t2 * f2 + t3 * f3) * im + b1 * f4 * i1 + b2 * f5 * i2 + b3 * f6 * i3
    )
    det = A11 * A22 - A12 * A12
    l1 = (c1 * A22 - c2 * A12) / det
    l2 = (A11 * c2 - A12 * c1) / det
    return (
        (f4 + l1 * a1 + l2 * b1) * i1,
        (f5 + l1 * a2 + l2 * b2) * i2,
        (f6 + l1 * a3_ + l2 * b3) * i3,
    )


@inline
def _pole_residual(
    p: FloatArray, y: FloatArray, t1: float, t2: float, t3: float, K: float
) -> float:
    """``w_n' + K sigma'`` at the trial rate ``K`` (``n = e3 x tau``, ``sigma = -(gamma, n)``):
    the numerator of ``K'`` (module docstring)."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    td1, td2, td3 = tau_rate(y, t1, t2, t3, K)
    wd1, wd2, wd3 = _spin_rate(p, y, t1, t2, t3, td1, td2, td3)
    n1, n2 = -t2, t1  # n = e3 x tau, n3 = 0
    nd1, nd2 = -td2, td1
    gd1, gd2 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3
    wn_rate = wd1 * n1 + wd2 * n2 + w1 * nd1 + w2 * nd2
    sigma_rate = -(gd1 * n1 + gd2 * n2) - (g1 * nd1 + g2 * nd2)
    residual: float = wn_rate + K * sigma_rate
    return residual


@kernel  # a call of its own: taken only near the pole; inlined, it doubled the compile time
def pole_rate(p: FloatArray, y: FloatArray) -> float:
    """``K*``: the rate of the carried direction at which ``K'`` has no ``1/sigma`` term (the
    limit of ``psi' = -w_n / s`` along every motion that reaches the pole; module docstring).
    The residual is affine in ``K`` (to ``O((tau, e3))``, which vanishes for the geometric
    direction): two trial rates determine its root. 0 where it has none (no motion through the
    pole: ``w = 0`` there)."""
    t1, t2, t3 = tau_carried(y)
    F0 = _pole_residual(p, y, t1, t2, t3, 0.0)
    F1 = _pole_residual(p, y, t1, t2, t3, 1.0)
    slope = F1 - F0
    if slope == 0.0 or not math.isfinite(slope):
        return 0.0
    rate: float = -F0 / slope
    return rate


@inline
def carried_rate(p: FloatArray, y: FloatArray) -> float:
    """``psi_nu'``: the rate ``K = -w_n / sigma`` (``n = e3 x tau``, ``sigma = -(gamma, n)``)
    that keeps the carried ``tau`` perpendicular to the axis (``(tau, e3) = 0``), blended into
    the pole rate ``K*`` (:func:`pole_rate`) on the scale :data:`BLEND_S`: the same to
    round-off for ``|sigma| >> BLEND_S``, ``K*`` at the pole, and smooth (module docstring)."""
    t1, t2, t3 = tau_carried(y)
    n1, n2 = -t2, t1
    sigma = -(y[12] * n1 + y[13] * n2)
    w_n = y[3] * n1 + y[4] * n2
    sigma2 = sigma * sigma
    if sigma2 >= POLE_RATE_S * POLE_RATE_S:
        far: float = -w_n / sigma
        s2 = y[12] * y[12] + y[13] * y[13]
        if s2 > RESYNC_S * RESYNC_S:  # relax the offset from the axis azimuth (modulo pi)
            psi = math.atan2(y[11], y[8])
            offset = y[17] - psi - math.pi * round((y[17] - psi) / math.pi)
            far -= RELAX * (1.0 - RESYNC_S * RESYNC_S / s2) * offset
        return far
    cut = 1.0 - sigma2 / (POLE_RATE_S * POLE_RATE_S)
    weight = BLEND_S * BLEND_S * cut * cut
    rate: float = (-w_n * sigma + pole_rate(p, y) * weight) / (sigma2 + BLEND_S * BLEND_S)
    return rate


@inline
def tau_of(p: FloatArray, y: FloatArray) -> Float6:
    """The carried constraint direction and its rate (:func:`carried_rate`)."""
    t1, t2, t3 = tau_carried(y)
    td1, td2, td3 = tau_rate(y, t1, t2, t3, carried_rate(p, y))
    return t1, t2, t3, td1, td2, td3


@kernel
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint rows ``f1`` (normal) and ``(vp, tau) = 0``; returns 2."""
    normal_row(p, y, 0, J, bias, dirs)
    t1, t2, t3, td1, td2, td3 = tau_of(p, y)
    contact_row(p, y, 1, t1, t2, t3, td1, td2, td3, J, bias, dirs)
    return 2


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations (:func:`.rhs_contact` with the row along ``tau``)."""
    t1, t2, t3, td1, td2, td3 = tau_of(p, y)
    return rhs_contact(p, y, dy, ws, True, t1, t2, t3, td1, td2, td3)


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection (:func:`.project_contact` with the row along
    ``tau``)."""
    t1, t2, t3 = tau_carried(y)
    project_contact(p, y, True, t1, t2, t3)


@inline
def direction_rate(p: FloatArray, y: FloatArray, variant: int) -> float:
    """``psi_nu'``: :func:`carried_rate`."""
    return carried_rate(p, y)


@inline
def sync_direction(y: FloatArray, variant: int) -> None:
    """Nothing: the carried azimuth is never reset (it relaxes, :func:`carried_rate`)."""
    return


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    if gamma[0] == 0.0 and gamma[1] == 0.0:  # vertical: the carried direction (module docstring)
        psi_nu = vertical_direction(omega, alpha, beta)
        nu = math.cos(psi_nu) * np.asarray(alpha) + math.sin(psi_nu) * np.asarray(beta)
    else:
        _, nu = tau_nu(gamma)
    wxr = np.cross(omega, contact_arm(body, gamma))
    slip = free["v_nu"] + wxr @ nu  # contact-point velocity vp = slip * nu
    out: FloatArray = -wxr + slip * nu
    return out


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    return [gamma, sp.Matrix([0, 0, 1]).cross(gamma)]  # tau, unnormalised


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr + free[0] * gamma.cross(tau)  # contact velocity along nu = gamma x tau only


def _vertical_eigenvalues(body: SphericalTop, omega3: float, pole: int) -> ComplexArray:
    """No linearisation at the vertical: refused (ValueError, reported by
    :mod:`rollingtop.stability`)."""
    raise ValueError(
        "the parallel model's constraint direction tau = e3 x gamma / s is undefined at the "
        "vertical, and the state there does not determine the motion (the continuation through "
        "the pole is not unique, rollingtop.contact.parallel): its vertical spin has no "
        "linearisation; simulate it instead"
    )


#: Relative tolerance of the particular case ``a3 = 0, I1 = I2 = I3`` (:func:`_particular`).
PARTICULAR_RTOL = 1e-12


def _particular(body: SphericalTop) -> tuple[str, ...]:
    """The slip along ``nu`` is an integral when the centre of mass is at the geometric centre
    and the ellipsoid of inertia is a sphere (``a3 = 0``, ``I1 = I2 = I3``; proved by
    :mod:`rollingtop.symbolic.parallel`, where the ansatz search finds this case)."""
    I1, I2, I3 = body.inertia
    spherical = abs(I2 - I1) <= PARTICULAR_RTOL * I1 and abs(I3 - I1) <= PARTICULAR_RTOL * I1
    balanced = abs(body.a3) <= PARTICULAR_RTOL * body.R
    return ("slip_nu",) if spherical and balanced else ()


MODEL = ContactModel(
    name="parallel",
    description="contact kept, no slip across the horizontal projection of the axis "
    "(the companion paper)",
    constraints=("contact (vp, gamma) = 0", "no slip across the axis projection (vp, tau) = 0"),
    free_velocity={"v_nu": 1},
    integrals_symmetric=("energy", "jellett"),
    integrals_general=("energy",),
    velocity=_velocity,
    symbolic_directions=_symbolic_directions,
    symbolic_velocity=_symbolic_velocity,
    vertical_direction=vertical_direction,
    vertical_eigenvalues=_vertical_eigenvalues,
    carries_direction=True,
    determined_through_vertical=False,
    colour="#9467bd",
    particular_integrals=_particular,
    symbolic_claims="rollingtop.symbolic.parallel:claims",
)
