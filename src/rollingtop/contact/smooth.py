"""Smooth (frictionless) plane: only the contact is kept, ``f1 = (vp, gamma) = 0``."""

import numpy as np

from rollingtop._jit import kernel
from rollingtop.contact._base import ContactModel, contact_arm
from rollingtop.contact._rows import normal_row

CODE = 1


@kernel
def rows(p, y, J, bias, dirs):
    """Constraint row ``f1``; returns 1."""
    normal_row(p, y, 0, J, bias, dirs)
    return 1


def _velocity(body, gamma, omega, alpha, beta, free):
    vx, vy = free["v_horizontal"]
    wxr = np.cross(omega, contact_arm(body, gamma))
    return vx * np.asarray(alpha) + vy * np.asarray(beta) - (wxr @ gamma) * np.asarray(gamma)


MODEL = ContactModel(
    name="smooth",
    code=CODE,
    description="contact kept, frictionless plane",
    constraints=("contact (vp, gamma) = 0",),
    free_velocity={"v_horizontal": 2},
    integrals_symmetric=("energy", "lagrange", "jellett", "area", "momentum_x", "momentum_y"),
    integrals_general=("energy", "area", "momentum_x", "momentum_y"),
    velocity=_velocity,
    colour="#2ca02c",
)
