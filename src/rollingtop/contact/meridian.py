"""The paper's model: no slip along the horizontal projection of the symmetry axis.

Kilin & Ivanova (2023), eqs. (2.4)-(2.6): contact is kept, ``f1 = (vp, gamma) = 0``, and the
contact point does not slip along ``nu = (e3 - gamma3 gamma) / sqrt(1 - gamma3^2)``,
``f2 = (vp, nu) = 0``; it slips freely across, along ``tau = e3 x gamma / sqrt(1 - gamma3^2)``.

**Pole cases.** ``nu`` is undefined when the axis is vertical. On the level sets ``C1 = M3``
(``C1 = -M3``) of the area and Lagrange integrals the south (north) pole can touch the plane
(paper Sec. 3.3), and the exact motion passes through the pole with ``nu`` continuous in the
fixed frame: its azimuth ``psi_nu`` turns at the finite rate ``psi' = -w_n / s``, which on these
level sets is ``M3 / (I1 (1 + gamma3))`` (``-M3 / (I1 (1 - gamma3))``). The direction computed
from the orientation alone cannot follow it: a numerical trajectory misses the pole by a tiny
distance, and there ``(e3 - gamma3 gamma)/s`` sweeps through every horizontal direction in a
tiny time, forcing huge reactions and stalling any integrator. So in a pole case the direction
is carried as a state variable instead: ``nu = cos(psi_nu) alpha + sin(psi_nu) beta`` with
``psi_nu' = M3 / (I1 (1 +- gamma3))`` and ``M3 = I3 w3`` from the state -- the limit of the
constraint direction along the motion, regular at the pole. Away from the pole
(``s > RESYNC_S``) ``psi_nu`` is re-synchronised to the geometric azimuth modulo ``pi`` after
every step, so there the constraint is exactly the paper's; nearer the pole too where the axis
moves across its meridian rather than towards the pole (``RESYNC_ANGLE``), as a sleeping top
does. After each pole passage ``psi_nu = psi + pi``: the sign ``sigma = cos(psi_nu - psi)`` tells
on which side of the pole the motion is, which is what keeps ``F6`` (odd under the passage)
continuous in the monitoring.

**No spin.** On ``M3 = C1 = 0`` both poles are pole levels at once (:func:`pole_case` says
``"both"``, :func:`select_variant` takes the south variant) and the exact rate is ``psi_nu' = 0``:
the motion is planar rocking in a fixed vertical plane, through either pole. ``M3 = I3 w3`` read
from the state is exactly 0 only in special orientations (round-off of the torque about ``e3``
gives ``|w3|`` of a few ulps of ``|w|`` otherwise), and the variant's rate
``M3 / (I1 (1 + gamma3))`` would turn such noise into a huge turn of ``nu`` at the north pole
(and ``0/0`` there for an exact zero; measured: a general-orientation rocking motion stalled with
"step size underflow" before this rule). So :func:`psi_nu_rate` is exactly 0 while
``|M3| <= NO_SPIN_TOLERANCE |I w|``: this is the no-spin level to round-off, where the pole the
variant is not made for is no wall but a passage.

**Vertical start.** At a vertical axis ``gamma = (0, 0, +-1)`` the geometric ``nu`` is undefined,
but every such state is on a pole level: ``C1 = (I w, gamma) = +-I3 w3 = +-M3`` exactly, whatever
``w1, w2``. So a motion from it is started in the pole variant with the carried direction
(:func:`vertical_direction`). That direction is not free when the axis moves: the axis leaves the
vertical along ``gamma' = gamma x w``, and the meridian direction of the motion for ``t -> 0+``
is ``nu = (e3 - gamma3 gamma)/s -> (w x e3)/|w x e3|`` at either pole, horizontal and across the
horizontal part of ``w``. That is the only ``nu`` with which the state lies on its level's motion
(``w_n = (w, n) = 0`` at the pole, as ``w_n = (M3 gamma3 - C1)/(I1 s) -> 0`` requires; with
another ``nu`` the carried direction would leave the meridian plane at once and the area integral
would not hold). Only when ``w1 = w2 = 0`` (the sleeping top) is ``nu`` free; it is then taken
along the fixed ``x`` axis, ``nu = alpha`` (``psi_nu = 0``). An axis within
:data:`POLE_TOLERANCE` of the vertical counts as vertical and is set exactly vertical
(:func:`rollingtop.dynamics.state.initial_state`): so near it the geometric ``nu`` (which sweeps
through all horizontal directions there) is never used to start a motion.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline
from rollingtop._types import Float6, FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, Symbolic, Vertical, contact_arm
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import contact_row, normal_row, sync_azimuth
from rollingtop.contact._rows import sync_direction as sync_geometric

#: The stepper's stage loop inlines this model's right-hand side (short closed form: fast, and
#: cheap to compile twice; :data:`rollingtop._compiled._template._dispatch.INLINE_RHS`).
INLINE_RHS = True

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: The variants (kernels of their own, :class:`~rollingtop.contact._base.Kernel`): the pole
#: cases, with the constraint direction carried in ``psi_nu``; chosen by :func:`select_variant`.
#: In compiled code a variant is its index: 0 the geometric ``nu``, 1 south, 2 north.
VARIANTS = ("south", "north")
GEOMETRIC, SOUTH, NORTH = 0, 1, 2
#: Below this ``sqrt(gamma1^2 + gamma2^2)`` the axis counts as vertical: the geometric ``nu`` is
#: undefined (or sweeps through all directions), and an initial state there is set exactly
#: vertical and started with the carried direction (module docstring, "Vertical start").
POLE_TOLERANCE = 1e-8
#: ``|C1 -+ M3|`` at most this times ``max(|M3|, |C1|)`` is a pole case: the one decision used by
#: the simulator (:func:`select_variant`), the reduction and every command (:func:`pole_case`).
#: Small enough that the near-pole levels ``|C1 -+ M3| >= 1e-12 max(|M3|, |C1|)`` are resolved
#: as what they are (orbits reflected at a thin wall next to the pole), large enough to absorb the
#: round-off of ``C1`` computed from a state (a few ulps).
POLE_CASE_TOLERANCE = 1e-13
#: Above this ``s`` the carried azimuth is re-synchronised with the geometric one (modulo pi).
RESYNC_S = 0.05
#: Closer to the pole, ``psi_nu`` is re-synchronised where ``s > RESYNC_S_MIN`` and the axis moves
#: across its meridian (the sine of the angle between the tilt and its rate above
#: ``RESYNC_ANGLE``). Without it a sleeping top, which stays near the pole and precesses, lets the
#: carried direction drift off the tilt: the mismatch ``eps`` and ``C1 - M3`` feed each other
#: (``eps' = (M3 - C1) / (I1 s^2)``, ``C1' ~ a3 lambda s eps``), growing from round-off.
RESYNC_S_MIN = 1e-7
RESYNC_ANGLE = 0.5
#: ``|M3| = |I3 w3|`` at most this times ``|I w|`` counts as no spin in the carried direction's
#: rate (:func:`psi_nu_rate`): well above the round-off that the torque about ``e3`` leaves in
#: ``w3`` of a planar motion (a few 1e-16 ``|w|``, measured), far below any spin that matters (a
#: south level with ``|M3| = 1e-10 |I w|`` has its north-pole wall within ~1e-10 rad of the pole,
#: where a passage and a reflection with ``psi`` turned by pi are the same motion).
NO_SPIN_TOLERANCE = 1e-10


@inline
def nu_geometric(y: FloatArray) -> Float6:
    """``nu = (e3 - gamma3 gamma)/s`` and its time derivative along the motion.

    ``s = sqrt(gamma1^2 + gamma2^2)`` (free of cancellation near the poles) and
    ``nu = (-gamma3 gamma1 / s, -gamma3 gamma2 / s, s)`` for ``|gamma| = 1``.
    """
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    gd1 = g2 * w3 - g3 * w2
    gd2 = g3 * w1 - g1 * w3
    gd3 = g1 * w2 - g2 * w1
    s = math.sqrt(g1 * g1 + g2 * g2)
    sd = (g1 * gd1 + g2 * gd2) / s
    n1 = -g3 * g1 / s
    n2 = -g3 * g2 / s
    nd1 = -(gd3 * g1 + g3 * gd1) / s - n1 * sd / s
    nd2 = -(gd3 * g2 + g3 * gd2) / s - n2 * sd / s
    return n1, n2, s, nd1, nd2, sd


@inline
def psi_nu_rate(p: FloatArray, y: FloatArray, north: bool) -> float:
    """``psi_nu' = M3 / (I1 (1 + gamma3))`` (south) or ``-M3 / (I1 (1 - gamma3))`` (north);
    exactly 0 with no spin, ``|M3| <= NO_SPIN_TOLERANCE |I w|`` (see the module docstring)."""
    M3 = p[6] * y[5]
    Iw1, Iw2 = p[4] * y[3], p[5] * y[4]
    if M3 * M3 <= NO_SPIN_TOLERANCE * NO_SPIN_TOLERANCE * (Iw1 * Iw1 + Iw2 * Iw2 + M3 * M3):
        return 0.0
    rate: float
    if north:
        rate = -M3 / (p[4] * (1.0 - y[14]))
        return rate
    rate = M3 / (p[4] * (1.0 + y[14]))
    return rate


@inline
def nu_carried(p: FloatArray, y: FloatArray, north: bool) -> Float6:
    """Carried ``nu = cos(psi_nu) alpha + sin(psi_nu) beta`` (pole cases) and
    ``nu' = psi_nu' (gamma x nu) + nu x w``."""
    c, s = math.cos(y[17]), math.sin(y[17])
    n1 = c * y[6] + s * y[9]
    n2 = c * y[7] + s * y[10]
    n3 = c * y[8] + s * y[11]
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    rate = psi_nu_rate(p, y, north)
    nd1 = rate * (g2 * n3 - g3 * n2) + (n2 * w3 - n3 * w2)
    nd2 = rate * (g3 * n1 - g1 * n3) + (n3 * w1 - n1 * w3)
    nd3 = rate * (g1 * n2 - g2 * n1) + (n1 * w2 - n2 * w1)
    return n1, n2, n3, nd1, nd2, nd3


@inline
def nu_of(p: FloatArray, y: FloatArray, variant: int) -> Float6:
    """The constraint direction and its derivative for ``variant`` (geometric or carried)."""
    if variant == GEOMETRIC:
        return nu_geometric(y)
    return nu_carried(p, y, variant == NORTH)


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint rows ``f1`` (normal) and ``f2`` (along ``nu``, geometric or carried by
    ``variant``); returns their number, 2."""
    normal_row(p, y, 0, J, bias, dirs)
    n1, n2, n3, nd1, nd2, nd3 = nu_of(p, y, variant)
    contact_row(p, y, 1, n1, n2, n3, nd1, nd2, nd3, J, bias, dirs)
    return 2


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations (:func:`.rhs_contact` with the row along ``nu``)."""
    n1, n2, n3, nd1, nd2, nd3 = nu_of(p, y, variant)
    return rhs_contact(p, y, dy, ws, True, n1, n2, n3, nd1, nd2, nd3)


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection (:func:`.project_contact` with the row along
    ``nu``)."""
    n1, n2, n3, _, _, _ = nu_of(p, y, variant)
    project_contact(p, y, True, n1, n2, n3)


