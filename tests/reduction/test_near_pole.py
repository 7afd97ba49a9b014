"""Levels near a pole level (0 < |C1 -+ M3| <= 1e-2): turning points, periods and delta_psi
against an independent mpmath oracle at 40 digits, on two bodies (a3 > 0 and a3 < 0), six
distances from the pole, both poles and both signs; the limits on the pole level; the pole
tolerance at its boundary."""

import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.absolute import period_map
from rollingtop.contact.meridian import MODEL, POLE_CASE_TOLERANCE, pole_case
from rollingtop.reduction import POLE_TOLERANCE, LevelSet, orbits
from rollingtop.reduction.near_pole import near_pole

#: Relative accuracy asked of period, delta_psi and the pole distance of the turning point.
RTOL = 1e-10
#: Slack on the reported error estimates: |true error| <= ERR_SLACK * reported + ROUND * |value|.
ERR_SLACK, ROUND = 10.0, 1e-13

BODIES = {
    "paper": dict(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5),
    "low": dict(R=1.0, m=1.0, g=1.0, a3=-0.15, I1=0.4, I3=0.2),
}
#: (M3, C2, h) of a level whose orbit reaches the wall, per body and pole
LEVELS = {
    ("paper", "south"): (1.0, -0.3, 1.1),
    ("paper", "north"): (1.0, -0.3, 1.1),
    ("low", "south"): (1.0, 0.4, 1.6),
    ("low", "north"): (1.0, 0.3, 1.6),
}
#: six distances, with the pole and the sign of (C1 -+ M3) cycling through all four pairs
DISTANCES = [
    (1e-2, "south", +1),
    (1e-4, "north", -1),
    (1e-6, "south", -1),
    (1e-8, "north", +1),
    (1e-10, "south", +1),
    (1e-12, "north", -1),
]


@mp.workdps(40)  # a local context: the global precision is left alone
def oracle(b: dict, M3: float, C1: float, C2: float, h: float, pole: str):
    """The orbit next to the pole's wall by mpmath (40 digits), in the distance q from the pole.

    docs/model.md's U(gamma3) with gamma3 = cos(theta), theta = q (south) or pi - q (north); the
    turning points by bracketing on a log grid and refining; the period
    2 int sqrt(rho / (2 (h - U))) and delta_psi = 2 int psi' dt, psi' = (C1 - M3 gamma3) /
    (I1 s^2), by tanh-sinh quadrature with break points that resolve the wall.
    Returns (q1, T, delta_psi); q1 is the pole distance of the turning point at the wall.
    """
    R, m, g, a3, I1 = (mp.mpf(b[k]) for k in ("R", "m", "g", "a3", "I1"))
    M3, C1, C2, h = mp.mpf(M3), mp.mpf(C1), mp.mpf(C2), mp.mpf(h)
    sign = 1 if pole == "south" else -1

    def parts(q):
        theta = q if sign > 0 else mp.pi - q
        c, s = mp.cos(theta), mp.sin(theta)
        P = (R * (M3 - C1 * c) + a3 * (M3 * c - C1)) / s + C2 + M3 * a3 * mp.acos(c)
        U = (C1 - M3 * c) ** 2 / (2 * I1 * s**2) + m * P**2 / (2 * I1**2) + m * g * a3 * c
        rho = I1 + m * (a3**2 + R**2 + 2 * a3 * R * c)
        return U, rho, (C1 - M3 * c) / (I1 * s**2)

    def F(q):
        return h - parts(q)[0]

    grid = [mp.mpf(10) ** k for k in np.arange(-16, -1, 0.25)] + list(
        mp.linspace(mp.mpf("0.1"), mp.pi - mp.mpf("0.01"), 200)
    )
    vals = [F(q) for q in grid]
    changes = [i for i in range(len(grid) - 1) if vals[i] * vals[i + 1] < 0]
    i1, i2 = changes[0], changes[1]
    q1 = mp.findroot(F, (grid[i1], grid[i1 + 1]), solver="anderson")
    q2 = mp.findroot(F, (grid[i2], grid[i2 + 1]), solver="anderson")
    pts = [q1]
    k = 1
    while q1 * 10**k < (q1 + q2) / 2:
        pts.append(q1 * 10**k)
        k += 1
    pts += [(q1 + q2) / 2, q2]

    def dt(q):
        U, rho, _ = parts(q)
        return mp.sqrt(rho / (2 * (h - U)))

    # the real part: at the end points h - U is zero to 40 digits and may round below it
    T = 2 * mp.re(mp.quad(dt, pts))
    dpsi = 2 * mp.re(mp.quad(lambda q: dt(q) * parts(q)[2], pts))
    return q1, T, dpsi


