"""The paper's model: no slip along the horizontal projection of the symmetry axis.

Kilin & Ivanova (2023), eqs. (2.4)-(2.6): contact is kept, ``f1 = (vp, gamma) = 0``, and the
contact point does not slip along ``nu = (e3 - gamma3 gamma) / sqrt(1 - gamma3^2)``,
``f2 = (vp, nu) = 0``; it slips freely across, along ``tau = e3 x gamma / sqrt(1 - gamma3^2)``.
"""

import math

import numpy as np
from numba import njit

from rollingtop.contact._base import ContactModel, contact_arm
from rollingtop.contact._rows import contact_row, normal_row

CODE = 0
#: Below this ``sqrt(gamma1^2 + gamma2^2)`` the axis counts as vertical and ``nu`` is undefined.
POLE_TOLERANCE = 1e-8


@njit(cache=True, error_model="numpy")
def rows(p, y, J, bias, dirs):
    """Constraint rows ``f1`` (normal) and ``f2`` (along ``nu``); returns their number, 2."""
    normal_row(p, y, 0, J, bias, dirs)
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    gd1 = g2 * w3 - g3 * w2
    gd2 = g3 * w1 - g1 * w3
    gd3 = g1 * w2 - g2 * w1
    # s = |horizontal part of e3| = sqrt(gamma1^2 + gamma2^2), free of cancellation near the poles;
    # nu = (e3 - gamma3 gamma) / s = (-gamma3 gamma1 / s, -gamma3 gamma2 / s, s) for |gamma| = 1.
    s = math.sqrt(g1 * g1 + g2 * g2)
    sd = (g1 * gd1 + g2 * gd2) / s
    n1 = -g3 * g1 / s
    n2 = -g3 * g2 / s
    n3 = s
    nd1 = -(gd3 * g1 + g3 * gd1) / s - n1 * sd / s
    nd2 = -(gd3 * g2 + g3 * gd2) / s - n2 * sd / s
    nd3 = sd
    contact_row(p, y, 1, n1, n2, n3, nd1, nd2, nd3, J, bias, dirs)
    return 2


def tau_nu(gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal unit vectors ``tau = e3 x gamma / s`` and ``nu = (e3 - gamma3 gamma) / s``."""
    g1, g2, g3 = gamma
    s = math.hypot(g1, g2)
    return np.array([-g2, g1, 0.0]) / s, np.array([-g3 * g1 / s, -g3 * g2 / s, s])


def _singular(gamma: np.ndarray) -> str | None:
    if math.hypot(gamma[0], gamma[1]) < POLE_TOLERANCE:
        return (
            f"the symmetry axis is vertical (gamma3 = {gamma[2]:+.12g}): the meridian constraint "
            "direction nu = (e3 - gamma3 gamma)/sqrt(1 - gamma3^2) is undefined"
        )
    return None


def _velocity(body, gamma, omega, alpha, beta, free):
    tau, _ = tau_nu(gamma)
    wxr = np.cross(omega, contact_arm(body, gamma))
    slip = free["v_tau"] + wxr @ tau  # contact-point velocity vp = slip * tau
    return -wxr + slip * tau


MODEL = ContactModel(
    name="meridian",
    code=CODE,
    description="contact kept, no slip along the horizontal projection of the axis (the paper)",
    constraints=("contact (vp, gamma) = 0", "no slip along the axis projection (vp, nu) = 0"),
    free_velocity={"v_tau": 1},
    integrals_symmetric=("energy", "lagrange", "jellett", "area", "F6"),
    integrals_general=("energy", "area"),
    velocity=_velocity,
    singular=_singular,
)