@inline
def direction_rate(p: FloatArray, y: FloatArray, variant: int) -> float:
    """``psi_nu'``: :func:`psi_nu_rate` in a pole case, 0 otherwise (``psi_nu`` then follows the
    axis azimuth, :func:`sync_direction`)."""
    if variant == GEOMETRIC:
        return 0.0
    return psi_nu_rate(p, y, variant == NORTH)


@inline
def sync_direction(y: FloatArray, variant: int) -> None:
    """Re-synchronise ``psi_nu`` with the axis azimuth after a step: modulo ``2 pi`` with the
    geometric ``nu`` (where the azimuth is defined); in a pole case modulo ``pi`` (keeping the
    side of the pole), only away from the pole (``s > RESYNC_S``) or where the axis moves across
    its meridian (module docstring)."""
    if variant == GEOMETRIC:
        sync_geometric(y, variant)
        return
    s = math.sqrt(y[8] * y[8] + y[11] * y[11])
    if s <= RESYNC_S:
        # Near the pole only where the axis moves across its meridian rather than towards the
        # pole (RESYNC_ANGLE): there the geometric direction is well defined although s is
        # small (a sleeping top's precession), while along a passage it would carry the
        # numerical miss distance of the pole.
        if s <= RESYNC_S_MIN:
            return
        w1, w2 = y[3], y[4]
        da = y[6] * w2 - y[7] * w1  # alpha3' (alpha' = alpha x w): the tilt's rate
        db = y[9] * w2 - y[10] * w1  # beta3'
        across = abs(y[8] * db - y[11] * da)
        if across <= RESYNC_ANGLE * s * math.sqrt(da * da + db * db):
            return
    sync_azimuth(y, math.pi)


