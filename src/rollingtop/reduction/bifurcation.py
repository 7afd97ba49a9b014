"""Bifurcation diagrams of the reduced system: the classification the paper leaves open (Sec. 3.3).

Fix the body and the integrals ``(M3, C1)``. On the level set ``(M3, C1, C2)`` the effective
potential (eq. 3.11, :class:`~rollingtop.reduction.LevelSet`) is, in the nutation angle ``theta``
(``gamma3 = cos theta``),

    U(theta; C2) = U0(theta) + m ((P0 + C2)^2 - P0^2) / (2 I1^2),    P = P0(theta) + C2 = I1 v_tau,

where ``U0, P0`` are ``U, P`` at ``C2 = 0``. So ``dU/dtheta = U0'(theta) + m C2 P'(theta) / I1^2``
is affine in ``C2`` (``P' = dP/dtheta`` does not depend on ``C2``), and ``theta`` is a steady
motion of the level ``C2`` exactly when

    C2 = C2*(theta) = -I1^2 U0'(theta) / (m P'(theta)).

In ``gamma3``, ``dP/dgamma3 = (M3 gamma3 - C1)(R + a3 gamma3) / s^3`` (``s = sin theta``): ``C2*``
has a pole at ``gamma3 = C1/M3`` (and at ``gamma3 = -R/a3`` for a centre of mass outside the
sphere), where ``U0'`` stays ``-m g a3 s != 0``; between the poles it is smooth. With the centre
of mass at the centre (``a3 = 0``) ``U0'`` vanishes there too: the pole is removable, and
``gamma3 = C1/M3`` is a steady motion for every ``C2`` -- a family drawn as a curve of its own,
which the other curve crosses (a pitchfork there, not a fold). The critical
values form the curves ``theta -> (C2*(theta), h*(theta))``, ``h* = U(theta; C2*(theta))``, in the
plane ``(C2, h)``. Along a curve ``U'' = -m P' C2*' / I1^2``: the critical point is a centre where
``P' C2*' < 0``, a saddle where ``> 0``, and the two meet at the **folds**, the extrema of ``C2*``
(cusps of the curves in the ``(C2, h)`` plane, where a centre and a saddle are born or die).

The **regions** of the plane between the curves (above ``min U``) are classified by what the level
``h`` holds: ``U -> +inf`` at both poles when ``|C1| != |M3|``, so ``{U < h}`` is a union of
intervals, each one periodic orbit of ``gamma3`` around the centres (minima of ``U``) it contains.
In the plane ``(C1, C2)`` at fixed ``M3`` the number of steady motions changes across the fold
curves ``C1 -> C2*(fold)``.

On a pole level (``C1 = +-M3``) the signed nutation angle covers both sides of the pole, where
``U`` is finite and smooth (:mod:`rollingtop.reduction.level`): an orbit whose interval of
``{U < h}`` contains the pole passes through it, and the regions say which do. The level without
spin (``M3 = C1 = 0``, ``U`` periodic) is refused.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from rollingtop._json import json_ready
from rollingtop.body import SphericalTop
from rollingtop.reduction.level import LevelSet, LevelSetError
from rollingtop.reduction.steady import critical_points

__all__ = [
    "BifurcationDiagram",
    "Branch",
    "Fold",
    "Region",
    "SteadyCountMap",
    "bifurcation_diagram",
    "critical_c2",
    "critical_energy",
    "folds",
    "region_signature",
    "steady_count_map",
]

FloatArray = NDArray[np.float64]

#: Points of ``theta`` per interval between poles of ``C2*`` (clustered towards the ends).
BRANCH_POINTS = 4001
#: Points of ``theta`` per ``pi`` of the domain on which ``dU`` is sampled to find a level's
#: critical points (:func:`rollingtop.reduction.steady.critical_points`).
CLASSIFY_POINTS = 1201
#: Extrema of ``C2*`` this close to the family of ``a3 = 0`` are where the curve meets it.
FAMILY_GAP = 1e-4
#: Critical values closer than this (relative) are one value: no region between them.
EQUAL_VALUES = 1e-9
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
        return {"C2": self.C2, "gamma3": self.gamma3, "h": self.h, "kind": self.kind,
                "theta": self.theta}  # fmt: skip


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
                t = brentq(lambda x: float(_dc2_star(level, np.array(x))), th[k], th[k + 1],
                           xtol=1e-15, rtol=4 * np.finfo(float).eps)  # fmt: skip
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


#: Marks an orbit (a tuple of centre indices) that passes through the pole.
THROUGH_POLE = -1
#: The pole's energy among the cuts of a column's h axis (pole levels).
POLE_CUT = -2


def _orbits_at(
    U: FloatArray,
    centre: NDArray[np.bool_],
    h: float,
    theta: FloatArray | None = None,
    pole: tuple[float, float] | None = None,
) -> tuple[tuple[int, ...], ...]:
    """The periodic orbits of the level ``h`` from the critical points (in order of decreasing
    ``theta``, ``U`` there, which are centres): each orbit as the indices of the centres it
    encloses, followed by :data:`THROUGH_POLE` when it passes through ``pole`` = ``(theta_p,
    U(theta_p))`` (a pole level; ``theta`` the critical points' angles). Exact: ``U`` is monotone
    between critical points and ``+inf`` at both ends of the domain, so the intervals of
    ``{U < h}`` are separated by the saddles with ``U >= h``."""
    orbits: list[tuple[int, ...]] = []
    group: list[int] = []
    upper = math.inf  # theta of the saddle that bounds the current group from above

    def close(lower: float) -> None:
        if not group:
            return
        through = pole is not None and pole[1] < h and lower < pole[0] < upper
        orbits.append((*group, THROUGH_POLE) if through else tuple(group))

    for k in range(len(U)):
        if not centre[k] and U[k] >= h:
            close(float(theta[k]) if theta is not None else -math.inf)
            group = []
            upper = float(theta[k]) if theta is not None else math.inf
        elif centre[k] and U[k] < h:
            group.append(k)
    close(-math.inf)
    return tuple(orbits)


def _centres(orbit: Sequence[int]) -> list[int]:
    return [k for k in orbit if k != THROUGH_POLE]


def _pole(level: LevelSet) -> tuple[float, float] | None:
    """``(theta, U)`` of the pole an orbit of a pole level can pass, else ``None``."""
    t = level.pole_theta
    return None if t is None else (t, float(level.U(t)))


def region_orbits(level: LevelSet, h: float) -> list[tuple[int, bool]]:
    """What the level ``h`` of ``level`` holds: for each periodic orbit (each interval of
    ``{U < h}``, in order of increasing ``gamma3``, or of decreasing signed ``theta`` on a pole
    level) the number of centres (minima of ``U``) inside it and whether it passes through the
    pole; ``[]``: no motion (``h <= min U``)."""
    _base_level(level.body, level.M3, level.C1)  # refuses the level without spin
    theta, U, u2 = _critical(level)
    return [(len(_centres(o)), THROUGH_POLE in o)
            for o in _orbits_at(U, u2 > 0, h, theta, _pole(level))]  # fmt: skip


def region_signature(level: LevelSet, h: float) -> tuple[int, ...]:
    """The number of centres inside each orbit of the level ``h`` (:func:`region_orbits`)."""
    return tuple(n for n, _ in region_orbits(level, h))


def describe_signature(signature: Sequence[int], through_pole: Sequence[bool] = ()) -> str:
    """Words for a :func:`region_signature`: ``"1 orbit around 1 centre"``, ``"2 orbits around
    1 + 1 centres"``, ``"no motion"``; with ``through_pole``, which orbits pass the pole."""
    if not signature:
        return "no motion"
    n = len(signature)
    centres = " + ".join(str(c) for c in signature)
    plural = "s" if n > 1 or signature[0] != 1 else ""
    words = f"{n} orbit{'s' if n > 1 else ''} around {centres} centre{plural}"
    passing = [k for k, p in enumerate(through_pole) if p]
    if passing and n == 1:
        words += ", through the pole"
    elif passing:
        which = " and ".join(f"orbit {k + 1}" for k in passing)
        words += f" ({which} through the pole)"
    return words


@dataclass(frozen=True)
class Region:
    """A connected region of the ``(C2, h)`` plane in which every level holds the same orbits.

    Attributes
    ----------
    name : str
        ``"A"``, ``"B"``, ... in order of the representative point's ``C2``, then ``h``.
    signature : tuple of int
        Centres inside each periodic orbit, in order of increasing ``gamma3``
        (:func:`region_signature`).
    label : str
        The signature in words.
    C2, h : float
        A representative level: the middle of the region's interval of ``h`` in its middle
        column.
    centre_gamma3 : tuple of tuple of float
        At the representative level: ``gamma3`` of the centres inside each orbit.
    through_pole : tuple of bool
        Whether each orbit passes through the pole (pole levels ``C1 = +-M3`` only).
    C2_range, h_range : tuple of float
        The extent of the region on the grid.
    cells : int
        The number of columns (values of ``C2`` on the grid) it spans.
    """

    name: str
    signature: tuple[int, ...]
    label: str
    C2: float
    h: float
    centre_gamma3: tuple[tuple[float, ...], ...]
    through_pole: tuple[bool, ...]
    C2_range: tuple[float, float]
    h_range: tuple[float, float]
    cells: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name, "label": self.label, "orbits": len(self.signature),
            "centres_per_orbit": list(self.signature), "C2": self.C2, "h": self.h,
            "centre_gamma3": [list(g) for g in self.centre_gamma3],
            "through_pole": list(self.through_pole),
            "C2_range": list(self.C2_range), "h_range": list(self.h_range), "cells": self.cells,
        }  # fmt: skip


