"""Quadrature of the time along an orbit of the one-degree-of-freedom system (paper eq. 3.11).

With ``theta' = -w_tau`` and ``h = rho theta'^2/2 + U(theta)`` (:mod:`.level`), the time from one
turning point to the other and back is

    T = 2 * integral_{theta1}^{theta2} sqrt(rho(theta) / (2 (h - U(theta)))) dtheta,

and ``Delta psi`` is the same integral weighted by ``psi'(theta)``. The machinery:

- the substitution ``theta = c + d sin(phi)`` that makes the integrand smooth at the turning
  points (:func:`period`), and ``dist_pole = dist_end cosh u`` on a half orbit that ends at the
  thin wall of ``U`` next to a pole (:func:`half_integral`, :func:`half_map`);
- the energy gap ``h - U`` to full relative accuracy next to a turning point
  (:func:`energy_gap`) and the time density ``dt/dtheta`` built on it (:func:`time_density`);
- Gauss-Legendre rules doubled until two values agree to :data:`PERIOD_RTOL`
  (:func:`doubled_gauss`), and a composite rule graded towards logarithmic peaks near a
  separatrix (:func:`graded_gauss`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NamedTuple, TypeAlias

import numpy as np
from numpy.typing import NDArray

from rollingtop.reduction._gauss import PERIOD_RTOL, doubled_gauss, graded_gauss, leggauss
from rollingtop.reduction._roots import brentq
from rollingtop.reduction.level import Level

__all__ = [
    "HalfMap",
    "PERIOD_RTOL",
    "WALL_RATIO",
    "energy_gap",
    "graded_gauss",
    "half_integral",
    "half_map",
    "period",
    "time_density",
]

FloatArray: TypeAlias = NDArray[np.float64]
#: A vectorised function of one variable: an integrand, a substitution, its Jacobian.
ArrayFn: TypeAlias = Callable[[FloatArray], FloatArray]
#: A weight ``w(theta)`` of the time integral, or ``None`` (the time itself): the *name* of a
#: method of the level, a function of ``theta`` that takes the same value at ``pi - theta`` on
#: the mirrored level (:meth:`LevelSet.mirrored`), as ``"psi_dot"`` does (``Delta psi``). A name,
#: not a bound method, so that a half orbit next to the north pole can be integrated on the
#: mirror image (:func:`_wall_period`).
Weight: TypeAlias = str | None


#: Gauss-Legendre rule for the energy gap near the turning points (see :func:`energy_gap`).
_GAP_NODES, _GAP_WEIGHTS = leggauss(20)
#: Within this fraction of the orbit's width from a turning point the gap is integrated.
_GAP_NEAR = 0.1


def energy_gap(level: Level, h: float, t1: float, t2: float, phi: FloatArray) -> FloatArray:
    """``h - U(theta)`` at ``theta = c + d sin(phi)`` on ``[t1, t2]`` (``phi`` of any shape; the
    result has its shape), accurate to a few ulps *relative* to itself.

    Far from the turning points it is the plain difference. Near them the plain difference
    loses all digits (``h`` and ``U`` agree there), so it is computed as
    ``U(end) - U(theta) = integral_theta^end U'`` (``end`` the nearer turning point) by a
    20-point Gauss-Legendre rule, with the distance to ``end`` taken from ``phi`` without
    cancellation (``t2 - theta = 2 d sin^2(pi/4 - phi/2)``): ``U'`` is evaluated to full
    absolute accuracy, so the gap keeps its relative accuracy down to the turning point, also
    when that is nearly a double root (just outside a separatrix).
    """
    shape = np.shape(phi)
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    d = (t2 - t1) / 2
    theta = (t1 + t2) / 2 + d * np.sin(phi)
    out: FloatArray = h - level.U(theta)
    for end, dist in (
        (t2, 2 * d * np.sin(np.pi / 4 - phi / 2) ** 2),
        (t1, -2 * d * np.sin(np.pi / 4 + phi / 2) ** 2),
    ):
        near = np.abs(dist) < _GAP_NEAR * (t2 - t1)
        if np.any(near):
            out[near] = _gap_from_slope(level, end, dist[near] / 2)
    return out.reshape(shape)


def _gap_from_slope(level: Level, end: float, half: FloatArray) -> FloatArray:
    """``U(end) - U(theta) = integral_theta^end U'`` by a 20-point Gauss-Legendre rule, with
    ``half = (end - theta) / 2`` (signed, shape ``(n,)``) given without cancellation: the
    energy gap next to the turning point ``end`` to its full relative accuracy, shape ``(n,)``."""
    x: FloatArray = end - half[:, None] * (1 + _GAP_NODES[None, :])
    gap: FloatArray = np.sum(_GAP_WEIGHTS * level.dU(x), axis=1) * half
    return gap


def time_density(
    level: Level, theta: FloatArray, gap: FloatArray, jac: float | FloatArray, weight: Weight
) -> FloatArray:
    """``2 sqrt(rho / (2 gap)) |dtheta/du| weight(theta)``: twice ``dt/du`` (times the weight)
    in an integration variable ``u`` with Jacobian ``jac``; 0 where it is not finite (at a
    turning point the substitutions make the limit finite, the rule never samples it).

    ``theta``, ``gap = h - U(theta)`` and ``jac`` broadcast together (shape ``(n,)``); so does
    the result.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        val = 2.0 * np.sqrt(level.rho(theta) / (2.0 * np.maximum(gap, 0.0))) * jac
        if weight is not None:
            val = val * getattr(level, weight)(theta)
    density: FloatArray = np.where(np.isfinite(val), val, 0.0)
    return density


