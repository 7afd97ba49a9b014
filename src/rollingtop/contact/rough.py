"""Rough plane: rolling without slipping, ``vp = 0`` (Routh's sphere for a symmetric body).

The three rows are ``(vp, e_i) = 0`` along the body axes: they span the same conditions as
``(vp, alpha) = (vp, beta) = (vp, gamma) = 0`` and their directions do not move in the body.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline
from rollingtop._types import Float3, Float6, FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, Symbolic, Vertical, contact_arm
from rollingtop.contact._rows import contact_arm_rate, contact_row, free_forces

#: The stepper's stage loop inlines this model's right-hand side (short closed form: fast, and
#: cheap to compile twice; :data:`rollingtop._compiled._template._dispatch.INLINE_RHS`).
INLINE_RHS = True

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint rows ``(vp, e1) = (vp, e2) = (vp, e3) = 0``; returns 3."""
    contact_row(p, y, 0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, J, bias, dirs)
    return 3


@inline
def _rough_matrix(p: FloatArray, r1: float, r2: float, r3: float) -> Float6:
    """``A = J M^-1 J^T`` of the rough model's rows ``J_k = (e_k, r x e_k)`` (lower triangle):
    ``A = 1/m + sum_j (r x e_k)_j (r x e_l)_j / I_j`` with ``r x e1 = (0, r3, -r2)``,
    ``r x e2 = (-r3, 0, r1)``, ``r x e3 = (r2, -r1, 0)``."""
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    A11 = im + r3 * r3 * i2 + r2 * r2 * i3
    A22 = im + r3 * r3 * i1 + r1 * r1 * i3
    A33 = im + r2 * r2 * i1 + r1 * r1 * i2
    A21 = -r1 * r2 * i3
    A31 = -r1 * r3 * i2
    A32 = -r2 * r3 * i1
    return A11, A21, A22, A31, A32, A33


@inline
def _solve3(
    A11: float,
    A21: float,
    A22: float,
    A31: float,
    A32: float,
    A33: float,
    b1: float,
    b2: float,
    b3: float,
) -> Float3:
    """``A^-1 b`` for a 3x3 SPD ``A`` (lower triangle) by Cholesky, in scalars."""
    L11 = math.sqrt(A11)
    L21 = A21 / L11
    L31 = A31 / L11
    L22 = math.sqrt(A22 - L21 * L21)
    L32 = (A32 - L31 * L21) / L22
    L33 = math.sqrt(A33 - L31 * L31 - L32 * L32)
    z1 = b1 / L11
    z2 = (b2 - L21 * z1) / L22
    z3 = (b3 - L31 * z1 - L32 * z2) / L33
    x3 = z3 / L33
    x2 = (z2 - L32 * x3) / L22
    x1 = (z1 - L21 * x2 - L31 * x3) / L11
    return x1, x2, x3


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations for the rows ``(vp, e_k) = 0``: with
    ``J u = vp = v + w x r`` the multipliers are the contact force ``lambda`` itself,
    ``A lambda = -w x r' - f_v / m - (I^-1 f_w) x r`` (the bias of row ``k`` is
    ``(r' x e_k, w) = (w x r')_k``), then ``m v' = f_v + lambda`` and
    ``I w' = f_w + r x lambda``."""
    w1, w2, w3 = y[3], y[4], y[5]
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = free_forces(p, y)
    q1, q2, q3 = f4 * i1, f5 * i2, f6 * i3  # I^-1 f_w
    c1 = -(w2 * rd3 - w3 * rd2) - f1 * im - (q2 * r3 - q3 * r2)
    c2 = -(w3 * rd1 - w1 * rd3) - f2 * im - (q3 * r1 - q1 * r3)
    c3 = -(w1 * rd2 - w2 * rd1) - f3 * im - (q1 * r2 - q2 * r1)
    A11, A21, A22, A31, A32, A33 = _rough_matrix(p, r1, r2, r3)
    l1, l2, l3 = _solve3(A11, A21, A22, A31, A32, A33, c1, c2, c3)
    dy[0] = (f1 + l1) * im
    dy[1] = (f2 + l2) * im
    dy[2] = (f3 + l3) * im
    dy[3] = (f4 + r2 * l3 - r3 * l2) * i1
    dy[4] = (f5 + r3 * l1 - r1 * l3) * i2
    dy[5] = (f6 + r1 * l2 - r2 * l1) * i3
    # what reaction() needs: the force directions are the body axes
    dirs, lam = ws[2], ws[4]
    for k in range(3):
        for c in range(3):
            dirs[k, c] = 1.0 if k == c else 0.0
    lam[0], lam[1], lam[2] = l1, l2, l3
    return 3


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection
    (:func:`rollingtop._compiled._template.dynamics.project`):
    ``lambda = A^-1 vp``, ``v <- v - lambda / m``, ``w <- w - I^-1 (r x lambda)``."""
    R, m, a3 = p[0], p[1], p[3]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3 = -R * g1, -R * g2, -R * g3 - a3
    w1, w2, w3 = y[3], y[4], y[5]
    c1 = y[0] + w2 * r3 - w3 * r2
    c2 = y[1] + w3 * r1 - w1 * r3
    c3 = y[2] + w1 * r2 - w2 * r1
    A11, A21, A22, A31, A32, A33 = _rough_matrix(p, r1, r2, r3)
    l1, l2, l3 = _solve3(A11, A21, A22, A31, A32, A33, c1, c2, c3)
    y[0] -= l1 / m
    y[1] -= l2 / m
    y[2] -= l3 / m
    y[3] -= (r2 * l3 - r3 * l2) / p[4]
    y[4] -= (r3 * l1 - r1 * l3) / p[5]
    y[5] -= (r1 * l2 - r2 * l1) / p[6]


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    return -np.cross(omega, contact_arm(body, gamma))


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    return [sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr


def _vertical_spin(body: SphericalTop, pole: int) -> float:
    """Critical spin of the vertical spin on the pole ``pole`` (+1 south, -1 north), rolling
    without slipping: with ``a = pole a3`` (the centre of mass above the sphere's centre) and
    ``l = R + a`` its height above the plane, stable for
    ``w3 > 2 sqrt(m g a (I1 + m l^2)) / (I3 + m R l)``; every spin when ``a <= 0``.

    ``I1 + m l^2`` is the moment of inertia about the contact point across the axis, and
    ``I3 + m R l`` the spin's gyroscopic moment once rolling couples the tilt rate to the
    centre's velocity. Found by the linearisation (:mod:`rollingtop.stability`) and
    held to it in the tests to round-off on several bodies; it reduces to Routh's classical
    condition for an eccentric sphere.
    """
    a = pole * body.a3
    if a <= 0.0:
        return 0.0
    height = body.R + a
    return (
        2.0
        * math.sqrt(body.m * body.g * a * (body.I1 + body.m * height * height))
        / (body.I3 + body.m * body.R * height)
    )


MODEL = ContactModel(
    name="rough",
    description="rolling without slipping (vp = 0)",
    constraints=("no slip (vp, e1) = 0", "no slip (vp, e2) = 0", "no slip (vp, e3) = 0"),
    free_velocity={},
    integrals_symmetric=("energy", "jellett", "routh"),
    reduction=("jellett", "routh"),
    integrals_general=("energy",),
    velocity=_velocity,
    symbolic=Symbolic(_symbolic_directions, _symbolic_velocity),
    vertical=Vertical(spin=_vertical_spin),
    colour="#d62728",
)
