"""The curves of a phase portrait, as data: what :mod:`rollingtop.plot` draws and the explorer
shows (paper Fig. 5).

Each orbit is computed from its exact parametrisation, not from a contoured grid: between its
turning points ``theta = c + d sin(phi)`` and ``w_tau = +-sqrt(2 (h - U) / rho)``, so a curve
closes exactly at the turning points and the separatrices pass exactly through the saddles. The
turning points are :func:`rollingtop.reduction.orbits`' (the reduction's one turning-point
search).

In a pole case (``C1 = +-M3``) orbits pass through the pole, where the paper's ``tau`` and
``w_tau`` change sign; there the abscissa is the signed nutation angle ``theta``
(``gamma3 = cos theta``, see :mod:`rollingtop.reduction.level`), in which the flow is regular.

Nothing here imports matplotlib.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rollingtop._types import FloatArray
from rollingtop.reduction._orbit import Orbit
from rollingtop.reduction._quadrature import energy_gap
from rollingtop.reduction.level import Level, LevelSetError, Real
from rollingtop.reduction.orbits import orbits
from rollingtop.reduction.steady import SteadyMotion, steady_motions

__all__ = [
    "OrbitCurve",
    "PortraitCurves",
    "abscissa",
    "default_h_levels",
    "level_curves",
    "normal_force_grid",
    "on_a_saddle",
    "orbit_curve",
    "portrait_curves",
]

#: Points per orbit on either branch of its closed curve (:func:`orbit_curve`).
ORBIT_POINTS = 400
#: Two energies closer than this, relative to ``max(1, |U|)``, are the same level (an energy
#: given as a saddle's ``U`` draws its separatrix).
SAME_LEVEL_RTOL = 1e-12


def default_h_levels(level: Level, count: int = 10) -> list[float]:
    """``count`` energies from just above the lowest steady motion to half again past the highest
    saddle (or, without saddles, a band above the minimum), plus the saddles' levels.

    Raises
    ------
    LevelSetError
        When the level has no steady motion (``U`` has no minimum).
    """
    motions = steady_motions(level)
    if not motions:
        raise LevelSetError(f"no steady motion on {level.describe()}: U has no minimum")
    u_min = min(m.U for m in motions)
    saddles = [m.U for m in motions if m.type == "saddle"]
    if saddles:
        top = max(saddles) + 0.5 * (max(saddles) - u_min)
    else:
        grid = np.linspace(*level.theta_domain, 2001)[200:-200]
        top = u_min + 0.5 * (float(np.median(level.U(grid))) - u_min)
    levels = u_min + (top - u_min) * (np.arange(1, count + 1) / count) ** 1.5
    return sorted({*map(float, levels), *saddles})


def abscissa(level: Level, theta: Real) -> Real:
    """The portrait's abscissa at ``theta``: ``gamma3 = cos(theta)``, or ``theta`` itself in a
    pole case (same shape)."""
    if level.pole:
        return theta
    x: Real = np.cos(theta)
    return x


def orbit_curve(
    level: Level, h: float, orbit: Orbit, n: int = ORBIT_POINTS
) -> tuple[FloatArray, FloatArray]:
    """The closed curve ``(abscissa, w_tau)`` of ``orbit`` at energy ``h``.

    Returns
    -------
    x, w : ndarray, shape (2 n,)
        The branch ``w_tau >= 0`` from one turning point to the other and back along
        ``w_tau <= 0``. An orbit that rolls over (no spin: ``theta`` runs round the circle) gives
        its two branches over the whole domain, shape ``(4 n + 1,)``, joined by a NaN.
    """
    t1, t2 = orbit.theta_min, orbit.theta_max
    if orbit.rolls_over:
        theta = np.linspace(*level.theta_domain, 2 * n)
        w = level.w_tau(theta, h)
        return np.concatenate([theta, [np.nan], theta]), np.concatenate([w, [np.nan], -w])
    phi = np.linspace(-math.pi / 2, math.pi / 2, n)
    theta = (t1 + t2) / 2 + (t2 - t1) / 2 * np.sin(phi)
    w = level.w_tau(theta, h, gap=energy_gap(level, h, t1, t2, phi))
    x = abscissa(level, theta)
    return np.concatenate([x, x[::-1]]), np.concatenate([w, -w[::-1]])


def level_curves(
    level: Level, h: float, n: int = ORBIT_POINTS
) -> list[tuple[FloatArray, FloatArray]]:
    """The closed curve (:func:`orbit_curve`) of every orbit of ``level`` at energy ``h`` that
    is not a steady motion; none where ``h`` has no motion."""
    try:
        found = orbits(level, h)
    except LevelSetError:
        return []
    return [orbit_curve(level, h, o, n) for o in found if o.kind != "steady"]


def normal_force_grid(level: Level, g3: FloatArray, w: FloatArray) -> FloatArray:
    """Normal reaction at the states ``(gamma3, w_tau)`` of the level set, shape
    ``(len(w), len(g3))``, in closed form (:meth:`rollingtop.reduction.LevelSet.normal_force`;
    no compiled code)."""
    G, Wt = np.meshgrid(g3, w, indexing="ij")
    N: FloatArray = level.normal_force(np.arccos(G), Wt).T
    return N


@dataclass(frozen=True)
class OrbitCurve:
    """One orbit's closed curve in a portrait (:func:`portrait_curves`).

    Attributes
    ----------
    h : float
        Its energy.
    x, w : ndarray, shape (m,)
        Abscissa and ``w_tau`` (:func:`orbit_curve`).
    separatrix : bool
        Whether it lies on a saddle's level.
    """

    h: float
    x: FloatArray
    w: FloatArray
    separatrix: bool


@dataclass(frozen=True)
class PortraitCurves:
    """Every orbit at a portrait's energies and the window that holds them
    (:func:`portrait_curves`).

    Attributes
    ----------
    curves : list of OrbitCurve
        In the order of the energies, steady motions left out.
    window : tuple of float
        ``(x_lo, x_hi, w_top)``: the abscissa's extent padded and clipped to the domain, and
        ``w_top`` 10 % above the highest ``|w_tau|``.
    """

    curves: list[OrbitCurve]
    window: tuple[float, float, float]


def on_a_saddle(h: float, saddle_levels: set[float]) -> bool:
    """Whether the energy ``h`` is one of ``saddle_levels`` (to :data:`SAME_LEVEL_RTOL`): its
    orbits are separatrices."""
    return any(abs(h - u) <= SAME_LEVEL_RTOL * max(1.0, abs(u)) for u in saddle_levels)


def portrait_curves(
    level: Level, levels: Sequence[float], *, motions: Sequence[SteadyMotion] | None = None
) -> PortraitCurves:
    """The closed curve of every orbit at the energies ``levels`` and their window;
    ``motions``: the level's steady motions where the caller has them already (default: they
    are computed).

    Raises
    ------
    LevelSetError
        When none of ``levels`` has a motion.
    """
    if motions is None:
        motions = steady_motions(level)
    saddle_levels = {m.U for m in motions if m.type == "saddle"}
    curves = []
    g_lo, g_hi, w_top = 1.0, -1.0, 0.0
    for h in levels:
        try:
            comps = orbits(level, h)
        except LevelSetError:
            continue
        separatrix = on_a_saddle(h, saddle_levels)
        for o in comps:
            if o.kind == "steady":
                continue
            x, y = orbit_curve(level, h, o)
            g_lo, g_hi = min(g_lo, np.nanmin(x)), max(g_hi, np.nanmax(x))
            w_top = max(w_top, float(np.nanmax(np.abs(y))))
            curves.append(OrbitCurve(h, x, y, separatrix or o.kind == "separatrix"))
    if g_lo > g_hi:
        raise LevelSetError(f"no motion on {level.describe()} at the requested h levels")
    pad = 0.05 * (g_hi - g_lo) + 1e-3
    if level.pole:
        g_lo, g_hi = max(level.theta_domain[0], g_lo - pad), min(level.theta_domain[1], g_hi + pad)
    else:
        g_lo, g_hi = max(-1.0, g_lo - pad), min(1.0, g_hi + pad)
    return PortraitCurves(curves, (float(g_lo), float(g_hi), 1.1 * w_top))