@dataclass(frozen=True)
class BifurcationDiagram:
    """The bifurcation diagram of ``(M3, C1)`` in the plane ``(C2, h)``.

    Attributes
    ----------
    body : SphericalTop
    M3, C1 : float
    branches : list of Branch
        The curves of critical values.
    folds : list of Fold
    regions : list of Region
    C2_grid, h_grid : ndarray, shapes (nc,), (nh,)
        The grid the regions were found on.
    region_index : ndarray of int, shape (nh, nc)
        Index into ``regions`` of each grid cell, for drawing (-1: no motion).
    min_U : ndarray, shape (nc,)
        ``min U`` over ``gamma3`` at each ``C2`` of the grid (below it: no motion).
    pole_energy : ndarray, shape (nc,)
        On a pole level, ``U`` at the pole for each ``C2`` of the grid: above it the orbits pass
        through the pole (NaN off the pole levels).
    """

    body: SphericalTop
    M3: float
    C1: float
    branches: list[Branch]
    folds: list[Fold]
    regions: list[Region]
    C2_grid: FloatArray
    h_grid: FloatArray
    region_index: NDArray[np.int64]
    min_U: FloatArray
    pole_energy: FloatArray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: the folds, the regions and the grid's extent."""
        return json_ready({
            "M3": self.M3, "C1": self.C1,
            "folds": [f.to_dict() for f in self.folds],
            "regions": [r.to_dict() for r in self.regions],
            "C2_range": [float(self.C2_grid[0]), float(self.C2_grid[-1])],
            "h_range": [float(self.h_grid[0]), float(self.h_grid[-1])],
            "grid": [len(self.C2_grid), len(self.h_grid)],
        })  # fmt: skip


