"""Smooth (frictionless) plane: only the contact is kept, ``f1 = (vp, gamma) = 0``."""

import numpy as np

from rollingtop._jit import inline, kernel
from rollingtop.contact._base import ContactModel, contact_arm
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import normal_row


@kernel
def rows(p, y, J, bias, dirs, variant):
    """Constraint row ``f1``; returns 1."""
    normal_row(p, y, 0, J, bias, dirs)
    return 1


@inline
def accel(p, y, dy, ws, variant):
    """Closed form of the accelerations (:func:`.rhs_contact`)."""
    return rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@inline
def project_velocity(p, y, variant):
    """Closed form of the velocity projection (:func:`.project_contact`)."""
    project_contact(p, y, False, 0.0, 0.0, 0.0)


def _velocity(body, gamma, omega, alpha, beta, free):
    vx, vy = free["v_horizontal"]
    wxr = np.cross(omega, contact_arm(body, gamma))
    return vx * np.asarray(alpha) + vy * np.asarray(beta) - (wxr @ gamma) * np.asarray(gamma)


def _symbolic_directions(sp, gamma):
    return [gamma]


def _symbolic_velocity(gamma, tau, wxr, free):
    return -wxr + free[0] * tau + free[1] * gamma.cross(tau)  # contact velocity horizontal


MODEL = ContactModel(
    name="smooth",
    description="contact kept, frictionless plane",
    constraints=("contact (vp, gamma) = 0",),
    free_velocity={"v_horizontal": 2},
    integrals_symmetric=("energy", "lagrange", "jellett", "area", "momentum_x", "momentum_y"),
    integrals_general=("energy", "area", "momentum_x", "momentum_y"),
    velocity=_velocity,
    symbolic_directions=_symbolic_directions,
    symbolic_velocity=_symbolic_velocity,
    colour="#2ca02c",
)