#: Run by default: every (pole, sign) pair, both bodies, distances 1e-2 to 1e-12; the rest with
#: --slow (each case costs 1 to 2.5 s of mpmath).
DEFAULT_CASES = {("paper", 1e-2), ("low", 1e-6), ("low", 1e-8), ("low", 1e-12)}
CASES = [
    pytest.param(body, d, pole, sign, marks=() if (body, d) in DEFAULT_CASES else pytest.mark.slow)
    for body in BODIES
    for (d, pole, sign) in DISTANCES
]


@pytest.mark.parametrize(("body_name", "d", "pole", "sign"), CASES)
def test_near_pole_orbit_matches_mpmath(body_name, d, pole, sign):
    b = BODIES[body_name]
    M3, C2, h = LEVELS[(body_name, pole)]
    C1 = (M3 if pole == "south" else -M3) + sign * d  # C1 -+ M3 = sign * d (float as given)
    level = LevelSet(SphericalTop(**b), M3, C1, C2)
    assert level.pole is None
    found = [o for o in orbits(level, h) if o.pole_distance < 0.1]
    assert len(found) == 1, found
    (orbit,) = found
    q1, T, dpsi = oracle(b, M3, C1, C2, h, pole)
    assert orbit.pole_distance == pytest.approx(float(q1), rel=RTOL)
    if pole == "south":
        assert orbit.theta_min == pytest.approx(float(q1), rel=RTOL)
    else:
        assert math.pi - orbit.theta_max == pytest.approx(float(q1), rel=RTOL, abs=4e-16)
    assert orbit.period == pytest.approx(float(T), rel=RTOL)
    assert abs(orbit.period - float(T)) <= ERR_SLACK * orbit.period_error + ROUND * orbit.period
    pm = period_map(level, h, orbit)
    assert pm.delta_psi == pytest.approx(float(dpsi), rel=RTOL, abs=RTOL)
    true_err = abs(pm.delta_psi - float(dpsi))
    assert true_err <= ERR_SLACK * pm.delta_psi_error + ROUND * max(abs(pm.delta_psi), 1.0)


@pytest.mark.parametrize("side", [+1, -1])
def test_limits_on_the_pole_level(paper_body, side):
    """T and delta_psi tend to the reported limits as C1 -> M3 from either side; the limits of
    delta_psi differ by 2 pi; the pole level's period is the sum of the reflecting limits at C2
    and -C2 (the paper's unsigned variables); the friction needed grows like 1/|C1 - M3|."""
    M3, C2, h = 1.0, -0.3, 1.1
    near = {}
    for d in (1e-6, 1e-9):
        level = LevelSet(paper_body, M3, M3 + side * d, C2)
        (orbit,) = orbits(level, h)
        near[d] = (orbit, period_map(level, h, orbit), near_pole(level, h, orbit))
    orbit, pm, info = near[1e-9]
    # T approaches its limit like d log(1/d), delta_psi like d: the distances at d = 1e-6 and
    # 1e-9 shrink by those rates' ratios (within a factor 1.5: the constants are not asymptotic)
    gap_T = {d: abs(near[d][0].period - info.period_limit) for d in near}
    gap_P = {d: abs(near[d][1].delta_psi - info.delta_psi_limit) for d in near}
    rate_T = (1e-9 * math.log(1e9)) / (1e-6 * math.log(1e6))
    assert gap_T[1e-9] / gap_T[1e-6] == pytest.approx(rate_T, rel=0.5)
    assert gap_P[1e-9] / gap_P[1e-6] == pytest.approx(1e-3, rel=0.5)
    assert gap_T[1e-9] < 1e-6 and gap_P[1e-9] < 1e-8
    # the numbers for this level (measured with an mpmath oracle)
    assert info.period_limit == pytest.approx(2.461689680143, abs=2e-12)
    assert info.pole_level_period == pytest.approx(3.469261466266, abs=2e-12)
    pole_level = LevelSet(paper_body, M3, M3, C2)
    (through,) = orbits(pole_level, h)
    assert through.pole_passage and through.period == pytest.approx(info.pole_level_period)
    mirror = LevelSet(paper_body, M3, M3 + side * 1e-9, -C2)
    other = near_pole(mirror, h, orbits(mirror, h)[0])
    assert info.period_limit + other.period_limit == pytest.approx(through.period, rel=1e-11)
    # friction ~ 1/d: a thousand times thinner wall, a thousand times more friction (within 1%)
    ratio = near[1e-9][2].friction_needed / near[1e-6][2].friction_needed
    assert ratio == pytest.approx(1e3, rel=1e-2)
    assert info.min_normal_force > 0