def _integrand(level: Level, h: float, t1: float, t2: float, weight: Weight = None) -> ArrayFn:
    """``2 weight(theta) dt/dtheta`` in the variable ``phi`` (``theta = c + d sin phi``)."""
    c, d = (t1 + t2) / 2, (t2 - t1) / 2

    def f(phi: FloatArray) -> FloatArray:
        theta = c + d * np.sin(phi)
        gap = energy_gap(level, h, t1, t2, phi)
        return time_density(level, theta, gap, d * np.cos(phi), weight)

    return f


#: An orbit's end closer to its pole than this fraction of the orbit's width sits next to a thin
#: wall of ``U`` (a level near a pole level): that half of the orbit is integrated in the
#: variable ``x`` of ``dist = dist_end cosh x`` (see :func:`_wall_period`).
WALL_RATIO = 0.25
#: Within this fraction of the local length scale from a turning point, ``h - U`` is integrated
#: from ``U'`` instead of subtracted (see :func:`_half_integrand`).
_GAP_NEAR_WALL = 0.1


def period(
    level: Level,
    h: float,
    theta1: float,
    theta2: float,
    peaks: Sequence[float] = (),
    weight: Weight = None,
) -> tuple[float, float]:
    """Period of the orbit between the simple turning points ``theta1 < theta2``.

    ``peaks`` are theta values of saddles near the orbit (break points for the graded
    fallback). With ``weight`` (the name of a method of the level, :data:`Weight`) the integral
    over one period of ``weight(theta(t)) dt`` instead. Returns ``(value, estimated absolute
    error)``.

    When an end of the orbit lies next to a thin wall of ``U`` at a pole (a level near a pole
    level, closer to the pole than :data:`WALL_RATIO` times the orbit's width), the orbit is
    split and each half integrated in a variable that resolves the wall
    (:func:`_wall_period`); otherwise by ``theta = c + d sin(phi)`` on the whole orbit.
    """
    walls = _walls(level, theta1, theta2)
    if any(walls):
        return _wall_period(level, h, theta1, theta2, walls, peaks, weight)
    c, d = (theta1 + theta2) / 2, (theta2 - theta1) / 2
    f = _integrand(level, h, theta1, theta2, weight)
    done = doubled_gauss(f, -math.pi / 2, math.pi / 2)
    if done is not None:
        return done
    # Slow convergence: a logarithmic peak near a saddle, inside the orbit or at a turning point
    # that is nearly a double root. Composite rule graded towards the peaks and the ends.
    breaks = [math.asin(min(1.0, max(-1.0, (p - c) / d))) for p in peaks if theta1 < p < theta2]
    coarse = graded_gauss(f, -math.pi / 2, math.pi / 2, breaks, 20)
    fine = graded_gauss(f, -math.pi / 2, math.pi / 2, breaks, 30)
    return fine, abs(fine - coarse)


