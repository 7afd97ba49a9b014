"""Rubber rolling: no slip, ``vp = 0``, and no spin about the normal, ``(w, gamma) = 0``.

The rough model's three rows ``(vp, e_k) = 0`` along the body axes, plus a fourth row on the
angular velocity alone, ``J = (0, 0, 0, gamma)`` (``docs/model.md``, "Constraints"). Its reaction
is a torque ``mu gamma`` about the normal (no force: its row of force directions is 0, so the
contact force of :func:`rollingtop._compiled._kernel.reaction` is the no-slip rows' alone). Its
bias is ``(gamma', w) = (gamma x w, w) = 0``. Neither reaction does work (``vp = 0``,
``(w, gamma) = 0``): the energy is conserved; the torque changes the angular momentum about the
normal, so the rough model's Jellett integral and the area and Lagrange integrals are lost
(``rollingtop verify`` proves the energy and shows the others vary, ``tests/symbolic``). A body
of revolution keeps an integral linear in ``w``, ``rubber_spin = w3 sqrt(I3 J)``, through which
the model reduces to one degree of freedom (:mod:`rollingtop.reduction.rubber`; proved by
:mod:`rollingtop.symbolic.rubber`).

A body rolling this way cannot spin about a vertical symmetry axis: at ``gamma = (0, 0, +-1)``
the fourth row is ``w3 = 0`` (:attr:`~rollingtop.contact.ContactModel.has_vertical_spin`).
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, Symbolic, contact_arm
from rollingtop.contact._rows import contact_arm_rate, contact_row, free_forces
from rollingtop.contact.rough import _rough_matrix, _solve3

#: The stepper's stage loop inlines this model's right-hand side (short closed form: fast, and
#: cheap to compile twice; :data:`rollingtop._compiled._template._dispatch.INLINE_RHS`).
INLINE_RHS = True

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: The spin constraint, as an initial ``omega`` that violates it is told.
NO_SPIN = "(omega, gamma) = 0"


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint rows ``(vp, e_k) = 0`` (``k = 1, 2, 3``) and ``(w, gamma) = 0``; returns 4."""
    contact_row(p, y, 0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, J, bias, dirs)
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    for c in range(3):
        J[3, c] = 0.0
        dirs[3, c] = 0.0  # a torque: no force at the contact point
    J[3, 3], J[3, 4], J[3, 5] = g1, g2, g3
    # J' u = (gamma', w) with gamma' = gamma x w: zero up to round-off
    bias[3] = (g2 * w3 - g3 * w2) * w1 + (g3 * w1 - g1 * w3) * w2 + (g1 * w2 - g2 * w1) * w3
    return 4


