"""The shell-rotor pair's integrals that differ from a lone body's
(:mod:`rollingtop.contact.shell_rotor`; each proved by :mod:`rollingtop.symbolic.shell_rotor`).

They are the model's declaration (:attr:`rollingtop.contact.ContactModel.integral_forms`): the
integrals module evaluates them under the same names as the lone body's (``energy``,
``jellett``, ``F6``) for this model only. NumPy on states ``Y`` of shape ``(..., 18)``, the
shell's relative spin ``delta`` in the last slot; each returns shape ``(...)``. Kept out of the
model's module so that its compiled kernels' cache key does not cover them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._layout import GAMMA, PSI_NU, V, W
from rollingtop._types import FloatArray

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

__all__ = ["pair_F6", "pair_energy", "pair_jellett", "pair_weight"]

_E3 = np.array([0.0, 0.0, 1.0])


def _rotor_arm(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The contact point seen from the rotor's centre of mass, ``r = -R gamma - a3 e3``."""
    r: FloatArray = -body.R * Y[..., GAMMA]
    r[..., 2] -= body.a3
    return r


def pair_energy(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The pair's energy: the rotor's ``m v^2/2 + (w, I w)/2 - m g (r, gamma)`` plus the
    shell's ``ms v_O^2/2 + Js |Omega|^2/2``, ``v_O = v - a3 w x e3``, ``Omega = w + delta e3``
    (the shell's centre stays at height ``R``: its weight adds a constant, left out)."""
    v, w, gamma = Y[..., V], Y[..., W], Y[..., GAMMA]
    o1 = v[..., 0] - body.a3 * w[..., 1]
    o2 = v[..., 1] + body.a3 * w[..., 0]
    spin = w[..., 2] + Y[..., PSI_NU]
    kinetic = 0.5 * body.m * np.sum(v * v, axis=-1)
    kinetic = kinetic + 0.5 * np.sum(w * (w * body.inertia), axis=-1)
    kinetic = kinetic + 0.5 * body.shell_mass * (o1 * o1 + o2 * o2 + v[..., 2] ** 2)
    kinetic = kinetic + 0.5 * body.shell_inertia * (w[..., 0] ** 2 + w[..., 1] ** 2 + spin**2)
    E: FloatArray = kinetic - body.m * body.g * np.sum(_rotor_arm(body, Y) * gamma, axis=-1)
    return E


def pair_jellett(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The pair's Jellett integral ``(K_G, r_G)``: the angular momentum about the pair's centre
    of mass ``G`` against the contact point seen from ``G``,
    ``K_G = I w + Js Omega + m (C - G) x v + ms (O - G) x v_O``, ``r_G = -R gamma - a3 e3 - G``
    (``C``: the rotor's centre of mass, the origin; ``O = -a3 e3`` the shell's centre;
    ``G = ms O / (m + ms)``)."""
    ms, Js, a3 = body.shell_mass, body.shell_inertia, body.a3
    O = -a3 * _E3
    G = ms * O / (body.m + ms)
    v, w = Y[..., V], Y[..., W]
    omega = w + Y[..., PSI_NU][..., None] * _E3
    v_O = v - np.cross(w, a3 * _E3)
    K = w * body.inertia + Js * omega + body.m * np.cross(-G, v) + ms * np.cross(O - G, v_O)
    value: FloatArray = np.sum(K * (_rotor_arm(body, Y) - G), axis=-1)
    return value


def pair_weight(body: SphericalTop, g3: Any) -> tuple[Any, Any]:
    """The pair's ``N(gamma3)`` and ``Phi(gamma3)`` of its ``F6``
    (:func:`rollingtop.symbolic.shell_rotor.f6_pair`, where they are derived and proved):
    ``Phi' = ((m + ms) R gamma3 + m a3) / sqrt(N)``. Real arrays (``arccos``'s argument is
    clipped to ``[-1, 1]``, round-off at the poles) or complex ones (the complex step of the
    reduction's ``d2U``: not clipped)."""
    R, m, a3, I1 = body.R, body.m, body.a3, body.I1
    ms, Js = body.shell_mass, body.shell_inertia
    K = (m + ms) * I1 + m * ms * a3**2
    alpha = Js * (I1 + Js + ms * R**2 + m * R**2 + m * a3**2) + R**2 * K
    beta = 2.0 * Js * m * R * a3
    kappa = R**2 * K
    N = alpha + beta * g3 - kappa * g3**2
    p = (m + ms) * R
    x = (2 * kappa * g3 - beta) / np.sqrt(beta**2 + 4 * alpha * kappa)
    arc = np.arccos(x if np.iscomplexobj(x) else np.clip(x, -1, 1))
    phi = -p / kappa * np.sqrt(N) - (m * a3 + p * beta / (2 * kappa)) / np.sqrt(kappa) * arc
    return N, phi


def pair_F6(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The pair's ``F6``: ``Omega3 sqrt(N) + R I3 w3 Phi(gamma3)`` (:func:`pair_weight`)."""
    N, phi = pair_weight(body, Y[..., 14])
    w3 = Y[..., 5]
    f6: FloatArray = (w3 + Y[..., PSI_NU]) * np.sqrt(N) + body.R * body.I3 * w3 * phi
    return f6
