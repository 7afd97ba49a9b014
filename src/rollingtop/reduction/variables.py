"""Maps between the full state and the reduced description (paper Sec. 3.1).

Full state ``y`` (18,) -> reduced variables ``(gamma3, v_tau, w_tau, w_n)`` and the integrals
``(M3, C1, C2, h)``; and back, from a level set, ``h`` and a starting ``gamma3``, to a full,
constraint-consistent state.

The orientation left free by the reduced variables is fixed by the Euler angles of the
3-1-3 convention: the vertical in the body frame is ``gamma = (s sin phi, s cos phi, gamma3)``
(``phi``: proper rotation about the symmetry axis), and ``psi = atan2(beta3, alpha3)`` is the
azimuth of the horizontal projection of the axis in the fixed frame (``docs/model.md``, "Motion in
absolute space"), so that ``nu = cos(psi) alpha + sin(psi) beta`` and
``tau = sin(psi) alpha - cos(psi) beta``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel
from rollingtop.dynamics.integrals import F6, area, energy, lagrange, reduced_components
from rollingtop.reduction.level import Level, LevelSetError

__all__ = [
    "reduce_state",
    "reduced_integrals",
    "euler_angles",
    "state_from_level",
    "states_on_level",
]

FloatArray: TypeAlias = NDArray[np.float64]


def reduce_state(
    Y: ArrayLike, pole: str | None = None, *, model: str | ContactModel | None = None
) -> dict[str, FloatArray]:
    """Reduced variables of states ``Y`` (shape ``(..., 18)``) of ``model``, each of shape
    ``(...)``.

    Returns ``gamma3, s, theta, v_tau, w_tau, w_n, v_n, v3, w3``; see
    :func:`rollingtop.dynamics.integrals.reduced_components` for the (signed) basis.
    """
    return reduced_components(Y, pole, model=model)


def reduced_integrals(
    body: SphericalTop, Y: ArrayLike, pole: str | None = None
) -> dict[str, FloatArray]:
    """``M3 = I3 w3``, ``C1 = F5``, ``C2 = F6``, ``h = E - I3 w3^2/2 - m g R`` of states ``Y``
    (shape ``(..., 18)``), each of shape ``(...)``; ``pole`` as in
    :func:`rollingtop.dynamics.integrals.F6`."""
    Y = np.asarray(Y, dtype=float)
    M3 = lagrange(body, Y)
    return {
        "M3": M3,
        "C1": area(body, Y),
        "C2": F6(body, Y, pole),
        "h": energy(body, Y) - M3**2 / (2 * body.I3) - body.m * body.g * body.R,
    }


def euler_angles(Y: ArrayLike) -> dict[str, FloatArray]:
    """Euler angles ``psi, theta, phi`` (3-1-3) of states ``Y``, each shape ``(...)``:
    ``gamma = (sin theta sin phi, sin theta cos phi, cos theta)``,
    ``psi = atan2(beta3, alpha3)``."""
    Y = np.asarray(Y, dtype=float)
    return {
        "psi": np.arctan2(Y[..., 11], Y[..., 8]),
        "theta": np.arctan2(np.hypot(Y[..., 12], Y[..., 13]), Y[..., 14]),
        "phi": np.arctan2(Y[..., 12], Y[..., 13]),
    }


def state_from_level(
    level: Level,
    h: float,
    gamma3: float,
    *,
    branch: int = 1,
    phi: float = 0.0,
    psi: float = 0.0,
    position: Sequence[float] = (0.0, 0.0),
    theta: float | None = None,
) -> FloatArray:
    """Full state on the level set ``(M3, C1, C2)`` with reduced energy ``h`` at ``gamma3``.

    Parameters
    ----------
    level : LevelSet
    h : float
        Reduced energy ``rho w_tau^2/2 + U``; must be ``>= U(gamma3)`` (to 1e-12 relative: a
        turning point found numerically is accepted, with ``w_tau = 0``).
    gamma3 : float
        Starting ``gamma3`` in ``(-1, 1)``.
    branch : {+1, -1}
        Sign of ``w_tau`` (``gamma3' = s w_tau``: +1 starts with ``gamma3`` increasing).
    phi, psi : float
        Euler angles fixing the orientation (see the module docstring).
    position : (float, float)
        Horizontal CoM position.
    theta : float, optional
        The nutation angle in ``(0, pi)`` instead of ``gamma3`` (which is then ignored): keeps
        the distance from the south pole to full precision (``cos(1e-12)`` rounds to 1).

    Returns
    -------
    y : ndarray, shape (18,)
        Satisfies the model's constraints (the level's: :attr:`LevelSet.model`); its
        integrals and ``h`` as given.
    """
    if theta is not None:
        if not 0.0 < theta < math.pi:
            raise LevelSetError(f"theta = {theta!r} must lie strictly inside (0, pi)")
        gamma3 = math.cos(theta)
    elif not -1.0 < gamma3 < 1.0:
        raise LevelSetError(f"gamma3 = {gamma3!r} must lie strictly inside (-1, 1)")
    if branch not in (1, -1):
        raise LevelSetError(f"branch = {branch!r} must be +1 or -1")
    if theta is None:
        theta = math.acos(gamma3)
    U = float(level.U(theta))
    if h < U - 1e-12 * max(1.0, abs(U)):
        raise LevelSetError(
            f"h = {h:.12g} is below the effective potential U({gamma3:g}) = {U:.12g}: "
            "no motion passes through this gamma3"
        )
    w_tau = branch * float(level.w_tau(theta, h))  # 0 at a turning point
    w_n = float(level.w_n(theta))
    s = math.sin(theta)
    gamma = np.array([s * math.sin(phi), s * math.cos(phi), gamma3])
    e3 = np.array([0.0, 0.0, 1.0])
    tau = np.cross(e3, gamma) / s
    n = np.cross(e3, tau)
    nu = np.array([-gamma3 * gamma[0] / s, -gamma3 * gamma[1] / s, s])  # (e3 - gamma3 gamma)/s
    alpha = math.cos(psi) * nu + math.sin(psi) * tau
    beta = math.sin(psi) * nu - math.cos(psi) * tau
    w = w_tau * tau + w_n * n + float(level.spin(theta)) * e3
    v = level.com_velocity(theta, w_tau, {"tau": tau, "n": n, "e3": e3, "gamma": gamma})
    y = np.empty(18)
    y[0:3], y[3:6], y[6:9], y[9:12], y[12:15] = v, w, alpha, beta, gamma
    y[15:17] = position
    y[17] = float(level.last_slot(theta, psi))
    return y


def states_on_level(level: Level, gamma3: ArrayLike, w_tau: ArrayLike) -> FloatArray:
    """Full states on the level set at the points ``(gamma3, w_tau)`` of its phase plane, all at
    once: :func:`state_from_level` (``phi = psi = 0``, at the origin) for arrays.

    Parameters
    ----------
    level : LevelSet
    gamma3, w_tau : array_like, broadcast together, shape ``(...)``
        ``gamma3`` strictly inside ``(-1, 1)``; ``w_tau`` of either sign (the energy is
        :meth:`LevelSet.energy`).

    Returns
    -------
    ndarray, shape ``(..., 18)``
        Satisfying the meridian model's constraints. A phase portrait's grid is thousands of
        points: built point by point it took a second, now a few milliseconds.
    """
    g3, wt = np.broadcast_arrays(np.asarray(gamma3, dtype=float), np.asarray(w_tau, dtype=float))
    if not np.all((g3 > -1.0) & (g3 < 1.0)):
        raise LevelSetError("gamma3 must lie strictly inside (-1, 1)")
    theta = np.arccos(g3)
    s = np.sin(theta)
    w_n = np.asarray(level.w_n(theta), dtype=float)
    y = np.zeros((*g3.shape, 18))
    # phi = 0: gamma = (0, s, gamma3), tau = (-1, 0, 0), n = (0, -1, 0), nu = (0, -gamma3, s);
    # psi = 0: alpha = nu, beta = -tau (the frames of state_from_level)
    gamma = np.stack([np.zeros_like(s), s, g3], axis=-1)
    frame = {
        "tau": np.array([-1.0, 0.0, 0.0]),
        "n": np.array([0.0, -1.0, 0.0]),
        "e3": np.array([0.0, 0.0, 1.0]),
        "gamma": gamma,
    }
    y[..., 0:3] = level.com_velocity(theta, wt, frame)
    y[..., 3] = -wt
    y[..., 4] = -w_n
    y[..., 5] = level.spin(theta)
    y[..., 7] = -g3
    y[..., 8] = s
    y[..., 9] = 1.0
    y[..., 13] = s
    y[..., 14] = g3
    y[..., 17] = level.last_slot(theta, 0.0)
    return y