def _default_c2_range(level: LevelSet, fs: Sequence[Fold]) -> tuple[float, float]:
    if fs:
        lo, hi = min(f.C2 for f in fs), max(f.C2 for f in fs)
    else:
        lo = hi = 0.0
    pad = max(1.0, 0.6 * (hi - lo))
    return lo - pad, hi + pad


def _default_h_range(
    branches: Sequence[Branch], c2: tuple[float, float], min_u: float
) -> tuple[float, float]:
    """From just below ``min_u`` to above the highest saddle with ``C2`` in ``c2`` (above the
    highest centre when there is no saddle)."""
    saddles, centres = [min_u], [min_u]
    for br in branches:
        inside = (br.C2 >= c2[0]) & (br.C2 <= c2[1]) & np.isfinite(br.h)
        saddles += br.h[inside & ~br.centre].tolist()
        centres += br.h[inside & br.centre].tolist()
    top = max(saddles) if len(saddles) > 1 else max(centres)
    span = max(top - min_u, 1e-3 * max(1.0, abs(min_u)))
    return min_u - 0.05 * span, top + 0.35 * span


def bifurcation_diagram(
    body: SphericalTop,
    M3: float,
    C1: float,
    *,
    C2_range: tuple[float, float] | None = None,
    h_range: tuple[float, float] | None = None,
    resolution: tuple[int, int] = (161, 161),
) -> BifurcationDiagram:
    """The bifurcation diagram of the reduced system at ``(M3, C1)`` in the plane ``(C2, h)``.

    Parameters
    ----------
    body : SphericalTop
        Dynamically symmetric body.
    M3, C1 : float
        Lagrange and area integrals; pole levels ``C1 = +-M3`` are refused.
    C2_range, h_range : (float, float), optional
        Window of the diagram. Default: the folds' ``C2`` widened by 60 % (at least 1 on each
        side); ``h`` from just below ``min U`` to above the highest saddle in that window.
    resolution : (int, int)
        ``nc`` values of ``C2`` (columns) and ``nh`` of ``h`` (for drawing). In each column the
        critical values cut the ``h`` axis into intervals with one set of orbits each
        (exact: :func:`region_signature`). Intervals of neighbouring columns belong to one
        region when they hold the same orbits around the same centres and share a bounding
        critical point or,
        across a fold (the number of critical points changes), when their orbits are of the
        same kind and they overlap. A region narrower than the column spacing in ``C2`` can be
        missed.

    Returns
    -------
    BifurcationDiagram
    """
    level = _base_level(body, M3, C1)
    nc, nh = (int(x) for x in resolution)
    if nc < 3 or nh < 3:
        raise LevelSetError(f"resolution = {resolution} must be at least (3, 3)")
    fs = folds(body, M3, C1)
    branches = _branches(level)
    marks = list(fs)
    t0 = _family(level)
    if t0 is not None:  # a3 = 0: the pitchfork where the family changes type belongs in view
        marks.append(Fold(_pitchfork_c2(level, t0), math.cos(t0), math.nan, "pitchfork", t0))
    c2_lo, c2_hi = C2_range if C2_range is not None else _default_c2_range(level, marks)
    if not (math.isfinite(c2_lo) and math.isfinite(c2_hi) and c2_lo < c2_hi):
        raise LevelSetError(f"C2 range ({c2_lo:g}, {c2_hi:g}) must be finite and increasing")
    C2_grid = np.linspace(c2_lo, c2_hi, nc)
    if t0 is not None:
        branches.append(_family_branch(level, t0, (c2_lo, c2_hi)))
    # per column: the critical values cut the h axis into intervals, each with one set of
    # orbits; a node is (column, lo, hi, orbits, its bounding critical points' indices, count)
    nodes: list[tuple[int, float, float, tuple[tuple[int, ...], ...], tuple[int, int, int]]] = []
    columns: list[list[int]] = []
    gammas: list[FloatArray] = []
    min_U = np.empty(nc)
    pole_energy = np.full(nc, np.nan)
    for j, c2 in enumerate(C2_grid):
        lv = LevelSet(body, level.M3, level.C1, float(c2))
        th, U, u2 = _critical(lv)
        gammas.append(np.cos(th))
        pole = _pole(lv)
        centre = u2 > 0
        min_U[j] = float(np.min(U[centre])) if centre.any() else math.nan
        # the h axis is cut at the critical values and, on a pole level, at the pole's energy
        # (above it orbits pass through the pole); POLE_CUT stands for the pole in the ids
        cut_values = [(float(u), k) for k, u in enumerate(U)]
        if pole is not None:
            cut_values.append((pole[1], POLE_CUT))
            pole_energy[j] = pole[1]
        cut_values.sort()
        column = []
        for pos, (lo, k) in enumerate(cut_values):
            upper = cut_values[pos + 1][1] if pos + 1 < len(cut_values) else -1
            hi = cut_values[pos + 1][0] if pos + 1 < len(cut_values) else math.inf
            if math.isfinite(hi) and not hi - lo > EQUAL_VALUES * max(1.0, abs(lo), abs(hi)):
                continue  # equal critical values (a symmetric body's twin wells), to round-off
            mid = 0.5 * (lo + hi) if math.isfinite(hi) else lo + 1.0 + abs(lo)
            column.append(len(nodes))
            nodes.append((j, lo, hi, _orbits_at(U, centre, mid, th, pole), (k, upper, len(U))))
        columns.append(column)
    if h_range is None:
        h_range = _default_h_range(branches, (c2_lo, c2_hi), float(np.nanmin(min_U)))
    h_lo, h_hi = h_range
    if not (math.isfinite(h_lo) and math.isfinite(h_hi) and h_lo < h_hi):
        raise LevelSetError(f"h range ({h_lo:g}, {h_hi:g}) must be finite and increasing")
    h_grid = np.linspace(h_lo, h_hi, nh)
    # regions: nodes of neighbouring columns with the same orbits and overlapping h intervals
    parent = list(range(len(nodes)))

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def same_region(a: int, b: int) -> bool:
        (_, lo1, hi1, o1, id1), (_, lo2, hi2, o2, id2) = nodes[a], nodes[b]
        if id1[2] == id2[2]:
            # no fold between the columns: the same orbits (around the same centres) above the
            # same critical value or below the same one (where two curves cross, a region
            # keeps one of its two bounding curves; a strip between the crossing curves keeps
            # neither)
            return o1 == o2 and (id1[0] == id2[0] or id1[1] == id2[1])
        # a fold between them: the same kind of orbits, overlapping in h
        return _kinds(o1) == _kinds(o2) and lo1 < hi2 and lo2 < hi1

    for j in range(nc - 1):
        for a in columns[j]:
            for b in columns[j + 1]:
                if same_region(a, b):
                    parent[find(a)] = find(b)
    members: dict[int, list[int]] = {}
    for a in range(len(nodes)):
        if nodes[a][3] and nodes[a][2] > h_lo and nodes[a][1] < h_hi:  # motion, in the window
            members.setdefault(find(a), []).append(a)
    reps = []
    for group in members.values():
        cols = sorted(nodes[a][0] for a in group)
        middle = cols[len(cols) // 2]
        a = next(a for a in group if nodes[a][0] == middle)
        j, lo, hi, orbits, _ = nodes[a]
        lo_c, hi_c = max(lo, h_lo), min(hi, h_hi)
        los = [max(nodes[b][1], h_lo) for b in group]
        his = [min(nodes[b][2], h_hi) for b in group]
        where = tuple(tuple(float(gammas[j][k]) for k in _centres(orbit)) for orbit in orbits)
        reps.append((float(C2_grid[j]), 0.5 * (lo_c + hi_c), orbits, group, min(los), max(his),
                     where))  # fmt: skip
    reps.sort(key=lambda r: (r[0], r[1]))
    region_index = np.full((nh, nc), -1, dtype=np.int64)
    regions = []
    for n_reg, (c2, h, orbits, group, lo, hi, where) in enumerate(reps):
        cols = [nodes[a][0] for a in group]
        for a in group:
            j, lo_a, hi_a, _, _ = nodes[a]
            region_index[(h_grid > lo_a) & (h_grid <= hi_a), j] = n_reg
        sig = tuple(len(_centres(o)) for o in orbits)
        passing = tuple(THROUGH_POLE in o for o in orbits)
        regions.append(Region(
            name=_region_name(n_reg), signature=sig, label=describe_signature(sig, passing),
            C2=c2, h=h, centre_gamma3=where, through_pole=passing,
            C2_range=(float(C2_grid[min(cols)]), float(C2_grid[max(cols)])),
            h_range=(lo, hi), cells=len(group),
        ))  # fmt: skip
    return BifurcationDiagram(body, float(level.M3), float(level.C1), branches, fs, regions,
                              C2_grid, h_grid, region_index, min_U, pole_energy)  # fmt: skip


def _kinds(orbits: tuple[tuple[int, ...], ...]) -> list[tuple[int, bool]]:
    return [(len(_centres(o)), THROUGH_POLE in o) for o in orbits]


def _region_name(k: int) -> str:
    letters = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
    return letters[k] if k < 26 else f"{letters[k // 26 - 1]}{letters[k % 26]}"


@dataclass(frozen=True)
class SteadyCountMap:
    """The number of steady motions over the plane ``(C1, C2)`` at fixed ``M3``.

    Attributes
    ----------
    M3 : float
    C1_grid, C2_grid : ndarray, shapes (n1,), (n2,)
    count : ndarray of int, shape (n2, n1)
        Number of critical points of ``U`` (on a pole line ``C1 = +-M3``, in the signed angle's
        domain; -1 for the level without spin, ``M3 = C1 = 0``, which is not classified).
    fold_C1, fold_C2 : ndarray, shape (k,)
        Points of the fold curves: every fold of every ``C1`` of the grid.
    """

    M3: float
    C1_grid: FloatArray
    C2_grid: FloatArray
    count: NDArray[np.int64]
    fold_C1: FloatArray
    fold_C2: FloatArray

    def to_dict(self) -> dict[str, Any]:
        values, cells = np.unique(self.count[self.count >= 0], return_counts=True)
        return json_ready({
            "M3": self.M3,
            "C1_range": [float(self.C1_grid[0]), float(self.C1_grid[-1])],
            "C2_range": [float(self.C2_grid[0]), float(self.C2_grid[-1])],
            "grid": [len(self.C1_grid), len(self.C2_grid)],
            "steady_counts": {str(int(v)): int(c) for v, c in zip(values, cells, strict=True)},
            "fold_curve": [[float(a), float(b)] for a, b in
                           zip(self.fold_C1, self.fold_C2, strict=True)],
        })  # fmt: skip


def steady_count_map(
    body: SphericalTop,
    M3: float,
    *,
    C1_range: tuple[float, float],
    C2_range: tuple[float, float],
    resolution: tuple[int, int] = (121, 121),
) -> SteadyCountMap:
    """The number of steady motions at each ``(C1, C2)`` of a grid, and the fold curves.

    For each ``C1`` the steady motions of the level ``C2`` are the solutions of
    ``C2*(gamma3) = C2``, counted as sign changes of ``C2* - C2`` on each interval between the
    poles of ``C2*`` (:data:`BRANCH_POINTS` points each).
    """
    n1, n2 = (int(x) for x in resolution)
    if n1 < 2 or n2 < 2:
        raise LevelSetError(f"resolution = {resolution} must be at least (2, 2)")
    C1_grid = np.linspace(*C1_range, n1)
    C2_grid = np.linspace(*C2_range, n2)
    count = np.full((n2, n1), -1, dtype=np.int64)
    fold_c1: list[float] = []
    fold_c2: list[float] = []
    for k, c1 in enumerate(C1_grid):
        try:
            level = _base_level(body, M3, float(c1))
        except LevelSetError:
            continue  # a pole line
        # the family gamma3 = C1/M3 of a body with a3 = 0 is a steady motion at every C2
        total = np.full(n2, 0 if _family(level) is None else 1, dtype=np.int64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for a, e in _intervals(level):
                c2s = _c2_star(level, _interval_grid(a, e, BRANCH_POINTS))
                diff = np.sign(c2s[None, :] - C2_grid[:, None])
                total += np.count_nonzero(diff[:, :-1] * diff[:, 1:] < 0, axis=1)
        count[:, k] = total
        for f in folds(body, M3, float(c1)):
            fold_c1.append(float(c1))
            fold_c2.append(f.C2)
    return SteadyCountMap(float(M3), C1_grid, C2_grid, count, np.array(fold_c1),
                          np.array(fold_c2))  # fmt: skip
