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
number that would be noise. The quadrature itself is :mod:`._quadrature`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from rollingtop.reduction._orbit import (
    SEPARATRIX_TOLERANCE,
    STEADY_TOLERANCE,
    Orbit,
    Orbits,
    turning_point,
)
from rollingtop.reduction._quadrature import PERIOD_RTOL, WALL_RATIO, half_integral, period
from rollingtop.reduction.level import Level, LevelSetError, near_north
from rollingtop.reduction.no_spin import no_spin_orbits
from rollingtop.reduction.steady import SteadyMotion, critical_points, steady_motion

__all__ = ["Orbit", "Orbits", "orbits", "period", "half_integral", "canonical_orbit", "near_north"]
__all__ += ["PERIOD_RTOL", "WALL_RATIO", "SEPARATRIX_TOLERANCE", "STEADY_TOLERANCE"]


def _barrier_end(
    level: Level, h: float, end: float, inward: float, crit: Sequence[float], named: str
) -> float:
    """A point near a domain end where ``U > h`` (the potential's barrier), nearer the end than
    every critical point ``crit`` of ``U`` (a motion within 1e-7 of a pole has its centre
    between the end and a barrier point farther in). ``named``: the level as messages name it
    (the user's, where ``level`` is its mirror image)."""
    for eps in (1e-6, 1e-9, 1e-12, 1e-15, 1e-20, 1e-30, 1e-50, 1e-100, 1e-200, 1e-300):
        t = end + inward * eps * (1 + abs(end))
        if t == end:
            break
        if any((c - t) * inward <= 0.0 for c in crit):  # a critical point beyond t
            continue
        with np.errstate(all="ignore"):
            if level.U(t) > h:
                return t
    raise LevelSetError(
        f"the motion reaches within 1e-15 of theta = {end:g} on {named}, h = {h:g}: "
        "the wall of U beside that pole is thinner than double precision resolves there "
        f"({level.pole_advice})"
    )


def orbits(level: Level, h: float) -> Orbits:
    """All connected components of the level set ``(M3, C1, C2, h)``, sorted by ``gamma3_min``
    (a list that knows ``level`` and ``h``: :class:`Orbits`).

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
        return Orbits(no_spin_orbits(level, h), level, h)
    if near_north(level):
        mirrored = [_mirror(o) for o in _orbits(level.mirrored(), h, level.describe())]
        return Orbits(sorted(mirrored, key=lambda o: (o.gamma3_min, o.theta_min)), level, h)
    return Orbits(_orbits(level, h), level, h)


def _mirror(o: Orbit) -> Orbit:
    """An orbit of the mirrored level seen on the original one (``theta -> pi - theta``)."""
    return replace(
        o,
        gamma3_min=-o.gamma3_max,
        gamma3_max=-o.gamma3_min,
        theta_min=math.pi - o.theta_max,
        theta_max=math.pi - o.theta_min,
    )


def canonical_orbit(level: Level, h: float, orbit: Orbit) -> tuple[Level, Orbit]:
    """The level and orbit on which quadratures of ``orbit`` are most accurate: the mirror image
    for a level near the north pole (:func:`near_north`), where the turning point next to the
    pole is known to its full relative precision; else ``(level, orbit)``."""
    if not near_north(level):
        return level, orbit
    mirrored = level.mirrored()
    candidates = _orbits(mirrored, h, level.describe())
    best = min(
        candidates,
        key=lambda c: (
            abs(math.pi - c.theta_max - orbit.theta_min)
            + abs(math.pi - c.theta_min - orbit.theta_max)
        ),
    )
    return mirrored, best


def _orbits(level: Level, h: float, named: str | None = None) -> list[Orbit]:
    """The orbits of ``level`` at ``h``; ``named``: the level as messages name it (default
    ``level.describe()``; the user's level where ``level`` is its mirror image)."""
    found = _components(level, h, level.describe() if named is None else named)
    if level.pole is None:
        found = [replace(o, pole_distance=min(o.theta_min, math.pi - o.theta_max)) for o in found]
    return found


def _components(level: Level, h: float, named: str) -> list[Orbit]:
    lo_end, hi_end = level.theta_domain
    inside = [t for t in critical_points(level) if lo_end < t < hi_end]
    lo = _barrier_end(level, h, lo_end, +1, inside, named)
    hi = _barrier_end(level, h, hi_end, -1, inside, named)
    crit = [t for t in inside if lo < t < hi]
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
                start = turning_point(level, h, a, b)
        if start is not None and ub > h >= ua:
            end = turning_point(level, h, a, b) if ua < h else a
            result.append(_make_orbit(level, h, start, end, crit, steadies, scale))
            start = None
    if not result and crit:  # h within round-off below a centre's U: that steady motion
        umin, c = min(zip(values[1:-1], crit, strict=True))
        if steadies[c].type == "center" and umin - h <= STEADY_TOLERANCE * scale:
            result.append(_make_orbit(level, h, c, c, crit, steadies, scale))
    if not result:
        umin = min(values[1:-1]) if crit else math.nan
        raise LevelSetError(
            f"no motion on {named} at h = {h:.12g}: h is below the minimum of the "
            f"effective potential U = {umin:.12g}"
        )
    pole = level.pole_theta
    physical = [o for o in result if o.theta_max > 0.0 or pole is None]
    if level.pole == "north":
        physical = [o for o in result if o.theta_min < math.pi]
    return sorted(physical or result, key=lambda o: (o.gamma3_min, o.theta_min))


def _make_orbit(
    level: Level,
    h: float,
    t1: float,
    t2: float,
    crit: Sequence[float],
    steadies: dict[float, SteadyMotion],
    scale: float,
) -> Orbit:
    """The orbit between the turning points ``t1 <= t2`` (steady, separatrix or periodic), given
    the critical points ``crit`` of ``U``, their steady motions and the scale of ``U``."""
    pole = level.pole_theta
    passage = pole is not None and t1 < pole < t2
    g = np.cos(np.linspace(t1, t2, 2001))
    g_min, g_max = float(np.min(np.cos([t1, t2]))), float(np.max(np.cos([t1, t2])))
    if passage:
        g_min, g_max = min(g_min, float(g.min())), max(g_max, float(g.max()))
        g_max = 1.0 if level.pole == "south" else g_max
        g_min = -1.0 if level.pole == "north" else g_min
    thetas = np.linspace(t1, t2, 2001)
    w_tau_max = float(np.max(level.w_tau(thetas, h)))
    note = "passes through the pole" if passage else ""
    # steady motion: a centre with h at (or within round-off of) its potential
    if t2 - t1 < 1e-7 * max(abs(t1), abs(t2)) or any(
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
