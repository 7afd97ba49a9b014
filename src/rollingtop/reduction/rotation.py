"""Rotation numbers: the classes of motion in absolute space (issue 14, section 3).

Over one period ``T`` of ``gamma3`` the axis azimuth advances by ``Delta psi`` and the motion on
the plane is a rigid motion (:mod:`rollingtop.absolute`). The **rotation number**
``N = Delta psi / (2 pi)`` decides what the contact point and the centre of mass do:

- ``N`` an integer: the rigid motion is a translation -- the body **drifts** without bound;
- ``N = p/q`` in lowest terms with ``q >= 2``: after ``q`` periods the motion repeats -- the
  paths are **closed**;
- otherwise the paths fill an annulus -- **bounded, quasi-periodic**.

``N`` depends on the level ``(C2, h)`` continuously along a family of orbits; the levels with
``N`` an integer form the *resonance curves* of the ``(C2, h)`` plane, and those with small ``q``
the low-order closed paths. At a centre ``N`` tends to ``psi' / omega`` (small oscillations
of frequency ``omega`` while the axis precesses at ``psi'``); towards a separatrix the period
grows like ``ln(1 / |h - h_s|) / lambda`` (``lambda`` the saddle's growth rate), so ``N``
diverges logarithmically with slope ``-k psi'_s / (2 pi lambda)`` against ``ln |h - h_s|``
(``k`` = 1 for an orbit that passes the saddle once a period, 2 for one around two wells) and
the resonance curves accumulate at the separatrix.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._json import json_ready
from rollingtop.body import SphericalTop
from rollingtop.reduction._quadrature import period
from rollingtop.reduction._roots import brentq
from rollingtop.reduction.level import Level, LevelSet, LevelSetError
from rollingtop.reduction.orbits import Orbit, canonical_orbit, orbits
from rollingtop.reduction.steady import SteadyMotion, critical_points

__all__ = [
    "RESONANCE_TOLERANCE",
    "RotationMap",
    "centre_rotation_number",
    "classify_rotation",
    "rotation_map",
    "rotation_number",
    "rotation_numbers",
]

FloatArray = NDArray[np.float64]

#: ``|N - p/q|`` below this: resonant (drifting for ``q = 1``, closed for ``q >= 2``).
RESONANCE_TOLERANCE = 1e-9
#: Largest denominator of a rotation number classified as closed.
MAX_DENOMINATOR = 12
#: Resonance curves traced on the map: ``N = p/q`` with ``q`` up to this (1: drifting).
CURVE_DENOMINATOR = 3


def rotation_number(level: Level, h: float, orbit: Orbit) -> tuple[float, float]:
    """``N = Delta psi / (2 pi)`` of a periodic orbit on ``level`` at energy ``h``, with its
    estimated absolute error (the quadrature of ``psi'`` over a period, as for the period)."""
    if orbit.kind != "periodic":
        raise LevelSetError(f"no rotation number for a {orbit.kind} orbit ({orbit.note})")
    if level.pole == "both":  # no spin: the axis does not precess
        return 0.0, 0.0
    exact_level, exact_orbit = canonical_orbit(level, h, orbit)
    lo, hi = exact_orbit.theta_min, exact_orbit.theta_max
    # break points of the quadrature: the pole, and the critical points inside the orbit (a
    # saddle there makes the integrand's logarithmic peak near a separatrix)
    inside = [float(c) for c in critical_points(exact_level) if lo < c < hi]
    peaks = [t for t in (exact_level.pole_theta,) if t is not None] + inside
    dpsi, err = period(
        exact_level, h, exact_orbit.theta_min, exact_orbit.theta_max, peaks=peaks, weight="psi_dot"
    )
    return dpsi / (2 * math.pi), err / (2 * math.pi)


def rotation_numbers(level: Level, h: float) -> list[float]:
    """``N`` of each periodic orbit of the level ``h`` (in order of increasing ``gamma3``)."""
    return [rotation_number(level, h, o)[0] for o in orbits(level, h) if o.kind == "periodic"]


def centre_rotation_number(motion: SteadyMotion) -> float:
    """The limit of ``N`` at a centre: ``psi' / omega``."""
    if motion.type != "center":
        raise LevelSetError(f"a {motion.type} has no small oscillations")
    return motion.precession_rate / motion.frequency


def classify_rotation(N: float, max_denominator: int = MAX_DENOMINATOR) -> dict[str, Any]:
    """The class of motion of rotation number ``N``: ``{"class": "drifting" | "closed" |
    "quasi-periodic", "p", "q"}`` (``p/q`` the nearest fraction with ``q <= max_denominator``;
    ``None`` for quasi-periodic)."""
    frac = Fraction(N).limit_denominator(max_denominator)
    if abs(N - float(frac)) <= RESONANCE_TOLERANCE:
        kind = "drifting" if frac.denominator == 1 else "closed"
        return {"class": kind, "p": frac.numerator, "q": frac.denominator}
    return {"class": "quasi-periodic", "p": None, "q": None}


@dataclass(frozen=True)
class RotationMap:
    """``N`` over a grid of the ``(C2, h)`` plane at fixed ``(M3, C1)``.

    Attributes
    ----------
    C2_grid, h_grid : ndarray, shapes (nc,), (nh,)
    N : ndarray, shape (nh, nc, k)
        Rotation number of each periodic orbit of the level (in order of increasing
        ``gamma3``; NaN where the level has fewer than ``k`` orbits or none).
    family : ndarray of int, shape (nh, nc, k)
        Which family each orbit belongs to, for joining grid points: a code of the centres
        (minima of ``U``, numbered in order of ``gamma3`` among all critical points) the orbit
        encloses; -1 where there is no orbit. Along a column ``N`` is continuous within a
        family.
    resonances : list of dict
        Points ``{"N", "p", "q", "C2", "h", "orbit"}`` of the resonance curves ``N = p/q`` with
        ``q <= CURVE_DENOMINATOR`` (``q = 1``: drifting; else closed after ``q`` periods), found
        by Brent's method along each column between grid points of the same orbit family.
    """

    M3: float
    C1: float
    C2_grid: FloatArray
    h_grid: FloatArray
    N: FloatArray
    family: NDArray[np.int64]
    resonances: list[dict[str, Any]]

    def to_dict(self) -> dict[str, Any]:
        finite = self.N[np.isfinite(self.N)]
        return json_ready(
            {
                "M3": self.M3,
                "C1": self.C1,
                "C2_range": [float(self.C2_grid[0]), float(self.C2_grid[-1])],
                "h_range": [float(self.h_grid[0]), float(self.h_grid[-1])],
                "grid": [len(self.C2_grid), len(self.h_grid)],
                "N_range": [float(finite.min()), float(finite.max())] if finite.size else None,
                "resonances": self.resonances,
            }
        )


def _family_code(theta_c: FloatArray, centre: NDArray[np.bool_], orbit: Orbit) -> int:
    """The centres inside ``orbit`` as a bit mask over the critical points (and their count)."""
    code = len(theta_c)
    for n, (t, c) in enumerate(zip(theta_c, centre, strict=True)):
        if c and orbit.theta_min <= t <= orbit.theta_max:
            code += 1 << (n + 8)
    return code


def _fractions_between(a: float, b: float, max_q: int) -> list[Fraction]:
    """Every ``p/q`` (lowest terms, ``q <= max_q``) strictly between ``a`` and ``b``."""
    lo, hi = min(a, b), max(a, b)
    out = set()
    for q in range(1, max_q + 1):
        for p in range(math.floor(lo * q) + 1, math.ceil(hi * q)):
            if lo < p / q < hi:
                out.add(Fraction(p, q))
    return sorted(out)


def _offset(h: float, level: Level, k: int, count: int, target: float) -> float:
    """``N - target`` of the ``k``-th of ``count`` orbits at ``h`` (for Brent's method)."""
    return _family_n(level, h, k, count) - target


def _family_steps(
    N: FloatArray, family: NDArray[np.int64], j: int
) -> Iterator[tuple[int, int, int]]:
    """``(i, k, count)`` for the neighbouring grid levels ``i, i + 1`` of column ``j`` that hold
    the same number ``count`` of orbits and where orbit ``k`` is of one family at both: there
    ``N`` is continuous between them."""
    counts = np.sum(np.isfinite(N[:, j, :]), axis=1)
    for i in range(N.shape[0] - 1):
        if counts[i] != counts[i + 1] or counts[i] == 0:
            continue
        for k in range(int(counts[i])):
            if family[i, j, k] == family[i + 1, j, k]:
                yield i, k, int(counts[i])


def _solve_level(
    level: Level,
    bracket: tuple[float, float],
    k: int,
    count: int,
    target: float,
    xtol: float,
) -> float | None:
    """The ``h`` in ``bracket`` where orbit ``k`` of ``count`` has ``N = target`` (Brent's
    method), or ``None`` where ``N - target`` does not change sign."""
    try:
        h: float = brentq(_offset, *bracket, args=(level, k, count, target), xtol=xtol)
    except ValueError:
        return None
    return h


def _family_n(level: Level, h: float, k: int, count: int) -> float:
    """``N`` of the ``k``-th of ``count`` periodic orbits at ``h`` (NaN if the count differs)."""
    periodic = [o for o in orbits(level, h) if o.kind == "periodic"]
    if len(periodic) != count:
        return math.nan
    return rotation_number(level, h, periodic[k])[0]


def rotation_map(
    body: SphericalTop,
    M3: float,
    C1: float,
    *,
    C2_range: tuple[float, float],
    h_range: tuple[float, float],
    resolution: tuple[int, int] = (41, 41),
    max_orbits: int = 2,
    progress: Callable[[int, int], None] | None = None,
) -> RotationMap:
    """Rotation numbers over a grid of ``(C2, h)`` and the integer-resonance points.

    Parameters
    ----------
    body : SphericalTop
    M3, C1 : float
        Not a pole level.
    C2_range, h_range : (float, float)
        The window.
    resolution : (int, int)
        ``(nc, nh)`` grid points.
    max_orbits : int
        Orbits per level kept in ``N`` (levels with more are truncated).
    progress : callable, optional
        ``progress(done, total)`` after each column of ``C2``.
    """
    nc, nh = (int(x) for x in resolution)
    if nc < 2 or nh < 2 or max_orbits < 1:
        raise LevelSetError(
            f"resolution = {resolution} must be at least (2, 2) and max_orbits "
            f"= {max_orbits} at least 1"
        )
    C2_grid = np.linspace(*C2_range, nc)
    h_grid = np.linspace(*h_range, nh)
    N = np.full((nh, nc, max_orbits), np.nan)
    family = np.full((nh, nc, max_orbits), -1, dtype=np.int64)
    resonances: list[dict[str, Any]] = []
    for j, c2 in enumerate(C2_grid):
        level = LevelSet(body, M3, C1, float(c2))
        if level.pole == "both":
            raise LevelSetError(
                f"{level.describe()}: without spin the axis does not precess (N = 0); no map"
            )
        theta_c = critical_points(level)
        centre = level.d2U(theta_c) > 0 if theta_c.size else np.zeros(0, dtype=bool)
        for i, h in enumerate(h_grid):
            try:
                found = [o for o in orbits(level, float(h)) if o.kind == "periodic"]
            except LevelSetError:
                continue  # no motion below min U
            for k, o in enumerate(found[:max_orbits]):
                N[i, j, k] = rotation_number(level, float(h), o)[0]
                family[i, j, k] = _family_code(theta_c, centre, o)
        for i, k, count in _family_steps(N, family, j):
            bracket = (float(h_grid[i]), float(h_grid[i + 1]))
            for frac in _fractions_between(
                float(N[i, j, k]), float(N[i + 1, j, k]), CURVE_DENOMINATOR
            ):
                h_res = _solve_level(level, bracket, k, count, float(frac), 1e-12)
                if h_res is not None:
                    resonances.append(
                        {
                            "N": float(frac),
                            "p": frac.numerator,
                            "q": frac.denominator,
                            "C2": float(c2),
                            "h": float(h_res),
                            "orbit": k,
                        }
                    )
        if progress is not None:
            progress(j + 1, nc)
    return RotationMap(float(M3), float(C1), C2_grid, h_grid, N, family, resonances)


def _crossing(
    body: SphericalTop, rmap: RotationMap, target: float, k: int = 0
) -> tuple[float, float] | None:
    """A level ``(C2, h)`` of the map where orbit ``k`` has ``N = target`` exactly (Brent's
    method between neighbouring grid points of one family), or ``None``."""
    for j in range(rmap.N.shape[1]):
        level = LevelSet(body, rmap.M3, rmap.C1, float(rmap.C2_grid[j]))
        for i, kk, count in _family_steps(rmap.N, rmap.family, j):
            a, b = rmap.N[i, j, kk], rmap.N[i + 1, j, kk]
            if kk != k or not (min(a, b) < target < max(a, b)):
                continue
            bracket = (float(rmap.h_grid[i]), float(rmap.h_grid[i + 1]))
            h = _solve_level(level, bracket, k, count, target, 1e-13)
            if h is not None:
                return float(rmap.C2_grid[j]), h
    return None


def _simplest_fraction(a: float, b: float, max_q: int = 200) -> Fraction | None:
    """The fraction with the smallest denominator ``2 <= q <= max_q`` strictly inside ``(a, b)``
    (integers excluded: they are the drifting class)."""
    lo, hi = min(a, b), max(a, b)
    for q in range(2, max_q + 1):  # the first q with a fraction inside: stop there
        p = math.floor(lo * q) + 1
        while p / q < hi:
            if math.gcd(p, q) == 1:
                return Fraction(p, q)
            p += 1
    return None


def class_examples(body: SphericalTop, rmap: RotationMap) -> dict[str, dict[str, Any]]:
    """One level of each class of motion found on the map: ``{"drifting", "closed",
    "quasi-periodic"} -> {"C2", "h", "orbit", "N", "p", "q"}`` (the first orbit of the level;
    classes the map does not reach are left out). Drifting: an integer ``N``; closed: the
    fraction ``p/q`` with the smallest ``q >= 2`` crossed between two grid levels of one
    family; quasi-periodic: the grid level whose ``N`` is farthest from every fraction with
    denominator at most 4."""
    out: dict[str, dict[str, Any]] = {}
    n0 = rmap.N[:, :, 0]
    if not np.isfinite(n0).any():
        return out
    if rmap.resonances:
        r = next((r for r in rmap.resonances if r["orbit"] == 0 and r["q"] == 1), None)
        if r is not None:
            out["drifting"] = {
                "C2": r["C2"],
                "h": r["h"],
                "orbit": 0,
                "N": float(r["N"]),
                "p": r["p"],
                "q": 1,
            }
    best: Fraction | None = None
    for j in range(n0.shape[1]):
        for i, k, _ in _family_steps(rmap.N, rmap.family, j):
            if k != 0:
                continue
            frac = _simplest_fraction(float(n0[i, j]), float(n0[i + 1, j]))
            if frac is not None and (best is None or frac.denominator < best.denominator):
                best = frac
    if best is not None:
        found = _crossing(body, rmap, float(best))
        if found is not None:
            out["closed"] = {
                "C2": found[0],
                "h": found[1],
                "orbit": 0,
                "N": float(best),
                "p": best.numerator,
                "q": best.denominator,
            }
    dist = np.full(n0.shape, -1.0)
    ok = np.isfinite(n0)
    fracs = np.array(sorted({p / q for q in range(1, 5) for p in range(-8 * q, 8 * q + 1)}))
    dist[ok] = np.min(np.abs(n0[ok][:, None] - fracs[None, :]), axis=1)
    row, col = (int(x) for x in np.unravel_index(int(np.argmax(dist)), dist.shape))
    if dist[row, col] > 0:
        out["quasi-periodic"] = {
            "C2": float(rmap.C2_grid[col]),
            "h": float(rmap.h_grid[row]),
            "orbit": 0,
            "N": float(n0[row, col]),
            "p": None,
            "q": None,
        }
    return out