def test_delta_psi_limits_differ_by_two_pi(paper_body):
    limits = []
    for side in (+1, -1):
        level = LevelSet(paper_body, 1.0, 1.0 + side * 1e-8, -0.3)
        limits.append(near_pole(level, 1.1, orbits(level, 1.1)[0]).delta_psi_limit)
    assert limits[0] - limits[1] == pytest.approx(2 * math.pi, rel=1e-12)
    pole_value = period_map(LevelSet(paper_body, 1.0, 1.0, -0.3), 1.1).delta_psi
    for lim in limits:  # neither limit is the pole level's value, even modulo 2 pi
        assert abs(math.remainder(lim - pole_value, 2 * math.pi)) > 1e-3  # 8.5e-3 here


def test_one_pole_tolerance_at_its_boundary(paper_body):
    """The reduction and the simulator take the same decision on either side of the tolerance."""
    assert POLE_TOLERANCE == POLE_CASE_TOLERANCE
    M3 = 1.0
    inside = M3 * (1 - 0.5 * POLE_CASE_TOLERANCE)
    outside = M3 * (1 - 2 * POLE_CASE_TOLERANCE)
    assert pole_case(M3, inside) == "south" and pole_case(-M3, inside) == "north"
    assert pole_case(M3, outside) is None and pole_case(-M3, outside) is None
    assert pole_case(0.0, 0.0) == "both"
    assert LevelSet(paper_body, M3, inside, -0.3).pole == "south"
    assert LevelSet(paper_body, M3, outside, -0.3).pole is None
    # the simulator's kernel choice follows the same decision for states on those levels (C1
    # recomputed from a state moves by ~1e-16, far less than the margins 0.5e-13 and 1e-13)
    own, south = MODEL.kernels[:2]
    from rollingtop.reduction import state_from_level

    for C1, expected in ((inside, south), (outside, own)):
        y = state_from_level(LevelSet(paper_body, M3, C1, -0.3), 1.1, 0.8)
        assert MODEL.kernel(paper_body, y) == expected


def test_mirror_image_is_the_same_motion(paper_body):
    """A level near the north pole is computed on its mirror image (e3 -> -e3): U, rho and psi'
    agree at pi - theta, and the per-period map's displacement agrees with a reconstruction in
    the original variables (where that is still accurate, 0.1 from the pole level)."""
    from rollingtop.absolute import reconstruct, start_theta

    level = LevelSet(paper_body, 1.0, -0.9, -0.3)
    mirror = level.mirrored()
    theta = np.linspace(0.2, 2.9, 7)
    for f in ("U", "rho", "psi_dot"):
        assert getattr(mirror, f)(math.pi - theta) == pytest.approx(
            getattr(level, f)(theta), rel=1e-12
        )
    (orbit,) = orbits(level, 1.1)
    pm = period_map(level, 1.1, orbit)
    direct = reconstruct(level, [0.0, orbit.period], theta0=start_theta(orbit), w_tau0=0.0)
    assert pm.displacement == pytest.approx(tuple(direct["position"][-1]), abs=1e-9)
    assert pm.delta_psi == pytest.approx(direct["psi"][-1], abs=1e-9)


def test_full_simulation_near_the_pole_level(paper_body):
    """The full equations on a level 1e-8 from the pole level: the period between turning
    points and the friction coefficient needed agree with the reduction's."""
    from rollingtop import simulate
    from rollingtop.scenario import IntegrationOptions, LevelSpec, Scenario

    M3, C1, C2, h = 1.0, 1.0 - 1e-8, -0.3, 1.1
    level = LevelSet(paper_body, M3, C1, C2)
    (orbit,) = orbits(level, h)
    info = near_pole(level, h, orbit)
    sc = Scenario(paper_body, "meridian", None,
                  IntegrationOptions(t_end=8.0, rtol=1e-12, atol=1e-14, samples=11),
                  level=LevelSpec(M3, C1, C2, h=h))  # fmt: skip
    traj = simulate(sc, events="w_tau", event_direction=1)
    assert traj.kernel_code == MODEL.code  # no pole case: the paper's geometric direction nu
    periods = np.diff(traj.event_t)
    assert len(periods) >= 2
    np.testing.assert_allclose(periods, orbit.period, rtol=1e-8)
    # the step-by-step monitoring samples the wall more coarsely than friction_needed: 5 %
    mu = traj.step_reactions["max_friction_ratio"]
    assert mu == pytest.approx(info.friction_needed, rel=0.05)
