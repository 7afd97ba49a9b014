"""Rough plane: rolling without slipping, ``vp = 0`` (Routh's sphere for a symmetric body).

The three rows are ``(vp, e_i) = 0`` along the body axes: they span the same conditions as
``(vp, alpha) = (vp, beta) = (vp, gamma) = 0`` and their directions do not move in the body.
"""

import numpy as np

from rollingtop._jit import kernel
from rollingtop.contact._base import ContactModel, contact_arm
from rollingtop.contact._rows import contact_row

CODE = 2


@kernel
def rows(p, y, J, bias, dirs):
    """Constraint rows ``(vp, e1) = (vp, e2) = (vp, e3) = 0``; returns 3."""
    contact_row(p, y, 0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, J, bias, dirs)
    contact_row(p, y, 2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, J, bias, dirs)
    return 3


def _velocity(body, gamma, omega, alpha, beta, free):
    return -np.cross(omega, contact_arm(body, gamma))


MODEL = ContactModel(
    name="rough",
    code=CODE,
    description="rolling without slipping (vp = 0)",
    constraints=("no slip (vp, e1) = 0", "no slip (vp, e2) = 0", "no slip (vp, e3) = 0"),
    free_velocity={},
    integrals_symmetric=("energy", "jellett", "routh"),
    integrals_general=("energy",),
    velocity=_velocity,
    colour="#d62728",
)
