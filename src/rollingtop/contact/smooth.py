"""Smooth (frictionless) plane: only the contact is kept, ``f1 = (vp, gamma) = 0``."""

from __future__ import annotations

import math
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact._base import ContactModel, FreeVelocity, Symbolic, Vertical, contact_arm
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import normal_row

#: The stepper's stage loop inlines this model's right-hand side (short closed form: fast, and
#: cheap to compile twice; :data:`rollingtop._compiled._template._dispatch.INLINE_RHS`).
INLINE_RHS = True

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint row ``f1``; returns 1."""
    normal_row(p, y, 0, J, bias, dirs)
    return 1


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations (:func:`.rhs_contact`)."""
    return rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection (:func:`.project_contact`)."""
    project_contact(p, y, False, 0.0, 0.0, 0.0)


def _velocity(
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    vx, vy = np.asarray(free["v_horizontal"], dtype=float)
    wxr = np.cross(omega, contact_arm(body, gamma))
    v: FloatArray = (
        vx * np.asarray(alpha) + vy * np.asarray(beta) - (wxr @ gamma) * np.asarray(gamma)
    )
    return v


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    return [gamma]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    return -wxr + free[0] * tau + free[1] * gamma.cross(tau)  # contact velocity horizontal


def _vertical_spin(body: SphericalTop, pole: int) -> float:
    """Critical spin of the vertical spin on the pole ``pole`` (+1 south, -1 north): on a smooth
    plane the centre of mass moves only vertically, to second order not at all at the vertical,
    so the body is Lagrange's top about its centre of mass with ``m g l`` replaced by
    ``m g a`` (``a = pole a3``, the height of the centre of mass above the sphere's centre):
    stable for ``I3^2 w3^2 > 4 I1 m g a``; every spin when ``a <= 0``."""
    a = pole * body.a3
    return 0.0 if a <= 0.0 else 2.0 * math.sqrt(body.I1 * body.m * body.g * a) / body.I3


MODEL = ContactModel(
    name="smooth",
    description="contact kept, frictionless plane",
    constraints=("contact (vp, gamma) = 0",),
    free_velocity={"v_horizontal": 2},
    integrals_symmetric=("energy", "lagrange", "jellett", "area", "momentum_x", "momentum_y"),
    integrals_general=("energy", "area", "momentum_x", "momentum_y"),
    velocity=_velocity,
    symbolic=Symbolic(_symbolic_directions, _symbolic_velocity),
    vertical=Vertical(spin=_vertical_spin),
    reduction=("M3", "C1", "p_horizontal"),
    colour="#2ca02c",
)