def _walls(level: Level, theta1: float, theta2: float) -> tuple[bool, bool]:
    """Whether each end of the orbit ``[theta1, theta2]`` sits at a thin wall next to a pole."""
    if level.pole is not None or not 0.0 < theta1 < theta2 < math.pi:
        return (False, False)
    width = theta2 - theta1
    return (theta1 < WALL_RATIO * width, math.pi - theta2 < WALL_RATIO * width)


class HalfMap(NamedTuple):
    """The substitution ``theta(u)``, ``u in [0, u_max]``, on a half orbit (:func:`half_map`)."""

    #: End of the variable's range (``u = 0`` at the turning point).
    u_max: float
    #: ``theta(u)``.
    theta: ArrayFn
    #: ``|dtheta/du|(u)``.
    jac: ArrayFn
    #: ``|theta(u) - t_end|``, without cancellation.
    dist: ArrayFn
    #: The length on which ``U`` varies near the turning point.
    scale: float


def half_map(t_end: float, mid: float, wall: bool, left: bool) -> HalfMap:
    """The substitution for the half orbit between the turning point ``t_end`` and ``mid``.

    Returns ``(u_max, theta(u), |dtheta/du|(u), dist(u), scale)`` (a :class:`HalfMap`) with
    ``u in [0, u_max]``, ``u = 0`` at the turning point, ``dist = |theta - t_end|`` without
    cancellation and ``scale`` the length on which ``U`` varies near the turning point.

    - At a wall (``dist_pole`` = distance of ``t_end`` from its pole, 0 or pi):
      ``dist_pole(theta) = dist_pole cosh u``. The inverse square root at the turning point
      becomes smooth (``dist ~ u^2``) and the wall, of width ``~dist_pole``, is stretched to
      ``u = O(1)``; the rest of the half orbit takes ``u`` up to ``log(2 width / dist_pole)``.
    - Otherwise ``theta = mid -+ (mid - t_end) sin u`` on ``[0, pi/2]`` (``u = pi/2`` at ``mid``
      is mapped to the start so that ``u = 0`` is the turning point).
    """
    sign = 1.0 if left else -1.0  # direction from the turning point into the orbit
    if wall:
        p = t_end if left else math.pi - t_end
        pole = 0.0 if left else math.pi
        u_max = math.acosh(abs(mid - pole) / p)

        def wall_theta(u: FloatArray) -> FloatArray:
            value: FloatArray = pole + sign * p * np.cosh(u)
            return value

        def wall_jac(u: FloatArray) -> FloatArray:
            value: FloatArray = p * np.sinh(u)
            return value

        def wall_dist(u: FloatArray) -> FloatArray:
            value: FloatArray = 2 * p * np.sinh(u / 2) ** 2
            return value

        return HalfMap(u_max, wall_theta, wall_jac, wall_dist, p)
    L = abs(mid - t_end)

    def theta(u: FloatArray) -> FloatArray:
        value: FloatArray = mid - sign * L * np.cos(u)
        return value

    def jac(u: FloatArray) -> FloatArray:
        value: FloatArray = L * np.sin(u)
        return value

    def dist(u: FloatArray) -> FloatArray:
        value: FloatArray = 2 * L * np.sin(u / 2) ** 2
        return value

    return HalfMap(math.pi / 2, theta, jac, dist, L)


def _half_integrand(
    level: Level, h: float, t_end: float, half: HalfMap, left: bool, weight: Weight
) -> ArrayFn:
    """``2 sqrt(rho / (2 (h - U))) |dtheta/du| weight`` on one half orbit (see :func:`half_map`).

    ``h - U`` within :data:`_GAP_NEAR_WALL` of the local scale from the turning point is
    ``U(t_end) - U(theta)``, the integral of ``U'`` by a 20-point Gauss-Legendre rule over an
    interval on which ``U'`` is smooth; elsewhere the plain difference (no cancellation there).
    """
    _, theta_of, jac, dist_of, scale = half
    sign = 1.0 if left else -1.0

    def f(u: FloatArray) -> FloatArray:
        u = np.asarray(u, dtype=float)
        theta = theta_of(u)
        dist = dist_of(u)
        gap: FloatArray = h - level.U(theta)
        near = dist < _GAP_NEAR_WALL * scale
        if np.any(near):
            gap[near] = _gap_from_slope(level, t_end, -sign * dist[near] / 2)
        return time_density(level, theta, gap, jac(u), weight)

    return f


