"""The no-spin level M3 = C1 = 0: both poles at once. Equilibria (which pole is a centre),
rocking and rolling-over periods against mpmath, the per-period map (a sideways drift)."""

import math

import mpmath as mp
import pytest

from rollingtop import SphericalTop
from rollingtop.absolute import period_map
from rollingtop.reduction import LevelSet, orbits, steady_motions

#: Relative accuracy of the periods against mpmath.
PERIOD_RTOL = 1e-11
#: gamma3 = cos(theta) at a pole (theta = 0 or pi): within a few ulps of +-1.
POLE_ATOL = 1e-15


@mp.workdps(30)  # a local context: the global precision is left alone
def plain_period(b: SphericalTop, C2: float, h: float, a: float, c: float, factor: int) -> float:
    """factor * int_a^c sqrt(rho / (2 (h - U))) dtheta with U = m C2^2/(2 I1^2) + m g a3 cos,
    by mpmath (tanh-sinh copes with the inverse square roots at turning points). ``a``, when a
    turning point, is refined to 30 digits first: the float one is off by round-off, which moves
    the integral by ~sqrt(round-off)."""

    def U(t):
        return b.m * mp.mpf(C2) ** 2 / (2 * b.I1**2) + b.m * b.g * b.a3 * mp.cos(t)

    def f(t):
        rho = b.I1 + b.m * (b.a3**2 + b.R**2 + 2 * b.a3 * b.R * mp.cos(t))
        return mp.re(mp.sqrt(rho / (2 * (h - U(t)))))

    if abs(U(a) - h) < 1e-9:
        a = mp.findroot(lambda t: U(t) - h, mp.mpf(a))

    return float(factor * mp.quad(f, [a, (a + c) / 2, c]))


@pytest.mark.parametrize("a3", [0.1, -0.1])
def test_equilibria_both_poles(a3):
    b = SphericalTop(R=1.0, m=1.0, g=1.0, a3=a3, I1=0.3, I3=0.5)
    level = LevelSet(b, 0.0, 0.0, 0.0)
    assert level.pole == "both"
    motions = steady_motions(level)
    assert [m.gamma3 for m in motions] == pytest.approx([-1.0, 1.0], abs=POLE_ATOL)
    low, high = motions
    # the centre of mass lowest is the centre: gamma3 = -1 for a3 > 0 (z = R + a3 gamma3)
    assert (low.type, high.type) == (("center", "saddle") if a3 > 0 else ("saddle", "center"))
    centre = low if a3 > 0 else high
    # small oscillations: omega^2 = U''/rho = m g |a3| / rho(pole)
    rho = b.I1 + b.m * (b.a3**2 + b.R**2 + 2 * b.a3 * b.R * centre.gamma3)
    assert centre.frequency == pytest.approx(math.sqrt(b.m * b.g * abs(a3) / rho), rel=1e-12)


def test_rocking_through_the_low_pole(paper_body):
    C2, h = 0.2, -0.02 + paper_body.m * 0.2**2 / (2 * paper_body.I1**2)
    level = LevelSet(paper_body, 0.0, 0.0, C2)
    (orbit,) = orbits(level, h)
    assert orbit.kind == "periodic" and orbit.pole_passage
    assert orbit.gamma3_min == pytest.approx(-1.0, abs=POLE_ATOL)
    # turning points: m g a3 cos(theta) = h - m C2^2/(2 I1^2)
    k = -0.02 / (paper_body.m * paper_body.g * paper_body.a3)
    assert orbit.gamma3_max == pytest.approx(k, rel=1e-13)
    assert orbit.theta_min + orbit.theta_max == pytest.approx(2 * math.pi, rel=1e-15)
    T = plain_period(paper_body, C2, h, orbit.theta_min, math.pi, 4)
    assert orbit.period == pytest.approx(T, rel=PERIOD_RTOL)
    pm = period_map(level, h, orbit)
    assert pm.delta_psi == 0.0 and pm.motion == "drifting"  # set, not computed, on this level
    # the axis does not precess; the CoM drifts at v_tau = C2 / I1 (the rocking averages out)
    assert math.hypot(*pm.drift_velocity) == pytest.approx(C2 / paper_body.I1, rel=1e-9)


def test_rolling_over_through_both_poles(paper_body):
    C2 = 0.3
    U_top = paper_body.m * C2**2 / (2 * paper_body.I1**2) + paper_body.m * paper_body.g * 0.1
    h = U_top + 0.35
    level = LevelSet(paper_body, 0.0, 0.0, C2)
    (orbit,) = orbits(level, h)
    assert orbit.kind == "periodic" and orbit.pole_passage
    assert (orbit.gamma3_min, orbit.gamma3_max) == (-1.0, 1.0)
    assert "both poles" in orbit.note
    T = plain_period(paper_body, C2, h, 0.0, 2 * math.pi, 1)
    assert orbit.period == pytest.approx(T, rel=PERIOD_RTOL)
    pm = period_map(level, h, orbit)
    # one turn rolls the sphere 2 pi R along nu and drifts C2/I1 * T along tau
    assert math.hypot(*pm.displacement) == pytest.approx(
        math.hypot(2 * math.pi * paper_body.R, C2 / paper_body.I1 * T), rel=1e-8
    )


def test_separatrix_and_rest(paper_body):
    level = LevelSet(paper_body, 0.0, 0.0, 0.0)
    (sep,) = orbits(level, paper_body.m * paper_body.g * 0.1)
    assert sep.kind == "separatrix" and math.isinf(sep.period)
    (rest,) = orbits(level, -paper_body.m * paper_body.g * 0.1)
    assert rest.kind == "steady" and rest.gamma3_min == pytest.approx(-1.0, abs=POLE_ATOL)
