"""The shell-with-rotor realization of the paper's constraint (paper Sec. 1, Fig. 2).

A light spherical shell (radius ``R``, mass ``ms``, moment of inertia ``Js`` about any
diameter, centre ``O`` at its geometric centre) rolls without slipping on the plane; a heavy
axisymmetric rotor -- the scenario's body: mass ``m``, central inertia ``diag(I1, I2, I3)``,
centre of mass ``C`` at ``a3 e3`` from ``O`` -- spins freely (frictionless bearing) about the
axis ``e3``, fixed in the shell through ``O``.

**State.** The rotor's, as for every model (``v`` its centre of mass's velocity, ``w`` its
angular velocity, the frame; body frame = the rotor's), and in the last slot ``y[17]`` the
shell's spin relative to the rotor, ``delta = Omega3 - w3``: the shell turns with
``Omega = w + delta e3`` (the axis is common, so the two angular velocities differ only along
it). The shell's no-slip condition ``v_O + Omega x (-R gamma) = 0``, ``v_O = v - w x a``, gives

    v = a3 w x e3 + R (w + delta e3) x gamma,

three conditions on ``(v, w, delta)``; ``q = (w, delta)`` are the independent velocities. For
the rotor this is the paper's constraint: its contact point ``vp = v + w x r`` moves with
``vp = R delta (e3 x gamma) = R s delta tau`` (only across the axis projection), so the rotor
obeys the meridian model's kinematics for every ``delta``; the shell's inertia decides
``delta``. With ``ms = Js = 0`` the pair *is* the meridian model (paper: "it is easy to show";
:mod:`rollingtop.symbolic.shell_rotor` derives it).

**Equations.** Kinetic energy ``T = m v^2/2 + (w, I w)/2 + ms v_O^2/2 + Js |Omega|^2/2``, the
rotor's weight at ``C`` and the shell's at ``O``, the contact force ``lambda`` at the contact
point. Poincare's equations in the quasi-velocities ``u = (v, w, delta)`` (momenta
``p = M u``, :func:`momenta`) are

    p_v' = p_v x w - (m + ms) g gamma + lambda
    p_w' = p_w x w + p_v x v + ms g a3 e3 x gamma + r x lambda
    p_delta' = -R (lambda, e3 x gamma).

With ``u = T(gamma) q`` and ``u' = T q' + k``, ``k = (R Omega x gamma', 0, 0)``, the reaction
drops out of ``T^T (M u' - F) = 0``: a 4x4 SPD system ``(T^T M T) q' = T^T (F - M k)``
(:func:`accelerations`); then ``lambda = (M u')_v - F_v``.

**Integrals** (all proved by :mod:`rollingtop.symbolic.shell_rotor`): energy (the pair's,
:func:`rollingtop.contact._shell_pair.pair_energy`: the body's with the shell's terms); the rotor's
axial spin ``w3`` -- the bearing is frictionless and every force the shell exerts on the rotor acts
on the axis, so its torque about ``C`` has no ``e3`` component, and Euler's equation gives ``I3 w3'
= (I1 - I2) w1 w2 = 0`` for a symmetric rotor (Lagrange's integral ``I3 w3``); a Jellett integral
about the pair's centre of mass and the pair's ``F6``
(:func:`~rollingtop.contact._shell_pair.pair_jellett`,
:func:`~rollingtop.contact._shell_pair.pair_F6`; the model declares them,
:attr:`~rollingtop.contact.OwnVelocity.integrals`): as many as the meridian model has, which it
becomes as the shell's mass and inertia vanish.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline, kernel
from rollingtop._types import ComplexArray, FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, OwnVelocity, Symbolic, Vertical
from rollingtop.contact._rows import contact_row, normal_row
from rollingtop.contact._shell_pair import pair_energy, pair_F6, pair_jellett

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: Index of the shell's relative spin ``delta`` in the state (the slot other models use for
#: their carried direction ``psi_nu``).
DELTA = 17


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """The rotor's two constraint rows (those of the meridian model, in the unnormalised
    direction ``e3 - gamma3 gamma`` so that they stay regular at the vertical, where the second
    degenerates to 0): contact kept, and no slip of the rotor's contact point along the axis
    projection. The third condition involves ``delta`` (module docstring); the closed forms
    keep all three."""
    normal_row(p, y, 0, J, bias, dirs)
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    gd1, gd2, gd3 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3, g1 * w2 - g2 * w1
    d1, d2, d3 = -g3 * g1, -g3 * g2, 1.0 - g3 * g3
    dd1 = -gd3 * g1 - g3 * gd1
    dd2 = -gd3 * g2 - g3 * gd2
    dd3 = -2.0 * g3 * gd3
    contact_row(p, y, 1, d1, d2, d3, dd1, dd2, dd3, J, bias, dirs)
    return 2


@inline
def momenta(
    p: FloatArray, v1: float, v2: float, v3: float, w1: float, w2: float, w3: float, d: float
) -> tuple[float, float, float, float, float, float, float]:
    """``M u`` for ``u = (v, w, delta)``: ``p_v = m v + ms v_O``,
    ``p_w = I w - ms a3 e3 x v_O + Js Omega``, ``p_delta = Js Omega3`` with
    ``v_O = v - a3 w x e3`` and ``Omega = w + delta e3``."""
    m, a3, I1, I2, I3, ms, Js = p[1], p[3], p[4], p[5], p[6], p[7], p[8]
    o1, o2, o3 = v1 - a3 * w2, v2 + a3 * w1, v3  # v_O = v - a3 (w2, -w1, 0)
    return (
        m * v1 + ms * o1,
        m * v2 + ms * o2,
        m * v3 + ms * o3,
        I1 * w1 + ms * a3 * o2 + Js * w1,  # -ms a3 e3 x v_O = ms a3 (o2, -o1, 0)
        I2 * w2 - ms * a3 * o1 + Js * w2,
        I3 * w3 + Js * (w3 + d),
        Js * (w3 + d),
    )


@inline
def _column(
    p: FloatArray, g1: float, g2: float, g3: float, w1: float, w2: float, w3: float, d: float
) -> tuple[float, float, float]:
    """``v`` of the independent velocities ``q = (w, delta)``:
    ``a3 w x e3 + R (w + delta e3) x gamma``."""
    R, a3 = p[0], p[3]
    o1, o2, o3 = w1, w2, w3 + d
    return (
        a3 * w2 + R * (o2 * g3 - o3 * g2),
        -a3 * w1 + R * (o3 * g1 - o1 * g3),
        R * (o1 * g2 - o2 * g1),
    )


@kernel  # a call of its own: inlined in each of its 14 uses, it took 10 s to compile
def _dot_mt(
    p: FloatArray,
    g1: float,
    g2: float,
    g3: float,
    i: int,
    x1: float,
    x2: float,
    x3: float,
    x4: float,
    x5: float,
    x6: float,
    x7: float,
) -> float:
    """``(T e_i, x)``: column ``i`` of ``T`` (``q = e_i``) against the 7-vector ``x``."""
    w1 = 1.0 if i == 0 else 0.0
    w2 = 1.0 if i == 1 else 0.0
    w3 = 1.0 if i == 2 else 0.0
    d = 1.0 if i == 3 else 0.0
    c1, c2, c3 = _column(p, g1, g2, g3, w1, w2, w3, d)
    return c1 * x1 + c2 * x2 + c3 * x3 + w1 * x4 + w2 * x5 + w3 * x6 + d * x7


@kernel  # a call of its own (see _dot_mt)
def _gram(p: FloatArray, g1: float, g2: float, g3: float, i: int, j: int) -> float:
    """``(T^T M T)_ij``."""
    w1 = 1.0 if j == 0 else 0.0
    w2 = 1.0 if j == 1 else 0.0
    w3 = 1.0 if j == 2 else 0.0
    d = 1.0 if j == 3 else 0.0
    c1, c2, c3 = _column(p, g1, g2, g3, w1, w2, w3, d)
    m1, m2, m3, m4, m5, m6, m7 = momenta(p, c1, c2, c3, w1, w2, w3, d)
    return _dot_mt(p, g1, g2, g3, i, m1, m2, m3, m4, m5, m6, m7)


@inline
def _solve4(
    A11: float,
    A21: float,
    A22: float,
    A31: float,
    A32: float,
    A33: float,
    A41: float,
    A42: float,
    A43: float,
    A44: float,
    b1: float,
    b2: float,
    b3: float,
    b4: float,
) -> tuple[float, float, float, float]:
    """``A^-1 b`` for a 4x4 SPD ``A`` (lower triangle) by Cholesky, in scalars."""
    L11 = math.sqrt(A11)
    L21 = A21 / L11
    L31 = A31 / L11
    L41 = A41 / L11
    L22 = math.sqrt(A22 - L21 * L21)
    L32 = (A32 - L31 * L21) / L22
    L42 = (A42 - L41 * L21) / L22
    L33 = math.sqrt(A33 - L31 * L31 - L32 * L32)
    L43 = (A43 - L41 * L31 - L42 * L32) / L33
    L44 = math.sqrt(A44 - L41 * L41 - L42 * L42 - L43 * L43)
    z1 = b1 / L11
    z2 = (b2 - L21 * z1) / L22
    z3 = (b3 - L31 * z1 - L32 * z2) / L33
    z4 = (b4 - L41 * z1 - L42 * z2 - L43 * z3) / L44
    x4 = z4 / L44
    x3 = (z3 - L43 * x4) / L33
    x2 = (z2 - L32 * x3 - L42 * x4) / L22
    x1 = (z1 - L21 * x2 - L31 * x3 - L41 * x4) / L11
    return x1, x2, x3, x4


@inline
def accelerations(
    p: FloatArray, y: FloatArray
) -> tuple[float, float, float, float, float, float, float, float, float, float]:
    """``(v', w', delta', lambda)`` at ``y`` (module docstring), as ten scalars."""
    R, m, g, a3, ms = p[0], p[1], p[2], p[3], p[7]
    v1, v2, v3, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    d = y[DELTA]
    P1, P2, P3, P4, P5, P6, _ = momenta(p, v1, v2, v3, w1, w2, w3, d)
    G = (m + ms) * g
    # F: Poincare's right-hand sides without the reaction (Newton's form: the weights as forces)
    F1 = P2 * w3 - P3 * w2 - G * g1
    F2 = P3 * w1 - P1 * w3 - G * g2
    F3 = P1 * w2 - P2 * w1 - G * g3
    h = ms * g * a3  # the shell's weight at O: torque a3 ms g e3 x gamma about C
    F4 = P5 * w3 - P6 * w2 + P2 * v3 - P3 * v2 - h * g2
    F5 = P6 * w1 - P4 * w3 + P3 * v1 - P1 * v3 + h * g1
    F6 = P4 * w2 - P5 * w1 + P1 * v2 - P2 * v1
    # k = (R Omega x gamma', 0, 0), gamma' = gamma x w
    gd1, gd2, gd3 = g2 * w3 - g3 * w2, g3 * w1 - g1 * w3, g1 * w2 - g2 * w1
    o1, o2, o3 = w1, w2, w3 + d
    k1 = R * (o2 * gd3 - o3 * gd2)
    k2 = R * (o3 * gd1 - o1 * gd3)
    k3 = R * (o1 * gd2 - o2 * gd1)
    K1, K2, K3, K4, K5, K6, K7 = momenta(p, k1, k2, k3, 0.0, 0.0, 0.0, 0.0)
    b1 = _dot_mt(p, g1, g2, g3, 0, F1 - K1, F2 - K2, F3 - K3, F4 - K4, F5 - K5, F6 - K6, -K7)
    b2 = _dot_mt(p, g1, g2, g3, 1, F1 - K1, F2 - K2, F3 - K3, F4 - K4, F5 - K5, F6 - K6, -K7)
    b3 = _dot_mt(p, g1, g2, g3, 2, F1 - K1, F2 - K2, F3 - K3, F4 - K4, F5 - K5, F6 - K6, -K7)
    b4 = _dot_mt(p, g1, g2, g3, 3, F1 - K1, F2 - K2, F3 - K3, F4 - K4, F5 - K5, F6 - K6, -K7)
    wd1, wd2, wd3, dd = _solve4(
        _gram(p, g1, g2, g3, 0, 0),
        _gram(p, g1, g2, g3, 1, 0),
        _gram(p, g1, g2, g3, 1, 1),
        _gram(p, g1, g2, g3, 2, 0),
        _gram(p, g1, g2, g3, 2, 1),
        _gram(p, g1, g2, g3, 2, 2),
        _gram(p, g1, g2, g3, 3, 0),
        _gram(p, g1, g2, g3, 3, 1),
        _gram(p, g1, g2, g3, 3, 2),
        _gram(p, g1, g2, g3, 3, 3),
        b1,
        b2,
        b3,
        b4,
    )
    c1, c2, c3 = _column(p, g1, g2, g3, wd1, wd2, wd3, dd)
    vd1, vd2, vd3 = c1 + k1, c2 + k2, c3 + k3
    Q1, Q2, Q3, _, _, _, _ = momenta(p, vd1, vd2, vd3, wd1, wd2, wd3, dd)
    return vd1, vd2, vd3, wd1, wd2, wd3, dd, Q1 - F1, Q2 - F2, Q3 - F3


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """The pair's accelerations (:func:`accelerations`), ``delta'`` included (the kernel writes
    the kinematics first, :func:`direction_rate` a placeholder). The reaction's rows for
    :func:`rollingtop._compiled._kernel.reaction`: the contact force along the body axes."""
    vd1, vd2, vd3, wd1, wd2, wd3, dd, l1, l2, l3 = accelerations(p, y)
    dy[0], dy[1], dy[2], dy[3], dy[4], dy[5] = vd1, vd2, vd3, wd1, wd2, wd3
    dy[DELTA] = dd  # after the kinematics (rollingtop._compiled._template.dynamics.rhs)
    dirs, lam = ws[2], ws[4]
    for k in range(3):
        for c in range(3):
            dirs[k, c] = 1.0 if k == c else 0.0
    lam[0], lam[1], lam[2] = l1, l2, l3
    return 3


@inline
def direction_rate(p: FloatArray, y: FloatArray, variant: int) -> float:
    """0: the rate of the state's last slot, ``delta'``, is written by :func:`accel` with the
    accelerations (computed once)."""
    return 0.0


@inline
def sync_direction(y: FloatArray, variant: int) -> None:
    """Nothing to re-synchronise: the last slot is the shell's spin, not a direction."""


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Onto the constraints: ``v`` from the independent velocities ``(w, delta)`` (module
    docstring), which satisfies all three conditions exactly."""
    c1, c2, c3 = _column(p, y[12], y[13], y[14], y[3], y[4], y[5], y[DELTA])
    y[0], y[1], y[2] = c1, c2, c3


def relative_spin(body: SphericalTop, y: FloatArray) -> float:
    """The shell's spin relative to the rotor, ``delta``, for which the rotor state ``y``
    (``v``, ``w`` and the frame set, meridian-consistent) is the pair's: its contact point's
    slip across the axis projection is ``R s delta`` (module docstring). At a vertical axis
    (``s = 0``) the slip is 0 whatever the shell does: ``delta = 0`` is taken."""
    gamma, w = y[12:15], y[3:6]
    s = math.hypot(gamma[0], gamma[1])
    if s == 0.0:
        return 0.0
    r = -body.R * gamma - np.array([0.0, 0.0, body.a3])
    vp = y[0:3] + np.cross(w, r)
    tau = np.array([-gamma[1], gamma[0], 0.0]) / s
    return float(vp @ tau) / (body.R * s)


def outputs(body: SphericalTop, Y: FloatArray) -> dict[str, FloatArray]:
    """Per sample of the states ``Y`` (n, 18): the shell's angular velocity
    ``Omega = w + delta e3`` and the bearing's reaction torque on the rotor about its centre of
    mass, ``tau_b = I w' + w x I w`` (Euler's equation; perpendicular to ``e3``: the bearing is
    frictionless), body frame, each of shape (n, 3)."""
    Y = np.atleast_2d(np.asarray(Y, dtype=float))
    p = body.params
    omega = Y[:, 3:6].copy()
    omega[:, 2] += Y[:, DELTA]
    torque = np.empty((len(Y), 3))
    inertia = body.inertia
    for k, y in enumerate(Y):
        wd = np.array(_accelerations(p, y)[3:6])
        w = y[3:6]
        torque[k] = inertia * wd + np.cross(w, inertia * w)
    return {"shell_omega": omega, "bearing_torque": torque}


@kernel
def _accelerations(
    p: FloatArray, y: FloatArray
) -> tuple[float, float, float, float, float, float, float, float, float, float]:
    """:func:`accelerations`, callable from Python."""
    return accelerations(p, y)


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    """The rotor's ``v`` exactly as for the meridian model (free ``v_tau``). At a vertical axis
    the shell's spin does not move the contact point, which then cannot slip: only
    ``v_tau = 0`` is the pair's (an ``InitialStateError`` otherwise)."""
    from rollingtop.contact import meridian

    if gamma[0] == 0.0 and gamma[1] == 0.0 and free["v_tau"] != 0.0:
        from rollingtop._errors import InitialStateError

        raise InitialStateError(
            f"v_tau = {free['v_tau']:g}: at a vertical axis the shell-rotor pair's contact point "
            "cannot slip (the shell's spin about the vertical does not move it); give v_tau = 0"
        )

    return meridian.MODEL.velocity(body, gamma, omega, alpha, beta, free)