def _wall_period(
    level: Level,
    h: float,
    theta1: float,
    theta2: float,
    walls: tuple[bool, bool],
    peaks: Sequence[float],
    weight: Weight,
) -> tuple[float, float]:
    """:func:`period` split at the middle, each half by :func:`half_integral`.

    A wall next to the north pole is integrated on the mirror image (:meth:`LevelSet.mirrored`,
    ``theta -> pi - theta``), where its distance from the pole is ``theta`` itself, a float of
    its own: ``pi - theta2`` keeps only the absolute precision of ``theta2`` (1e-7 relative for
    a wall 3e-9 from the pole), and so would ``sin`` there. The turning point is found again on
    the mirror, to its full relative precision.
    """
    mid = (theta1 + theta2) / 2
    total, error = 0.0, 0.0
    for t_end, wall, left in ((theta1, walls[0], True), (theta2, walls[1], False)):
        mirror = _north_wall(level, h, t_end, mid) if wall and not left else None
        if mirror is not None:
            mirrored, x_end = mirror
            value, err = half_integral(
                mirrored, h, x_end, math.pi - mid, True, True, [math.pi - p for p in peaks], weight
            )
        else:
            value, err = half_integral(level, h, t_end, mid, wall, left, peaks, weight)
        total, error = total + value, error + err
    return total, error


def _north_wall(level: Level, h: float, t_end: float, mid: float) -> tuple[Level, float] | None:
    """The mirrored level and the turning point ``pi - t_end`` found on it to full relative
    precision (the root of ``U = h`` bracketed by halving and doubling the first guess); ``None``
    when no bracket is found (the half is then integrated as it stands)."""
    mirrored = level.mirrored()
    guess, limit = math.pi - t_end, math.pi - mid

    def gap(x: float) -> float:
        with np.errstate(all="ignore"):
            return float(h - mirrored.U(x))

    lo, hi = guess, guess
    for _ in range(64):
        if gap(lo) < 0.0:
            break
        lo /= 2
    for _ in range(64):
        if gap(hi) > 0.0 or hi >= limit:
            break
        hi = min(2 * hi, limit)
    if not (gap(lo) < 0.0 < gap(hi)):
        return None
    root = float(brentq(gap, lo, hi, xtol=1e-300, rtol=8.9e-16, maxiter=500))
    return mirrored, root


def half_integral(
    level: Level,
    h: float,
    t_end: float,
    mid: float,
    wall: bool,
    left: bool,
    peaks: Sequence[float] = (),
    weight: Weight = None,
) -> tuple[float, float]:
    """Twice the time (or the integral of ``weight dt``) from the turning point ``t_end`` to the
    interior point ``mid`` (in the variable of :func:`half_map`). Returns ``(value, error)``.

    A Gauss-Legendre rule doubled until two successive values agree to :data:`PERIOD_RTOL` (of
    the integral of ``|f|``), the error being their difference; without convergence by 2048
    nodes (a saddle near the half orbit) the composite rule graded towards the ends and the
    saddles ``peaks``.
    """
    half = half_map(t_end, mid, wall, left)
    f = _half_integrand(level, h, t_end, half, left, weight)
    u_max = half.u_max
    done = doubled_gauss(f, 0.0, u_max)
    if done is not None:
        return done
    breaks = [
        float(brentq(lambda u, p=p: half.theta(u) - p, 0.0, u_max))
        for p in peaks
        if min(t_end, mid) < p < max(t_end, mid)
    ]
    coarse = graded_gauss(f, 0.0, u_max, breaks, 20)
    fine = graded_gauss(f, 0.0, u_max, breaks, 30)
    return fine, abs(fine - coarse)