def pole_case(M3: float, C1: float, scale: float = 0.0) -> str | None:
    """Which pole the level set ``(M3, C1)`` lets touch the plane (paper Sec. 3.3).

    Returns ``"south"`` when ``C1 = M3`` (``gamma3 = 1`` can be reached), ``"north"`` when
    ``C1 = -M3``, ``"both"`` when ``M3 = C1 = 0`` (no spin: both poles at once), else ``None``;
    equalities hold within :data:`POLE_CASE_TOLERANCE` times ``max(|M3|, |C1|, scale)``.
    ``scale`` is the size of the terms ``M3, C1`` were computed from, where they may cancel: for
    values read from a state, ``|I w|`` (``C1 = (I w, gamma)`` of a motion with no spin is a few
    ulps of ``|I w|``, not 0). Without it (0) a value counts as zero only when it is exactly 0.
    """
    M3, C1 = float(M3), float(C1)
    scale = max(abs(M3), abs(C1), float(scale))
    if scale == 0.0 or max(abs(M3), abs(C1)) <= POLE_CASE_TOLERANCE * scale:
        return "both"
    if abs(C1 - M3) <= POLE_CASE_TOLERANCE * scale:
        return "south"
    if abs(C1 + M3) <= POLE_CASE_TOLERANCE * scale:
        return "north"
    return None