@inline
def _solve4(
    p: FloatArray,
    r1: float,
    r2: float,
    r3: float,
    g1: float,
    g2: float,
    g3: float,
    c1: float,
    c2: float,
    c3: float,
    c4: float,
) -> tuple[float, float, float, float]:
    """``A^-1 c`` for ``A = J M^-1 J^T`` of the four rows, by the Schur complement of the
    rough block ``A3`` (:func:`._rough_matrix`): with ``b_k = (r x e_k, I^-1 gamma)`` and
    ``A44 = (gamma, I^-1 gamma)``, ``mu = (c4 - b A3^-1 c) / (A44 - b A3^-1 b)`` and
    ``lambda = A3^-1 (c - mu b)``."""
    i1, i2, i3 = 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    q1, q2, q3 = g1 * i1, g2 * i2, g3 * i3  # I^-1 gamma
    b1 = r3 * q2 - r2 * q3  # (r x e1, I^-1 gamma), r x e1 = (0, r3, -r2)
    b2 = r1 * q3 - r3 * q1  # r x e2 = (-r3, 0, r1)
    b3 = r2 * q1 - r1 * q2  # r x e3 = (r2, -r1, 0)
    A44 = g1 * q1 + g2 * q2 + g3 * q3
    A11, A21, A22, A31, A32, A33 = _rough_matrix(p, r1, r2, r3)
    x1, x2, x3 = _solve3(A11, A21, A22, A31, A32, A33, c1, c2, c3)
    z1, z2, z3 = _solve3(A11, A21, A22, A31, A32, A33, b1, b2, b3)
    mu = (c4 - b1 * x1 - b2 * x2 - b3 * x3) / (A44 - b1 * z1 - b2 * z2 - b3 * z3)
    return x1 - mu * z1, x2 - mu * z2, x3 - mu * z3, mu


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations: the rough model's (:func:`.rough.accel`) with the
    torque ``mu gamma`` and the row ``(w', gamma) = -(w, gamma') = 0``, whose right-hand side is
    ``-(gamma, I^-1 f_w)``; a 4x4 solve (:func:`_solve4`). Then ``m v' = f_v + lambda`` and
    ``I w' = f_w + r x lambda + mu gamma``."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = free_forces(p, y)
    q1, q2, q3 = f4 * i1, f5 * i2, f6 * i3  # I^-1 f_w
    c1 = -(w2 * rd3 - w3 * rd2) - f1 * im - (q2 * r3 - q3 * r2)
    c2 = -(w3 * rd1 - w1 * rd3) - f2 * im - (q3 * r1 - q1 * r3)
    c3 = -(w1 * rd2 - w2 * rd1) - f3 * im - (q1 * r2 - q2 * r1)
    c4 = -(g1 * q1 + g2 * q2 + g3 * q3)
    l1, l2, l3, mu = _solve4(p, r1, r2, r3, g1, g2, g3, c1, c2, c3, c4)
    dy[0] = (f1 + l1) * im
    dy[1] = (f2 + l2) * im
    dy[2] = (f3 + l3) * im
    dy[3] = (f4 + r2 * l3 - r3 * l2 + mu * g1) * i1
    dy[4] = (f5 + r3 * l1 - r1 * l3 + mu * g2) * i2
    dy[5] = (f6 + r1 * l2 - r2 * l1 + mu * g3) * i3
    # what reaction() needs: the force directions (body axes; none for the torque row)
    dirs, lam = ws[2], ws[4]
    for k in range(4):
        for c in range(3):
            dirs[k, c] = 1.0 if k == c else 0.0
    lam[0], lam[1], lam[2], lam[3] = l1, l2, l3, mu
    return 4


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection
    (:func:`rollingtop._compiled._template.dynamics.project`):
    ``(lambda, mu) = A^-1 (vp, (w, gamma))``, ``v <- v - lambda / m``,
    ``w <- w - I^-1 (r x lambda + mu gamma)``."""
    R, m, a3 = p[0], p[1], p[3]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3 = -R * g1, -R * g2, -R * g3 - a3
    w1, w2, w3 = y[3], y[4], y[5]
    c1 = y[0] + w2 * r3 - w3 * r2
    c2 = y[1] + w3 * r1 - w1 * r3
    c3 = y[2] + w1 * r2 - w2 * r1
    c4 = w1 * g1 + w2 * g2 + w3 * g3
    l1, l2, l3, mu = _solve4(p, r1, r2, r3, g1, g2, g3, c1, c2, c3, c4)
    y[0] -= l1 / m
    y[1] -= l2 / m
    y[2] -= l3 / m
    y[3] -= (r2 * l3 - r3 * l2 + mu * g1) / p[4]
    y[4] -= (r3 * l1 - r1 * l3 + mu * g2) / p[5]
    y[5] -= (r1 * l2 - r2 * l1 + mu * g3) / p[6]


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    return -np.cross(omega, contact_arm(body, gamma))


def _spin_directions(gamma: Any) -> dict[str, Any]:
    return {NO_SPIN: gamma}


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    return [sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr


def _symbolic_omega(gamma: Any, tau: Any, spin: Any) -> Any:
    return spin[0] * tau + spin[1] * gamma.cross(tau)  # horizontal: (w, gamma) = 0


MODEL = ContactModel(
    name="rubber",
    description="rubber rolling: no slip (vp = 0), no spin about the normal ((w, gamma) = 0)",
    constraints=(
        "no slip (vp, e1) = 0",
        "no slip (vp, e2) = 0",
        "no slip (vp, e3) = 0",
        "no spin (w, gamma) = 0",
    ),
    free_velocity={},
    integrals_symmetric=("energy", "rubber_spin"),
    reduction=("rubber_spin",),
    integrals_general=("energy",),
    velocity=_velocity,
    spin_directions=_spin_directions,
    symbolic=Symbolic(
        _symbolic_directions,
        _symbolic_velocity,
        omega=_symbolic_omega,
        claims="rollingtop.symbolic.rubber:claims",
    ),
    colour="#ff7f0e",
)
