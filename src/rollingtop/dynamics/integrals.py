"""First integrals, evaluated on arrays of states (``MODEL.md``, "Energy and first integrals").

Each function takes the body and states ``Y`` of shape ``(..., 17)`` and returns shape ``(...)``.
Which integrals hold for which model and body is declared by the contact models
(:meth:`rollingtop.contact.ContactModel.integrals`).
"""

from __future__ import annotations

import numpy as np

from rollingtop.body import SphericalTop
from rollingtop.dynamics._layout import ALPHA, BETA, GAMMA, V, W

__all__ = ["INTEGRALS", "evaluate"]


def _arm(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    r = -body.R * Y[..., GAMMA]
    r[..., 2] -= body.a3
    return r


def _Iw(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    return Y[..., W] * body.inertia


def energy(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """``E = m (v, v)/2 + (w, I w)/2 - m g (r, gamma)``; zero with the CoM on the plane."""
    v, w, gamma = Y[..., V], Y[..., W], Y[..., GAMMA]
    kinetic = 0.5 * body.m * np.sum(v * v, axis=-1) + 0.5 * np.sum(w * _Iw(body, Y), axis=-1)
    return kinetic - body.m * body.g * np.sum(_arm(body, Y) * gamma, axis=-1)


def lagrange(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Lagrange's integral ``F3 = I3 w3 = M3`` (symmetric body)."""
    return body.I3 * Y[..., 5]


def jellett(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Jellett's integral ``F4 = (I w, r)``."""
    return np.sum(_Iw(body, Y) * _arm(body, Y), axis=-1)


def area(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Area integral ``F5 = (I w, gamma)``: vertical angular momentum about the CoM."""
    return np.sum(_Iw(body, Y) * Y[..., GAMMA], axis=-1)


def reduced_components(Y: np.ndarray) -> dict[str, np.ndarray]:
    """``gamma3, s, v_tau, w_n`` of the reduced description (paper Sec. 3.1), shape ``(...)``.

    ``tau = e3 x gamma / s``, ``n = -(gamma1, gamma2, 0) / s``, ``s = sqrt(gamma1^2 + gamma2^2)``.
    """
    g1, g2, g3 = Y[..., 12], Y[..., 13], Y[..., 14]
    s = np.hypot(g1, g2)
    v1, v2 = Y[..., 0], Y[..., 1]
    w1, w2 = Y[..., 3], Y[..., 4]
    with np.errstate(invalid="ignore", divide="ignore"):
        v_tau = (-g2 * v1 + g1 * v2) / s
        w_n = -(g1 * w1 + g2 * w2) / s
    return {"gamma3": g3, "s": s, "v_tau": v_tau, "w_n": w_n}


def F6(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """The paper's new linear integral (symmetric body, meridian model):

    ``F6 = I1 (v_tau - (R gamma3 + a3) w_n) - M3 (R sqrt(1 - gamma3^2) + a3 arccos(gamma3))``.
    """
    c = reduced_components(Y)
    M3 = body.I3 * Y[..., 5]
    g3 = np.clip(c["gamma3"], -1.0, 1.0)
    return body.I1 * (c["v_tau"] - (body.R * g3 + body.a3) * c["w_n"]) - M3 * (
        body.R * c["s"] + body.a3 * np.arccos(g3)
    )


def momentum_x(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Horizontal momentum along the fixed axis of ``alpha``: ``m (v, alpha)``."""
    return body.m * np.sum(Y[..., V] * Y[..., ALPHA], axis=-1)


def momentum_y(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Horizontal momentum along the fixed axis of ``beta``: ``m (v, beta)``."""
    return body.m * np.sum(Y[..., V] * Y[..., BETA], axis=-1)


def routh(body: SphericalTop, Y: np.ndarray) -> np.ndarray:
    """Routh's integral ``w3 sqrt(I1 I3 + m I1 (r1^2 + r2^2) + m I3 r3^2)`` (rough plane)."""
    r = _arm(body, Y)
    q = body.I1 * body.I3 + body.m * body.I1 * (r[..., 0] ** 2 + r[..., 1] ** 2)
    q = q + body.m * body.I3 * r[..., 2] ** 2
    return Y[..., 5] * np.sqrt(q)


INTEGRALS = {
    f.__name__: f for f in (energy, lagrange, jellett, area, F6, momentum_x, momentum_y, routh)
}


def evaluate(body: SphericalTop, Y: np.ndarray, names) -> dict[str, np.ndarray]:
    """Evaluate the integrals ``names`` on states ``Y`` (shape ``(..., 17)``)."""
    Y = np.asarray(Y, dtype=float)
    return {name: INTEGRALS[name](body, Y) for name in names}