def select_variant(body: SphericalTop, y: FloatArray) -> str | None:
    """The variant for a motion from state ``y``: ``"south"`` / ``"north"`` on the pole level
    sets ``C1 = +-M3`` of a symmetric body (within :data:`POLE_CASE_TOLERANCE`), else ``None``
    (the geometric ``nu``). A vertical axis is always on a pole level (``C1 = +-M3`` there, see
    the module docstring); no spin (``M3 = C1 = 0`` to round-off of ``|I w|``) takes the south
    variant, whose direction then does not turn."""
    if not body.symmetric:
        return None
    Iw = body.inertia * np.asarray(y[3:6], dtype=float)
    M3 = body.I3 * y[5]
    C1 = float(np.dot(Iw, y[12:15]))
    pole = pole_case(M3, C1, math.hypot(*Iw))  # no square overflows
    if pole == "north":
        return "north"
    if pole is not None:  # "south", or "both" (no spin: the carried direction does not turn)
        return "south"
    return None


def tau_nu(gamma: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Horizontal unit vectors ``tau = e3 x gamma / s`` and ``nu = (e3 - gamma3 gamma) / s``."""
    g1, g2, g3 = gamma
    s = math.hypot(g1, g2)
    return np.array([-g2, g1, 0.0]) / s, np.array([-g3 * g1 / s, -g3 * g2 / s, s])


def horizontal_basis(
    gamma: FloatArray, omega: FloatArray, alpha: FloatArray, beta: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """``(tau, nu)`` of a state being built (:func:`tau_nu`); at a vertical axis, where they are
    undefined, ``nu`` is the carried direction the axis leaves in
    (:func:`vertical_direction`) and ``tau = nu x gamma``. The initial velocity of every model
    with a direction in the plane of ``nu`` and ``tau`` (meridian, parallel, oblique)."""
    if gamma[0] == 0.0 and gamma[1] == 0.0:
        psi_nu = vertical_direction(omega, alpha, beta)
        nu = math.cos(psi_nu) * np.asarray(alpha) + math.sin(psi_nu) * np.asarray(beta)
        return np.cross(nu, gamma), nu
    return tau_nu(gamma)


def vertical_direction(
    omega: FloatArray, alpha: FloatArray, beta: FloatArray, psi_nu: float = 0.0
) -> float:
    """Azimuth ``psi_nu`` of the carried constraint direction at a vertical axis.

    ``nu = cos(psi_nu) alpha + sin(psi_nu) beta`` (the convention of :func:`nu_carried`): the
    azimuth of ``nu`` in the fixed frame, from the fixed ``x`` axis (``alpha``) towards ``y``
    (``beta``). At ``gamma = (0, 0, +-1)`` it is the direction in which the axis leaves the
    vertical, ``nu = (w x e3)/|w x e3|`` (module docstring); when ``w1 = w2 = 0`` the axis does
    not leave it and ``nu`` is free: ``psi_nu`` is returned unchanged (0 for a new state:
    ``nu = alpha``).
    """
    w1, w2 = float(omega[0]), float(omega[1])
    if w1 == 0.0 and w2 == 0.0:
        return float(psi_nu)
    nu = np.array([w2, -w1, 0.0])  # w x e3, horizontal at either pole; its length cancels
    return math.atan2(float(nu @ np.asarray(beta)), float(nu @ np.asarray(alpha)))


def _singular(body: SphericalTop, gamma: FloatArray) -> str | None:
    if gamma[0] == 0.0 and gamma[1] == 0.0 and not body.symmetric:
        return (
            f"the symmetry axis is vertical (gamma3 = {gamma[2]:+.12g}), where the meridian "
            "constraint direction nu = (e3 - gamma3 gamma)/sqrt(1 - gamma3^2) is undefined, and "
            f"the body is not dynamically symmetric (I1 = {body.I1:g}, I2 = {body.I2:g}): the "
            "direction is carried through the vertical only on the pole levels of a symmetric body"
        )
    return None


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    tau, _ = horizontal_basis(gamma, omega, alpha, beta)
    wxr = np.cross(omega, contact_arm(body, gamma))
    slip = free["v_tau"] + wxr @ tau  # contact-point velocity vp = slip * tau
    return -wxr + slip * tau


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    return [gamma, sp.Matrix([0, 0, 1]) - gamma[2] * gamma]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr + free[0] * tau  # contact velocity along tau only


def _vertical_spin(body: SphericalTop, pole: int) -> float:
    """Critical spin of the vertical spin on the pole ``pole`` (+1 south, -1 north).

    The vertical spin lies on the pole level ``C1 = pole M3`` of the reduction, where ``U`` is
    smooth through the pole (:mod:`rollingtop.reduction.level`); there, with ``a = pole a3`` and
    ``l = R + a``, ``U''(pole) = M3^2 (I1 + m l^2) / (4 I1^2) - m g a`` (expand
    ``q1 = M3 tan(theta/2)``, ``P = M3 ((R - a) tan(theta/2) + a theta)`` and
    ``m g a cos(theta)`` to second order). Stable for ``U'' > 0``:
    ``w3 > 2 I1 sqrt(m g a / (I1 + m l^2)) / I3``; every spin when ``a <= 0``. The constraint
    direction is undefined at the vertical, so this (and the eigenvalues,
    :attr:`~rollingtop.contact.Vertical.through_reduction`) comes from the reduction
    rather than from a linearisation in ``(v, w, gamma)``.
    """
    a = pole * body.a3
    if a <= 0.0:
        return 0.0
    height = body.R + a
    return (
        2.0
        * body.I1
        * math.sqrt(body.m * body.g * a / (body.I1 + body.m * height * height))
        / body.I3
    )


MODEL = ContactModel(
    name="meridian",
    description="contact kept, no slip along the horizontal projection of the axis (the paper)",
    constraints=("contact (vp, gamma) = 0", "no slip along the axis projection (vp, nu) = 0"),
    free_velocity={"v_tau": 1},
    integrals_symmetric=("energy", "lagrange", "jellett", "area", "F6"),
    integrals_general=("energy", "area"),
    velocity=_velocity,
    symbolic=Symbolic(_symbolic_directions, _symbolic_velocity),
    vertical=Vertical(
        singular=_singular,
        tolerance=POLE_TOLERANCE,
        direction=vertical_direction,
        variants=VARIANTS,
        select_variant=select_variant,
        spin=_vertical_spin,
        through_reduction=True,
    ),
    reduction=("M3", "C1", "C2"),
    colour="#1f77b4",
    devices=("roller", "shell", "skates"),
)
