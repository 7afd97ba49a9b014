"""The critical curves of the bifurcation diagrams (:mod:`rollingtop.reduction.bifurcation`,
whose docstring derives them): ``C2*(theta)``, the energies on them, their folds and branches,
and a level's critical points."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop.body import SphericalTop
from rollingtop.reduction._roots import brentq
from rollingtop.reduction.level import LevelSet, LevelSetError
from rollingtop.reduction.steady import critical_points

FloatArray = NDArray[np.float64]
#: Points of ``theta`` per interval between poles of ``C2*`` (clustered towards the ends).
BRANCH_POINTS = 4001
#: Points of ``theta`` per ``pi`` of the domain on which ``dU`` is sampled to find a level's
#: critical points (:func:`rollingtop.reduction.steady.critical_points`).
CLASSIFY_POINTS = 1201
#: Extrema of ``C2*`` this close to the family of ``a3 = 0`` are where the curve meets it.
FAMILY_GAP = 1e-4
#: Step of the complex-step derivative (exact to round-off for analytic functions).
_COMPLEX_STEP = 1e-30


def _base_level(body: SphericalTop, M3: float, C1: float) -> LevelSet:
    """The level ``(M3, C1, 0)``: its ``U`` and ``P`` are ``U0`` and ``P0``. On a pole level
    (``C1 = +-M3``) the signed nutation angle's domain holds both sides of the pole
    (:attr:`LevelSet.theta_domain`); the level without spin (``M3 = C1 = 0``) is refused."""
    level = LevelSet(body, M3, C1, 0.0)
    if level.pole == "both":
        raise LevelSetError(
            f"M3 = {M3:g}, C1 = {C1:g}: without spin U is periodic in theta (rolling over both "
            "poles, rollingtop.reduction.no_spin); the bifurcation diagram needs M3 != 0"
        )
    return level


def _c2_star(level: LevelSet, theta: Any) -> Any:
    """``C2*(theta) = -I1^2 U0'(theta) / (m P'(theta))`` for real or complex ``theta``."""
    b = level.body
    _, _, _, dq2 = level._q(theta)
    dP = dq2 + level.M3 * b.a3
    return -(b.I1**2) * level.dU(theta) / (b.m * dP)


def critical_c2(body: SphericalTop, M3: float, C1: float, gamma3: float | FloatArray) -> Any:
    """``C2*(gamma3)``: the value of ``C2`` for which ``gamma3`` is a steady motion.

    Parameters
    ----------
    body : SphericalTop
        Dynamically symmetric body.
    M3, C1 : float
        Lagrange and area integrals (not a pole level ``C1 = +-M3``).
    gamma3 : float or ndarray, shape (...)
        In ``(-1, 1)``.

    Returns
    -------
    float or ndarray, shape (...)
        ``inf``-like values near the poles ``gamma3 = C1/M3`` (and ``-R/a3``).
    """
    level = _base_level(body, M3, C1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _c2_star(level, LevelSet.theta_of(gamma3))


def _energy_on_curve(level: LevelSet, theta: FloatArray, c2: FloatArray) -> FloatArray:
    """``h*(theta) = U(theta; C2)`` with ``C2 = c2`` (``U0 + m((P0 + C2)^2 - P0^2)/(2 I1^2)``)."""
    b = level.body
    P0 = level.P(theta)
    out: FloatArray = level.U(theta) + b.m * (2.0 * P0 * c2 + c2 * c2) / (2.0 * b.I1**2)
    return out


def critical_energy(body: SphericalTop, M3: float, C1: float, gamma3: float | FloatArray) -> Any:
    """``h*(gamma3) = U(gamma3; C2*(gamma3))``: the energy of the steady motion at ``gamma3``."""
    level = _base_level(body, M3, C1)
    theta = np.asarray(LevelSet.theta_of(gamma3), dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _energy_on_curve(level, theta, _c2_star(level, theta))


def _family(level: LevelSet) -> float | None:
    """With the centre of mass at the centre (``a3 = 0``) ``U0'`` and ``P'`` both vanish at
    ``gamma3 = C1/M3``: that ``theta`` is a steady motion for every ``C2`` (a family, drawn as a
    curve of its own; ``C2*`` is regular there). ``None`` otherwise."""
    if level.body.a3 != 0.0 or level.pole is not None or level.M3 == 0.0:
        return None
    c = level.C1 / level.M3
    return math.acos(c) if abs(c) < 1.0 else None


def _dc2_star(level: LevelSet, theta: FloatArray) -> FloatArray:
    """``dC2*/dtheta`` by the complex step (exact to round-off)."""
    z = np.asarray(theta, dtype=float) + 1j * _COMPLEX_STEP
    out: FloatArray = np.imag(_c2_star(level, z)) / _COMPLEX_STEP
    return out


def _cuts(level: LevelSet) -> list[float]:
    """The poles of ``C2*`` inside the theta domain, sorted: where ``gamma3 = C1/M3`` (not on a
    pole level, where ``C1/M3 = +-1``) and ``gamma3 = -R/a3``, if in ``(-1, 1)``."""
    b = level.body
    values = []
    if level.pole is None and level.M3 != 0.0 and abs(level.C1 / level.M3) < 1.0 and b.a3 != 0.0:
        values.append(level.C1 / level.M3)  # with a3 = 0 the pole is removable (_family)
    if b.a3 != 0.0 and abs(b.R / b.a3) < 1.0:
        values.append(-b.R / b.a3)
    lo, hi = level.theta_domain
    cuts = []
    for c in values:
        t = math.acos(c)
        for k in (-1, 0, 1):
            for x in (t + 2 * math.pi * k, -t + 2 * math.pi * k):
                if lo < x < hi:
                    cuts.append(x)
    return sorted(set(cuts))


def _intervals(level: LevelSet) -> list[tuple[float, float]]:
    lo, hi = level.theta_domain
    edges = [lo, *_cuts(level), hi]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def _interval_grid(a: float, b: float, n: int) -> FloatArray:
    """``n`` points inside ``(a, b)``, clustered towards both ends (where ``C2*`` diverges)."""
    u = (np.arange(n) + 0.5) / n
    grid: FloatArray = a + (b - a) * 0.5 * (1.0 - np.cos(np.pi * u))
    return grid


@dataclass(frozen=True)
class Fold:
    """A fold of the diagram: an extremum of ``C2*``, where a centre and a saddle merge.

    Attributes
    ----------
    C2, gamma3, h : float
        The level ``C2``, the steady motion's ``gamma3`` and its energy ``h``.
    kind : {"max", "min"}
        Whether ``C2*`` has a local maximum or minimum there (in ``gamma3``).
    theta : float
        The signed nutation angle (``gamma3 = cos theta``; negative beyond a pole passage).
    """

    C2: float
    gamma3: float
    h: float
    kind: str
    theta: float = math.nan

    def to_dict(self) -> dict[str, Any]:
        return {
            "C2": self.C2,
            "gamma3": self.gamma3,
            "h": self.h,
            "kind": self.kind,
            "theta": self.theta,
        }


def folds(body: SphericalTop, M3: float, C1: float) -> list[Fold]:
    """Every fold of the ``(C2, h)`` diagram of ``(M3, C1)``, sorted by ``gamma3`` (by
    decreasing signed ``theta`` on a pole level).

    The zeros of ``dC2*/dtheta`` (complex step) bracketed on :data:`BRANCH_POINTS` points per
    interval between poles and refined by Brent's method to round-off; a pair of folds closer
    than the grid's spacing would be missed.
    """
    level = _base_level(body, M3, C1)
    t0 = _family(level)
    found = []
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for a, b in _intervals(level):
            th = _interval_grid(a, b, BRANCH_POINTS)
            d = _dc2_star(level, th)
            sign = np.sign(d)
            for k in np.flatnonzero(sign[:-1] * sign[1:] < 0):
                if not (np.isfinite(d[k]) and np.isfinite(d[k + 1])):
                    continue
                t = brentq(
                    lambda x: float(_dc2_star(level, np.array(x))),
                    th[k],
                    th[k + 1],
                    xtol=1e-15,
                    rtol=4 * np.finfo(float).eps,
                )
                if t0 is not None and abs(t - t0) < FAMILY_GAP:
                    continue  # where the curve meets the family of a3 = 0: a pitchfork
                c2 = float(_c2_star(level, t))
                h = float(_energy_on_curve(level, np.array(t), np.array(c2)))
                # C2* has a maximum in theta where its derivative goes from + to -; in gamma3
                # (decreasing in theta) the same point is a maximum too
                kind = "max" if d[k] > 0 else "min"
                found.append(Fold(c2, math.cos(t), h, kind, float(t)))
    return sorted(found, key=lambda f: -f.theta)


@dataclass(frozen=True)
class Branch:
    """One curve of critical values, between two poles of ``C2*`` (or a pole and an end).

    Attributes
    ----------
    gamma3, C2, h : ndarray, shape (n,)
        Points ``(C2*(gamma3), h*(gamma3))`` of the curve.
    theta : ndarray, shape (n,)
        The signed nutation angle of each point (``gamma3 = cos theta``).
    centre : ndarray of bool, shape (n,)
        Whether the steady motion there is a centre (``U'' > 0``); saddles elsewhere.
    """

    gamma3: FloatArray
    C2: FloatArray
    h: FloatArray
    centre: NDArray[np.bool_]
    theta: FloatArray


def _branches(level: LevelSet, n: int = BRANCH_POINTS) -> list[Branch]:
    out = []
    b = level.body
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for a, e in _intervals(level):
            th = _interval_grid(a, e, n)
            c2 = _c2_star(level, th)
            h = _energy_on_curve(level, th, c2)
            _, _, _, dq2 = level._q(th)
            # U'' = -m P' C2*' / I1^2 (derivative of U'(theta; C2*(theta)) = 0 along the curve)
            u2 = -b.m * (dq2 + level.M3 * b.a3) * _dc2_star(level, th) / b.I1**2
            out.append(Branch(np.cos(th)[::-1], c2[::-1], h[::-1], (u2 > 0)[::-1], th[::-1]))
    return out


def _family_curvature(level: LevelSet, t0: float) -> tuple[float, float]:
    """``U0''(t0)`` and ``m P''(t0) / I1^2``: on the family ``theta = t0`` (``a3 = 0``)
    ``U''(t0; C2) = U0''(t0) + C2 m P''(t0) / I1^2`` (``P''`` by the complex step)."""
    b = level.body
    _, _, _, dq2 = level._q(np.array([t0 + 1j * _COMPLEX_STEP]))
    p2 = float(np.imag(dq2[0])) / _COMPLEX_STEP
    return float(level.d2U(t0)), b.m * p2 / b.I1**2


def _pitchfork_c2(level: LevelSet, t0: float) -> float:
    """The ``C2`` at which the family ``theta = t0`` (``a3 = 0``) changes type, ``U'' = 0``."""
    u0, slope = _family_curvature(level, t0)
    return -u0 / slope


def _family_branch(level: LevelSet, t0: float, window: tuple[float, float]) -> Branch:
    """The curve of the family ``theta = t0`` (``a3 = 0``) over the ``C2`` window: ``h = U(t0;
    C2)``, a centre where ``U''(t0; C2) > 0``."""
    c2 = np.linspace(window[0], window[1], 801)
    th = np.full_like(c2, t0)
    u0, slope = _family_curvature(level, t0)
    return Branch(np.cos(th), c2, _energy_on_curve(level, th, c2), u0 + slope * c2 > 0, th)


def _critical(level: LevelSet) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Critical points of ``U`` on ``level`` in order of decreasing signed ``theta`` (increasing
    ``gamma3`` off a pole level): ``theta``, ``U`` and ``U''_theta`` there
    (:func:`rollingtop.reduction.steady.critical_points` on :data:`CLASSIFY_POINTS` points, with
    its points at the thin wall next to a pole on a level near a pole level)."""
    lo, hi = level.theta_domain  # CLASSIFY_POINTS per pi of the domain (a pole level has 2 pi)
    points = int(CLASSIFY_POINTS * (hi - lo) / math.pi)
    th = critical_points(level, points)[::-1].copy()  # increasing gamma3 on (0, pi)
    return th, level.U(th), level.d2U(th) if th.size else th
