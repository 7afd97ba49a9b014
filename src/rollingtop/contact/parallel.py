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
still arrives), and, integrated as they stand (the direction turning at ``-w_n / sigma`` down to
``|sigma| ~ 1e-11``, as rollingtop did before the disk below), trajectories computed at
``rtol = 1e-10, 1e-11, 1e-12`` differ by O(1) within one time unit after the first passage
although they agree to 1e-11 before it: round-off chose the continuation. Energy and
Jellett's integral stay conserved to the tolerance through every passage (they hold for any
reaction at the contact point).

**The regularised passage.** rollingtop carries the direction in the state's ``psi_nu`` (the
azimuth of ``nu = cos(psi_nu) alpha + sin(psi_nu) beta``, ``tau = nu x gamma``). Away from the
vertical it turns with the axis azimuth ``psi = atan2(beta3, alpha3)`` (``psi_nu' = psi'``), and
any offset ``delta = psi_nu - psi`` (modulo ``pi``: ``tau`` and ``-tau`` are one constraint)
relaxes at the rate ``k = sqrt(RELAX^2 + PASS_RELAX^2 |e3'_h|^2 / (s^2 + S_POLE^2))``, at
least ``RELAX`` (:func:`carried_rate`); the offset is round-off there, so this is the model's
constraint to round-off. Inside the disk ``s < S_POLE`` (``1e-6``, 0.2 seconds of arc) the
rate is weighted down by ``W = 1 - (1 - s^2 / S_POLE^2)^3``, so that it stays of order
``|e3'_h| / S_POLE`` (:func:`carried_rate`): the constraint direction, undefined at the
vertical, is held there instead of turning at ``|w_n| / s``. Any direction that moves smoothly
with the state keeps the constraint ideal, so energy and Jellett's integral are conserved
through every passage.

Why: without the disk, passages whose transverse speed ``w_n`` does not vanish (the exponent
``q`` above is negative; 14 of 20 random bodies and states meet one before ``t = 1e4``) need
reactions that grow like ``|v_nu w_n| / s`` and steps below ten units in the last place of
``t``: a step-size underflow, which is not a continuation. With the disk, 100 of 100 random
bodies and states run to ``t = 1e4`` at ``rtol = 1e-10`` (issue 26; ``docs/passages.py``), and the
continuation is a property of the equations rather than of round-off: runs at ``rtol = 1e-10``
to ``1e-12`` approach the run at ``1e-13`` as the tolerance shrinks, through every passage
(measured after 40 time units and several passages: 1.6e-5, 1.2e-6, 8e-8). The continuation depends
on ``S_POLE`` (weakly: the state just after the first passage of ``tests/contact``'s seed-0 state
moves by 0.13 from ``S_POLE = 1e-6`` to ``1e-8``, by 0.05 from ``1e-7``): it is the regularised
model's, which the one-parameter family of exact continuations leaves free to choose. Blending
in the pole rate ``K*`` inside the disk (the continuation without the ``|sigma|^q`` term) was
tried and not kept: it brought back underflows (2 to 30 of 100 runs) and lost the convergence in
the tolerance.

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
from rollingtop._layout import CONTACT_PARAMS
from rollingtop._types import ComplexArray, Float3, Float6, FloatArray, Workspace
from rollingtop.contact._base import (
    ContactModel,
    FreeVelocity,
    RuleParameter,
    Symbolic,
    Vertical,
    contact_arm,
)
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import (
    contact_arm_rate,
    contact_row,
    free_forces,
    normal_row,
    row_bias,
)
from rollingtop.contact.meridian import horizontal_basis, vertical_direction

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: Radius (in ``s = sqrt(1 - gamma3^2)``) of the disk about the vertical inside which the
#: carried direction turns at a bounded rate (:func:`carried_rate`, module docstring).
S_POLE = 1e-6
#: Rate (per unit time) at which the carried azimuth relaxes towards the axis azimuth modulo
#: ``pi`` everywhere; the offset it removes is round-off, or what a passage left.
RELAX = 1.0
#: Relaxation per unit of the axis's turn ``|e3'_h| / s`` near the vertical: a passage's offset
#: decays like ``(S_POLE / s)^PASS_RELAX`` as the axis moves away (module docstring).
PASS_RELAX = 1.0
#: The rule's constants as the model's own parameters: a scenario's ``[contact]`` keys
#: (``pole_disk``, ``relax``, ``pass_relax``), in their slots of ``p`` in this order
#: (:meth:`rollingtop.contact.ContactModel.with_parameters`).
PARAMETERS = (
    RuleParameter(
        "pole_disk",
        S_POLE,
        "radius (in s = sqrt(1 - gamma3^2)) of the disk about the vertical "
        "inside which the carried constraint direction turns at a bounded rate",
        maximum=1.0,
    ),
    RuleParameter(
        "relax", RELAX, "rate at which the carried direction relaxes to the axis azimuth"
    ),
    RuleParameter(
        "pass_relax", PASS_RELAX, "relaxation per unit of the axis's turn near the vertical"
    ),
)


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
    p: FloatArray,
    y: FloatArray,
    t1: float,
    t2: float,
    t3: float,
    td1: float,
    td2: float,
    td3: float,
) -> Float3:
    """``w'`` under the rows ``(vp, gamma) = 0`` and ``(vp, t) = 0`` with ``t' = td``: the
    2x2 multiplier system of :mod:`rollingtop._compiled._kernel`, written out for the pole rate
    (which needs ``w'`` at two trial rates, without a workspace)."""
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