def _vertical_eigenvalues(body: SphericalTop, omega3: float, pole: int) -> ComplexArray:
    """Not analysed: refused (ValueError, reported by :mod:`rollingtop.stability`)."""
    raise ValueError(
        "the shell-rotor pair's vertical spin is not linearised: the generic linearisation "
        "sees the rotor's state only, and the shell's spin is a further variable; simulate it"
    )


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    e3 = sp.Matrix([0, 0, 1])
    return [gamma, e3 - gamma[2] * gamma]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr + free[0] * tau


MODEL = ContactModel(
    name="shell-rotor",
    description="a shell rolling without slipping with a rotor spinning freely inside about "
    "its axis (the paper's Sec. 1 realization; [shell] mass and inertia)",
    constraints=("contact (vp, gamma) = 0", "no slip of the rotor along nu (vp, nu) = 0"),
    free_velocity={"v_tau": 1},
    integrals_symmetric=("energy", "lagrange", "jellett", "F6"),
    reduction=("M3", "jellett", "C2"),
    integrals_general=("energy",),
    velocity=_velocity,
    symbolic=Symbolic(
        _symbolic_directions, _symbolic_velocity, claims="rollingtop.symbolic.shell_rotor:claims"
    ),
    vertical=Vertical(eigenvalues=_vertical_eigenvalues),
    own=OwnVelocity(
        "shell_spin",
        relative_spin,
        {"energy": pair_energy, "jellett": pair_jellett, "F6": pair_F6},
    ),
    devices=("shell",),
    state_outputs=outputs,
    colour="#8c564b",
)
