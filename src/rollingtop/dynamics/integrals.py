"""First integrals, evaluated on arrays of states (``docs/model.md``, "Energy and first integrals").

Each function takes the body and states ``Y`` of shape ``(..., 18)`` and returns shape ``(...)``.
Which integrals hold for which model and body is declared by the contact models
(:meth:`rollingtop.contact.ContactModel.integrals`).
"""

from __future__ import annotations

import numpy as np

from rollingtop.body import SphericalTop
from rollingtop.dynamics._layout import ALPHA, BETA, GAMMA, V, W

__all__ = ["INTEGRALS", "F6_reduced", "evaluate"]


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


def reduced_components(Y: np.ndarray, pole: str | None = None) -> dict[str, np.ndarray]:
    """Reduced variables of states ``Y`` (paper Sec. 3.1), each of shape ``(...)``.

    Returns ``gamma3, s, theta, v_tau, w_tau, w_n, v_n, v3, w3``. The basis is the one of the
    constraint direction ``nu`` carried in the state (``psi_nu``, see
    :mod:`rollingtop.dynamics._layout`): ``nu = cos(psi_nu) alpha + sin(psi_nu) beta``,
    ``tau = nu x gamma``, ``n = e3 x tau`` and the signed ``s = (nu, e3)``. Away from a pole
    passage this is exactly the paper's ``tau = e3 x gamma / s``, ``n = -(gamma1, gamma2, 0) / s``
    with ``s = sqrt(1 - gamma3^2) > 0``; after a passage of the pole in a pole case ``s, tau, n``
    and the components along them change sign (the signed convention of
    :mod:`rollingtop.reduction.level`), and ``theta = atan2(s, gamma3)`` is the signed nutation
    angle (taken in ``(0, 2 pi)`` for ``pole="north"``). States of 17 components (no
    ``psi_nu``) use the geometric ``nu``.
    """
    Y = np.asarray(Y, dtype=float)
    g1, g2, g3 = Y[..., 12], Y[..., 13], Y[..., 14]
    if Y.shape[-1] > 17:
        c, sn = np.cos(Y[..., 17]), np.sin(Y[..., 17])
        nu = c[..., None] * Y[..., ALPHA] + sn[..., None] * Y[..., BETA]
    else:
        h = np.hypot(g1, g2)
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.stack([-g3 * g1 / h, -g3 * g2 / h, h], axis=-1)
    tau = np.cross(nu, Y[..., GAMMA])
    n = np.stack([-tau[..., 1], tau[..., 0], np.zeros_like(tau[..., 0])], axis=-1)  # e3 x tau
    s = nu[..., 2]
    theta = np.arctan2(s, g3)
    if pole == "north":
        theta = np.mod(theta, 2 * np.pi)
    v, w = Y[..., V], Y[..., W]
    return {
        "gamma3": g3,
        "s": s,
        "theta": theta,
        "v_tau": np.sum(v * tau, axis=-1),
        "w_tau": np.sum(w * tau, axis=-1),
        "w_n": np.sum(w * n, axis=-1),
        "v_n": np.sum(v * n, axis=-1),
        "v3": Y[..., 2],
        "w3": Y[..., 5],
    }


def F6_reduced(
    body: SphericalTop,
    M3: np.ndarray | float,
    gamma3: np.ndarray | float,
    s: np.ndarray | float,
    theta: np.ndarray | float,
    v_tau: np.ndarray | float,
    w_n: np.ndarray | float,
) -> np.ndarray:
    """The paper's new linear integral in the reduced variables (eq. 3.9), the one definition:

    ``F6 = I1 (v_tau - (R gamma3 + a3) w_n) - M3 (R s + a3 theta)``,

    with ``s = sqrt(1 - gamma3^2)`` and ``theta = arccos(gamma3)`` in the paper's unsigned
    variables, or the signed ``s`` and ``theta`` of a pole case (:func:`F6`). Arguments
    broadcast together; the result has their common shape. Its inverse on a level set (``I1
    v_tau`` from ``C2``) is :meth:`rollingtop.reduction.LevelSet.P`.
    """
    return body.I1 * (v_tau - (body.R * gamma3 + body.a3) * w_n) - M3 * (
        body.R * s + body.a3 * theta
    )


def F6(body: SphericalTop, Y: np.ndarray, pole: str | None = None) -> np.ndarray:
    """The paper's new linear integral (symmetric body, meridian model, eq. 3.9) of states ``Y``:
    :func:`F6_reduced` of the reduced variables of :func:`reduced_components`, where
    ``sqrt(1 - gamma3^2)`` and ``arccos(gamma3)`` are the signed ``s`` and ``theta``, so that it
    stays constant through the pole passages of a pole case, where the paper's unsigned
    expression changes sign.
    """
    c = reduced_components(Y, pole)
    M3 = body.I3 * Y[..., 5]
    return F6_reduced(body, M3, c["gamma3"], c["s"], c["theta"], c["v_tau"], c["w_n"])


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


def evaluate(body: SphericalTop, Y: np.ndarray, names, pole: str | None = None) -> dict:
    """Evaluate the integrals ``names`` on states ``Y`` (shape ``(..., 18)``); ``pole`` is the
    meridian pole case the states belong to, if any (see :func:`F6`)."""
    Y = np.asarray(Y, dtype=float)
    return {name: F6(body, Y, pole) if name == "F6" else INTEGRALS[name](body, Y)
            for name in names}  # fmt: skip