@kernel  # the analysis of the exact model's pole; the integration does not call it
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
def rule(p: FloatArray) -> tuple[float, float, float]:
    """The passage rule's ``(S_POLE, RELAX, PASS_RELAX)``: the module's constants plus ``p``'s
    contact slots, their offsets (:data:`PARAMETERS`,
    :meth:`rollingtop.contact.ContactModel.params`; 0: the constants)."""
    return (
        S_POLE + p[CONTACT_PARAMS],
        RELAX + p[CONTACT_PARAMS + 1],
        PASS_RELAX + p[CONTACT_PARAMS + 2],
    )


@inline
def carried_rate(p: FloatArray, y: FloatArray) -> float:
    """``psi_nu'``: the rate of the axis azimuth ``psi = atan2(beta3, alpha3)``, with the offset
    ``delta = psi_nu - psi`` (modulo ``pi``) relaxed, both weighted down inside the disk
    ``s < S_POLE`` so that the rate stays of order ``|e3'_h| / S_POLE`` (module docstring):

        psi_nu' = W(s^2 / S_POLE^2) (psi' - k sin(2 delta) / 2),
        k = sqrt(RELAX^2 + PASS_RELAX^2 |e3'_h|^2 / (s^2 + S_POLE^2)),

    with ``W(u) = 1 - (1 - u)^3`` for ``u < 1`` and 1 beyond (``C^2`` at ``u = 1``); ``k`` is
    smooth where the axis stops, which ``RELAX + PASS_RELAX |e3'_h| / ...`` would not be. Written
    with ``s^2 psi' = alpha3 beta3' - beta3 alpha3'`` and ``s^2 sin(2 delta)`` as polynomials in
    ``alpha3, beta3``, it has no ``atan2`` and no division by ``s``: smooth everywhere, the
    vertical included."""
    s_pole, relax, pass_relax = rule(p)
    w1, w2 = y[3], y[4]
    a3_, b3 = y[8], y[11]
    a3d = y[6] * w2 - y[7] * w1  # alpha' = alpha x w (body frame), third component
    b3d = y[9] * w2 - y[10] * w1
    s2 = a3_ * a3_ + b3 * b3
    turn = a3_ * b3d - b3 * a3d  # s^2 psi'
    c2, n2 = math.cos(2.0 * y[17]), math.sin(2.0 * y[17])
    offset = n2 * (a3_ * a3_ - b3 * b3) - c2 * (2.0 * a3_ * b3)  # s^2 sin(2 delta)
    k = math.sqrt(
        relax * relax + pass_relax * pass_relax * (a3d * a3d + b3d * b3d) / (s2 + s_pole * s_pole)
    )
    numerator = turn - 0.5 * k * offset
    if s2 >= s_pole * s_pole:
        far: float = numerator / s2
        return far
    u = s2 / (s_pole * s_pole)
    near: float = numerator * (3.0 - 3.0 * u + u * u) / (s_pole * s_pole)  # W(u) / s^2
    return near


@inline
def tau_of(p: FloatArray, y: FloatArray) -> Float6:
    """The carried constraint direction and its rate (:func:`carried_rate`)."""
    t1, t2, t3 = tau_carried(y)
    td1, td2, td3 = tau_rate(y, t1, t2, t3, carried_rate(p, y))
    return t1, t2, t3, td1, td2, td3


@inline
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
    _, nu = horizontal_basis(gamma, omega, alpha, beta)  # at the vertical: the carried one
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
    symbolic=Symbolic(
        _symbolic_directions, _symbolic_velocity, claims="rollingtop.symbolic.parallel:claims"
    ),
    vertical=Vertical(
        direction=vertical_direction,
        eigenvalues=_vertical_eigenvalues,
        carries_direction=True,
        determined=False,
    ),
    colour="#9467bd",
    particular_integrals=_particular,
    parameters=PARAMETERS,
)
