"""The no-spin level ``M3 = C1 = 0``: both poles are pole levels at once.

With no spin about the axis (``w3 = 0``) and no vertical angular momentum (``C1 = 0``) the
reduced motion is planar: ``w_n = 0``, ``v_tau = C2 / I1`` is constant and the effective
potential is ``U(theta) = m C2^2 / (2 I1^2) + m g a3 cos(theta)``, smooth on the whole circle of
the signed nutation angle (:class:`~rollingtop.reduction.level.LevelSet` with
``pole == "both"``). Its critical points are the two poles: for ``a3 g > 0`` the body resting
with its centre of mass lowest (``gamma3 = -1``, ``theta = pi``) is a centre and the upright
body (``gamma3 = +1``) a saddle; for ``a3 g < 0`` the other way round. The motions are

- *rocking* about the centre (``h`` below the saddle's ``U``), passing through the lower pole
  twice per period, between the turning points ``cos(theta) = (h - m C2^2/(2 I1^2)) / (m g a3)``;
- *rolling over* (``h`` above it), ``theta`` advancing by ``2 pi`` per period through both poles;
  the period is the integral of ``sqrt(rho / (2 (h - U)))`` over the circle, a periodic analytic
  integrand, so the trapezoidal rule converges exponentially (doubled until two values agree);
- the separatrix between them, and the body at rest at the centre.

The axis does not precess (``psi' = -w_n / s = 0``), so the per-period map is a translation:
every such motion drifts sideways at ``v_tau = C2 / I1`` (plus the rolling).
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop.reduction._orbit import (
    SEPARATRIX_TOLERANCE,
    STEADY_TOLERANCE,
    Orbit,
    turning_point,
)
from rollingtop.reduction._quadrature import (
    PERIOD_RTOL,
    FloatArray,
    Weight,
    graded_gauss,
    period,
    time_density,
)
from rollingtop.reduction.level import Level, LevelSetError
from rollingtop.reduction.steady import steady_motion

__all__ = ["no_spin_orbits", "rolling_over_period"]


def _poles(level: Level) -> tuple[float, float] | None:
    """``(theta of the centre, theta of the saddle)``, or ``None`` when ``U`` is constant."""
    b = level.body
    k = b.m * b.g * b.a3
    if k == 0.0:
        return None
    return (math.pi, 0.0) if k > 0 else (0.0, math.pi)


def rolling_over_period(level: Level, h: float, weight: Weight = None) -> tuple[float, float]:
    """Period of a rolling-over motion: ``integral over theta in [t_s, t_s + 2 pi]`` of
    ``sqrt(rho / (2 (h - U)))`` (``t_s`` the saddle, where the integrand peaks). Returns
    ``(value, estimated absolute error)``."""
    poles = _poles(level)
    start = poles[1] if poles else 0.0

    def f(theta: FloatArray) -> FloatArray:  # dt/dtheta (times the weight): jac 1/2 undoes the 2
        return time_density(level, theta, h - level.U(theta), 0.5, weight)

    prev = None
    for n in (2**k for k in range(4, 17)):
        theta = start + 2 * math.pi * np.arange(n) / n
        cur = float(np.sum(f(theta))) * 2 * math.pi / n
        if prev is not None and abs(cur - prev) <= PERIOD_RTOL * abs(cur):
            return cur, abs(cur - prev)
        prev = cur
    # slow: a logarithmic peak at the saddle (just above the separatrix)
    coarse = graded_gauss(f, start, start + 2 * math.pi, [], 20)
    fine = graded_gauss(f, start, start + 2 * math.pi, [], 30)
    return fine, abs(fine - coarse)


def no_spin_orbits(level: Level, h: float) -> list[Orbit]:
    """The orbits on the no-spin level at reduced energy ``h`` (module docstring): one rocking,
    rolling-over, separatrix or steady motion.

    Raises
    ------
    LevelSetError
        ``h`` below the minimum of ``U``.
    """
    if level.pole != "both":
        raise LevelSetError(f"not a no-spin level: {level.describe()}")
    poles = _poles(level)
    if poles is None:  # U constant: uniform rolling over (or rest)
        U0 = float(level.U(0.0))
        if h < U0:
            raise LevelSetError(
                f"no motion on {level.describe()} at h = {h:.12g}: below U = {U0:.12g}"
            )
        if h - U0 <= STEADY_TOLERANCE * max(abs(h), 1e-300):
            return [
                Orbit(
                    1.0,
                    1.0,
                    0.0,
                    0.0,
                    math.nan,
                    0.0,
                    "steady",
                    True,
                    0.0,
                    "at rest: U is constant on this level (a3 g = 0), every gamma3 is a "
                    "neutral equilibrium",
                )
            ]
        T, err = rolling_over_period(level, h)
        w_max = float(np.max(level.w_tau(np.array([0.0, math.pi]), h)))  # at the lighter pole
        return [
            Orbit(
                -1.0,
                1.0,
                -math.pi,
                math.pi,
                T,
                err,
                "periodic",
                True,
                w_max,
                "rolls over: passes through both poles each period",
            )
        ]
    centre, saddle = poles
    Uc, Us = float(level.U(centre)), float(level.U(saddle))
    scale = max(abs(h), abs(Uc), abs(Us), 1e-300)
    if h < Uc - STEADY_TOLERANCE * scale:
        raise LevelSetError(
            f"no motion on {level.describe()} at h = {h:.12g}: h is below the minimum of the "
            f"effective potential U = {Uc:.12g}"
        )
    g_c = math.cos(centre)
    if h - Uc <= STEADY_TOLERANCE * scale:
        m = steady_motion(level, centre)
        return [
            Orbit(
                g_c,
                g_c,
                centre,
                centre,
                m.period,
                0.0,
                "steady",
                False,
                0.0,
                "at rest at the pole (h at the minimum of U); period of small oscillations",
            )
        ]
    w_max = float(level.w_tau(centre, h))
    if abs(h - Us) <= SEPARATRIX_TOLERANCE * scale:
        return [
            Orbit(
                -1.0,
                1.0,
                saddle - math.pi,
                saddle + math.pi,
                math.inf,
                math.inf,
                "separatrix",
                True,
                w_max,
                f"on the separatrix through the upright pole (|h - U(saddle)| = "
                f"{abs(h - Us):.2g}): the period grows without bound",
            )
        ]
    if h > Us:
        T, err = rolling_over_period(level, h)
        return [
            Orbit(
                -1.0,
                1.0,
                saddle - math.pi,
                saddle + math.pi,
                T,
                err,
                "periodic",
                True,
                w_max,
                "rolls over: passes through both poles each period",
            )
        ]
    # rocking about the centre, between turning points symmetric about it
    t1 = turning_point(level, h, centre - math.pi + 1e-300, centre)
    t2 = 2 * centre - t1
    T, err = period(level, h, t1, t2)
    g_turn = math.cos(t1)
    g_min, g_max = (min(g_c, g_turn), max(g_c, g_turn))
    return [
        Orbit(
            g_min,
            g_max,
            t1,
            t2,
            T,
            err,
            "periodic",
            True,
            w_max,
            f"planar rocking through the pole gamma3 = {g_c:+.0f} (no spin)",
        )
    ]
