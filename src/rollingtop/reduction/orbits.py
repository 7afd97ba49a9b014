"""Orbits on a level set ``(M3, C1, C2, h)``: turning points and periods (paper eqs. 3.10-3.11).

With ``theta' = -w_tau`` and ``h = rho theta'^2/2 + U(theta)`` (see :mod:`.level`), each connected
component of ``{U(theta) <= h}`` between two simple turning points is a periodic orbit of period

    T = 2 * integral_{theta1}^{theta2} sqrt(rho(theta) / (2 (h - U(theta)))) dtheta.

The inverse-square-root singularities at the turning points are removed by the substitution
``theta = c + d sin(phi)``, ``phi in [-pi/2, pi/2]``, which makes the integrand smooth (analytic):
Gauss-Legendre quadrature then converges exponentially and is doubled until two successive
values agree to :data:`PERIOD_RTOL`. Near a separatrix (a saddle of ``U`` at a level within a
tiny margin of ``h``, inside or at the edge of the orbit) the integrand develops a logarithmic
peak: the quadrature switches to a composite rule graded geometrically towards the peak and the
turning points (written here because it must be vectorised over the nodes), and within
:data:`SEPARATRIX_TOLERANCE` of the separatrix the period is reported as unbounded instead of a
number that would be noise.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass, replace

import numpy as np
from scipy.optimize import brentq

from rollingtop._json import json_ready
from rollingtop.reduction.level import LevelSet, LevelSetError
from rollingtop.reduction.steady import critical_points, steady_motion

__all__ = ["Orbit", "orbits", "period"]

#: ``|h - U(saddle)|`` below this (relative to the scale of ``U``) is on the separatrix.
SEPARATRIX_TOLERANCE = 1e-10
#: Target relative accuracy of the period quadrature (two successive rules agree to this).
PERIOD_RTOL = 1e-12
#: ``h - U_min`` below this (relative) is the steady motion itself.
STEADY_TOLERANCE = 1e-13


@dataclass(frozen=True)
class Orbit:
    """One connected component of the level set ``(M3, C1, C2, h)``.

    Attributes
    ----------
    gamma3_min, gamma3_max : float
        Range of ``gamma3`` on the orbit (a pole passage reaches ``+-1``).
    theta_min, theta_max : float
        Turning points in the signed nutation angle (``gamma3 = cos theta``).
    period : float
        Period of ``gamma3(t)`` (``inf`` on a separatrix).
    period_error : float
        Estimated absolute error of ``period``.
    kind : {"periodic", "steady", "separatrix"}
    pole_passage : bool
        The orbit passes through the pole (pole cases only).
    w_tau_max : float
        Largest ``|w_tau|`` on the orbit.
    note : str
        Plain-language remark (near separatrix, pole passage, ...), or empty.
    pole_distance : float
        Distance in ``theta`` of the orbit's nearer end from its pole, to full relative
        precision (``theta_max = pi - pole_distance`` near the north pole rounds it): the width
        of the gap next to the pole on a level near a pole level; NaN in a pole case.
    """

    gamma3_min: float
    gamma3_max: float
    theta_min: float
    theta_max: float
    period: float
    period_error: float
    kind: str
    pole_passage: bool
    w_tau_max: float
    note: str = ""
    pole_distance: float = math.nan

    def to_dict(self) -> dict:
        """JSON-ready dict (non-finite values become ``None``)."""
        return json_ready(asdict(self))

    @property
    def rolls_over(self) -> bool:
        """``theta`` runs round the whole circle (no spin, above the upright pole's energy):
        the orbit has no turning points and ``theta_min``, ``theta_max`` are a full turn apart."""
        return self.theta_max - self.theta_min >= 2 * math.pi * (1 - 1e-12)


@functools.lru_cache(maxsize=16)
def _leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1], kept (numpy computes them by an ``n x n``
    eigenvalue problem: 0.2 s for ``n = 4096``)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = w.flags.writeable = False
    return x, w


#: Gauss-Legendre rule for the energy gap near the turning points (see :func:`_gap`).
_GAP_NODES, _GAP_WEIGHTS = _leggauss(20)
#: Within this fraction of the orbit's width from a turning point the gap is integrated.
_GAP_NEAR = 0.1


def _gap(level: LevelSet, h: float, t1: float, t2: float, phi) -> np.ndarray:
    """``h - U(theta)`` at ``theta = c + d sin(phi)`` on ``[t1, t2]``, accurate to a few ulps
    *relative* to itself.

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
    out = h - level.U(theta)
    for end, dist in (
        (t2, 2 * d * np.sin(np.pi / 4 - phi / 2) ** 2),
        (t1, -2 * d * np.sin(np.pi / 4 + phi / 2) ** 2),
    ):
        near = np.abs(dist) < _GAP_NEAR * (t2 - t1)
        if np.any(near):
            out[near] = _gap_from_slope(level, end, dist[near] / 2)
    return out.reshape(shape)


def _gap_from_slope(level: LevelSet, end: float, half: np.ndarray) -> np.ndarray:
    """``U(end) - U(theta) = integral_theta^end U'`` by a 20-point Gauss-Legendre rule, with
    ``half = (end - theta) / 2`` (signed) given without cancellation: the energy gap next to
    the turning point ``end`` to its full relative accuracy."""
    x = end - half[:, None] * (1 + _GAP_NODES[None, :])
    return np.sum(_GAP_WEIGHTS * level.dU(x), axis=1) * half


def _time_density(level: LevelSet, theta, gap, jac, weight):
    """``2 sqrt(rho / (2 gap)) |dtheta/du| weight(theta)``: twice ``dt/du`` (times the weight)
    in an integration variable ``u`` with Jacobian ``jac``; 0 where it is not finite (at a
    turning point the substitutions make the limit finite, the rule never samples it)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        val = 2.0 * np.sqrt(level.rho(theta) / (2.0 * np.maximum(gap, 0.0))) * jac
        if weight is not None:
            val = val * weight(theta)
    return np.where(np.isfinite(val), val, 0.0)


def _integrand(level: LevelSet, h: float, t1: float, t2: float, weight=None):
    """``2 weight(theta) dt/dtheta`` in the variable ``phi`` (``theta = c + d sin phi``)."""
    c, d = (t1 + t2) / 2, (t2 - t1) / 2

    def f(phi):
        theta = c + d * np.sin(phi)
        return _time_density(level, theta, _gap(level, h, t1, t2, phi), d * np.cos(phi), weight)

    return f


def _doubled_gauss(f, a: float, b: float) -> tuple[float, float] | None:
    """Gauss-Legendre rules of 32, 64, ..., 2048 nodes on ``[a, b]`` until two successive
    values agree to :data:`PERIOD_RTOL` of the integral of ``|f|`` (the weighted integrals may
    vanish); returns ``(value, their difference)``, or ``None`` without convergence."""
    prev = None
    for n in (32, 64, 128, 256, 512, 1024, 2048):
        x, w = _leggauss(n)
        values = f(a + (b - a) * (x + 1) / 2) * w * ((b - a) / 2)
        cur, size = float(np.sum(values)), float(np.sum(np.abs(values)))
        if prev is not None and abs(cur - prev) <= PERIOD_RTOL * size:
            return cur, abs(cur - prev)
        prev = cur
    return None


def _graded_gauss(f, a: float, b: float, points, n: int) -> float:
    """Composite Gauss-Legendre on ``[a, b]``, graded geometrically (ratio 0.2, 24 levels)
    towards ``a``, ``b`` and each of ``points``: resolves peaks of width down to ~1e-17 there."""
    x, w = _leggauss(n)
    knots = np.unique(np.clip([a, *points, b], a, b))
    edges = []
    ratios = 0.2 ** np.arange(24, -1, -1)
    for u, v in zip(knots[:-1], knots[1:], strict=True):
        m = (u + v) / 2
        edges.append(np.concatenate([[u], u + (m - u) * ratios]))
        edges.append(np.concatenate([[v], v - (v - m) * ratios])[::-1])
    total = 0.0
    for e in edges:
        lo, hi = e[:-1], e[1:]
        half = (hi - lo) / 2
        nodes = (lo + hi)[:, None] / 2 + half[:, None] * x[None, :]
        total += float(np.sum(f(nodes.ravel()).reshape(nodes.shape) * w * half[:, None]))
    return total


#: An orbit's end closer to its pole than this fraction of the orbit's width sits next to a thin
#: wall of ``U`` (a level near a pole level): that half of the orbit is integrated in the
#: variable ``x`` of ``dist = dist_end cosh x`` (see :func:`_wall_period`).
WALL_RATIO = 0.25
#: Within this fraction of the local length scale from a turning point, ``h - U`` is integrated
#: from ``U'`` instead of subtracted (see :func:`_half_integrand`).
_GAP_NEAR_WALL = 0.1


def period(
    level: LevelSet, h: float, theta1: float, theta2: float, peaks=(), weight=None
) -> tuple[float, float]:
    """Period of the orbit between the simple turning points ``theta1 < theta2``.

    ``peaks`` are theta values of saddles near the orbit (break points for the graded
    fallback). With ``weight`` (a function of theta) the integral over one period of
    ``weight(theta(t)) dt`` instead. Returns ``(value, estimated absolute error)``.

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
    done = _doubled_gauss(f, -math.pi / 2, math.pi / 2)
    if done is not None:
        return done
    # Slow convergence: a logarithmic peak near a saddle, inside the orbit or at a turning point
    # that is nearly a double root. Composite rule graded towards the peaks and the ends.
    breaks = [math.asin(min(1.0, max(-1.0, (p - c) / d))) for p in peaks if theta1 < p < theta2]
    coarse = _graded_gauss(f, -math.pi / 2, math.pi / 2, breaks, 20)
    fine = _graded_gauss(f, -math.pi / 2, math.pi / 2, breaks, 30)
    return fine, abs(fine - coarse)


def _walls(level: LevelSet, theta1: float, theta2: float) -> tuple[bool, bool]:
    """Whether each end of the orbit ``[theta1, theta2]`` sits at a thin wall next to a pole."""
    if level.pole is not None or not 0.0 < theta1 < theta2 < math.pi:
        return (False, False)
    width = theta2 - theta1
    return (theta1 < WALL_RATIO * width, math.pi - theta2 < WALL_RATIO * width)


def _half_map(t_end: float, mid: float, wall: bool, left: bool):
    """The substitution for the half orbit between the turning point ``t_end`` and ``mid``.

    Returns ``(u_max, theta(u), |dtheta/du|(u), dist(u), scale)`` with ``u in [0, u_max]``,
    ``u = 0`` at the turning point, ``dist = |theta - t_end|`` without cancellation and
    ``scale`` the length on which ``U`` varies near the turning point.

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

        def theta(u):
            return pole + sign * p * np.cosh(u)

        def jac(u):
            return p * np.sinh(u)

        def dist(u):
            return 2 * p * np.sinh(u / 2) ** 2

        return u_max, theta, jac, dist, p
    L = abs(mid - t_end)

    def theta(u):
        return mid - sign * L * np.cos(u)

    def jac(u):
        return L * np.sin(u)

    def dist(u):
        return 2 * L * np.sin(u / 2) ** 2

    return math.pi / 2, theta, jac, dist, L


def _half_integrand(level: LevelSet, h: float, t_end: float, half, left: bool, weight):
    """``2 sqrt(rho / (2 (h - U))) |dtheta/du| weight`` on one half orbit (see :func:`_half_map`).

    ``h - U`` within :data:`_GAP_NEAR_WALL` of the local scale from the turning point is
    ``U(t_end) - U(theta)``, the integral of ``U'`` by a 20-point Gauss-Legendre rule over an
    interval on which ``U'`` is smooth; elsewhere the plain difference (no cancellation there).
    """
    _, theta_of, jac, dist_of, scale = half
    sign = 1.0 if left else -1.0

    def f(u):
        u = np.asarray(u, dtype=float)
        theta = theta_of(u)
        dist = dist_of(u)
        gap = h - level.U(theta)
        near = dist < _GAP_NEAR_WALL * scale
        if np.any(near):
            gap[near] = _gap_from_slope(level, t_end, -sign * dist[near] / 2)
        return _time_density(level, theta, gap, jac(u), weight)

    return f


def _wall_period(level, h, theta1, theta2, walls, peaks, weight) -> tuple[float, float]:
    """:func:`period` split at the middle, each half by :func:`half_integral`."""
    mid = (theta1 + theta2) / 2
    total, error = 0.0, 0.0
    for t_end, wall, left in ((theta1, walls[0], True), (theta2, walls[1], False)):
        value, err = half_integral(level, h, t_end, mid, wall, left, peaks, weight)
        total, error = total + value, error + err
    return total, error


def half_integral(
    level: LevelSet, h, t_end, mid, wall: bool, left: bool, peaks=(), weight=None
) -> tuple[float, float]:
    """Twice the time (or the integral of ``weight dt``) from the turning point ``t_end`` to the
    interior point ``mid`` (in the variable of :func:`_half_map`). Returns ``(value, error)``.

    A Gauss-Legendre rule doubled until two successive values agree to :data:`PERIOD_RTOL` (of
    the integral of ``|f|``), the error being their difference; without convergence by 2048
    nodes (a saddle near the half orbit) the composite rule graded towards the ends and the
    saddles ``peaks``.
    """
    half = _half_map(t_end, mid, wall, left)
    f = _half_integrand(level, h, t_end, half, left, weight)
    u_max = half[0]
    done = _doubled_gauss(f, 0.0, u_max)
    if done is not None:
        return done
    breaks = [
        float(brentq(lambda u, p=p: half[1](u) - p, 0.0, u_max))
        for p in peaks
        if min(t_end, mid) < p < max(t_end, mid)
    ]
    coarse = _graded_gauss(f, 0.0, u_max, breaks, 20)
    fine = _graded_gauss(f, 0.0, u_max, breaks, 30)
    return fine, abs(fine - coarse)


def _root(level: LevelSet, h: float, a: float, b: float) -> float:
    # xtol tiny: the root is found to a relative 4 ulps also next to a pole (theta ~ 1e-12)
    return brentq(lambda t: h - level.U(t), a, b, xtol=1e-300, rtol=8.9e-16, maxiter=500)


def _barrier_end(level: LevelSet, h: float, end: float, inward: float) -> float:
    """A point near a domain end where ``U > h`` (the potential's barrier)."""
    for eps in (1e-6, 1e-9, 1e-12, 1e-15, 1e-20, 1e-30, 1e-50, 1e-100, 1e-200, 1e-300):
        t = end + inward * eps * (1 + abs(end))
        if t == end:
            break
        with np.errstate(all="ignore"):
            if level.U(t) > h:
                return t
    raise LevelSetError(
        f"the motion reaches within 1e-15 of theta = {end:g} on {level.describe()}, h = {h:g}: "
        "the wall of U beside that pole is thinner than double precision resolves there "
        "(for the pole case set C1 = +-M3 exactly; or rescale M3, C1)"
    )


def orbits(level: LevelSet, h: float) -> list[Orbit]:
    """All connected components of the level set ``(M3, C1, C2, h)``, sorted by ``gamma3_min``.

    A level nearer the north pole level than the south one is computed on its mirror image
    (:meth:`LevelSet.mirrored`), where the distance of the wall from the pole is ``theta``
    itself and keeps its relative precision; the turning points are mapped back.

    Raises
    ------
    LevelSetError
        When ``h`` is below the minimum of ``U``: no motion on this level.
    """
    if not isinstance(h, int | float) or isinstance(h, bool) or not math.isfinite(h):
        raise LevelSetError(f"level h = {h!r} must be a finite number")
    h = float(h)
    if level.pole == "both":
        from rollingtop.reduction.no_spin import no_spin_orbits

        return no_spin_orbits(level, h)
    if near_north(level):
        mirrored = [_mirror(o) for o in _orbits(level.mirrored(), h)]
        return sorted(mirrored, key=lambda o: (o.gamma3_min, o.theta_min))
    return _orbits(level, h)


def near_north(level: LevelSet) -> bool:
    """A level that is no pole case and lies nearer ``C1 = -M3`` than ``C1 = M3``: computed on
    its mirror image (:meth:`LevelSet.mirrored`)."""
    return level.pole is None and abs(level.M3 + level.C1) < abs(level.M3 - level.C1)


def _mirror(o: Orbit) -> Orbit:
    """An orbit of the mirrored level seen on the original one (``theta -> pi - theta``)."""
    return replace(
        o,
        gamma3_min=-o.gamma3_max,
        gamma3_max=-o.gamma3_min,
        theta_min=math.pi - o.theta_max,
        theta_max=math.pi - o.theta_min,
    )


def canonical_orbit(level: LevelSet, h: float, orbit: Orbit) -> tuple[LevelSet, Orbit]:
    """The level and orbit on which quadratures of ``orbit`` are most accurate: the mirror image
    for a level near the north pole (:func:`near_north`), where the turning point next to the
    pole is known to its full relative precision; else ``(level, orbit)``."""
    if not near_north(level):
        return level, orbit
    mirrored = level.mirrored()
    candidates = _orbits(mirrored, h)
    best = min(
        candidates,
        key=lambda c: (
            abs(math.pi - c.theta_max - orbit.theta_min)
            + abs(math.pi - c.theta_min - orbit.theta_max)
        ),
    )
    return mirrored, best


def _orbits(level: LevelSet, h: float) -> list[Orbit]:
    found = _components(level, h)
    if level.pole is None:
        found = [replace(o, pole_distance=min(o.theta_min, math.pi - o.theta_max)) for o in found]
    return found


def _components(level: LevelSet, h: float) -> list[Orbit]:
    lo_end, hi_end = level.theta_domain
    lo = _barrier_end(level, h, lo_end, +1)
    hi = _barrier_end(level, h, hi_end, -1)
    crit = [t for t in critical_points(level) if lo < t < hi]
    knots = [lo, *crit, hi]
    values = [float(level.U(t)) for t in knots]
    scale = max(abs(h), max(abs(v) for v in values[1:-1]) if crit else abs(h), 1e-300)
    steadies = {t: steady_motion(level, t) for t in crit}
    # Walk the monotonic segments between knots; collect intervals where U <= h.
    result: list[Orbit] = []
    start = None
    for i in range(len(knots) - 1):
        a, b, ua, ub = knots[i], knots[i + 1], values[i], values[i + 1]
        if start is None:
            if ua <= h and i > 0:  # a critical point at or below h begins a component
                start = a
            elif ua > h >= ub:
                start = _root(level, h, a, b)
        if start is not None and ub > h >= ua:
            end = _root(level, h, a, b) if ua < h else a
            result.append(_make_orbit(level, h, start, end, crit, steadies, scale))
            start = None
    if not result:
        umin = min(values[1:-1]) if crit else math.nan
        raise LevelSetError(
            f"no motion on {level.describe()} at h = {h:.12g}: h is below the minimum of the "
            f"effective potential U = {umin:.12g}"
        )
    pole = level.pole_theta
    physical = [o for o in result if o.theta_max > 0.0 or pole is None]
    if level.pole == "north":
        physical = [o for o in result if o.theta_min < math.pi]
    return sorted(physical or result, key=lambda o: (o.gamma3_min, o.theta_min))


def _make_orbit(level, h, t1, t2, crit, steadies, scale) -> Orbit:
    pole = level.pole_theta
    passage = pole is not None and t1 < pole < t2
    g = np.cos(np.linspace(t1, t2, 2001))
    g_min, g_max = float(np.min(np.cos([t1, t2]))), float(np.max(np.cos([t1, t2])))
    if passage:
        g_min, g_max = min(g_min, float(g.min())), max(g_max, float(g.max()))
        g_max = 1.0 if level.pole == "south" else g_max
        g_min = -1.0 if level.pole == "north" else g_min
    thetas = np.linspace(t1, t2, 2001)
    w_tau_max = float(np.sqrt(np.max(np.maximum(2 * (h - level.U(thetas)) / level.rho(thetas), 0))))
    note = "passes through the pole" if passage else ""
    # steady motion: a centre with h at (or within round-off of) its potential
    if t2 - t1 < 1e-7 or any(
        steadies[c].type == "center"
        and t1 <= c <= t2
        and h - steadies[c].U <= STEADY_TOLERANCE * scale
        for c in crit
    ):
        c = min(crit, key=lambda x: abs(x - (t1 + t2) / 2)) if crit else (t1 + t2) / 2
        m = steadies.get(c)
        T = m.period if m is not None else math.nan
        c = float(c)
        return Orbit(
            math.cos(c),
            math.cos(c),
            c,
            c,
            T,
            0.0,
            "steady",
            False,
            0.0,
            "steady motion (h at the minimum of U); period of small oscillations",
        )
    # saddles that bound or split this orbit: inside it, or just outside a turning point
    margin = 0.05 * (t2 - t1) + 1e-3
    near = [
        c
        for c in crit
        if steadies[c].type != "center"
        and t1 - margin <= c <= t2 + margin
        and abs(h - steadies[c].U) <= 1e-6 * scale
    ]
    gap = min((abs(h - steadies[c].U) for c in near), default=math.inf)
    if gap <= SEPARATRIX_TOLERANCE * scale:
        return Orbit(
            g_min,
            g_max,
            t1,
            t2,
            math.inf,
            math.inf,
            "separatrix",
            passage,
            w_tau_max,
            f"on the separatrix (|h - U(saddle)| = {gap:.2g}): the period grows without bound",
        )
    T, err = period(level, h, t1, t2, peaks=[c for c in crit if t1 < c < t2])
    if near:
        # T ~ (2 / lambda) log(1/gap): the round-off of h and U (~eps * scale) moves T by
        # (2 / lambda) * eps * scale / gap -- the period is ill-conditioned near a separatrix.
        rates = [steadies[c].growth_rate for c in near if steadies[c].type == "saddle"]
        lam = max(rates) if rates else 1.0
        err = max(err, 2.0 / lam * 4 * np.finfo(float).eps * scale / gap)
        note = (note + "; " if note else "") + (
            f"near a separatrix (|h - U(saddle)| = {gap:.2g}): period ~ log(1/gap), "
            f"relative uncertainty {err / T:.1g} from the round-off of h"
        )
    return Orbit(g_min, g_max, t1, t2, T, err, "periodic", passage, w_tau_max, note)
