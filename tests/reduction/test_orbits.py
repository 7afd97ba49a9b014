"""Steady motions and orbits on the paper's Fig. 5 level set, against mpmath and the full
simulation."""

import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import simulate
from rollingtop.reduction import (
    LevelSet,
    LevelSetError,
    euler_angles,
    orbits,
    reduce_state,
    state_from_level,
    steady_motions,
)
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario

from . import plain

PERIOD_RTOL = 1e-10  # issue 3: quadrature period, 1e-10 relative
SIM_PERIOD_RTOL = 1e-9  # issue 3: quadrature vs full simulation (events on w_tau = 0)


@pytest.fixture
def fig5(paper_body):
    return LevelSet(paper_body, M3=1.0, C1=0.5, C2=-2.0)


def simulate_from(level, h, gamma3, t_end, **kw):
    y0 = state_from_level(level, h, gamma3, branch=1)
    ic = InitialConditions(gamma=y0[12:15], omega=y0[3:6], alpha=y0[6:9], v=y0[0:3])
    sc = Scenario(level.body, "meridian", ic,
                  IntegrationOptions(t_end=t_end, rtol=1e-12, atol=1e-14, samples=501))  # fmt: skip
    return simulate(sc, **kw)


def test_steady_motions_of_fig5(fig5, paper_body):
    """Two centres and a saddle between them; U' = 0 there to mpmath precision."""
    with mp.workdps(30):
        motions = steady_motions(fig5)
        assert [m.type for m in motions] == ["center", "saddle", "center"]
        assert [m.gamma3 for m in motions] == sorted(m.gamma3 for m in motions)
        for m in motions:
            root = mp.findroot(lambda g: mp.diff(lambda x: plain.U(paper_body, 1, 0.5, -2, x), g),
                               (m.gamma3 - 1e-6, m.gamma3 + 1e-6), solver="anderson")  # fmt: skip
            assert m.gamma3 == pytest.approx(float(root), abs=1e-12)
            assert m.U == pytest.approx(float(plain.U(paper_body, 1, 0.5, -2, root)), rel=1e-13)
            u2 = mp.diff(lambda x: plain.U(paper_body, 1, 0.5, -2, x), root, 2)
            assert m.U2 == pytest.approx(float(u2), rel=1e-8)
            assert (m.U2 > 0) == (m.type == "center")


def test_a_state_started_at_a_centre_stays_there(fig5):
    centre = steady_motions(fig5)[2]
    traj = simulate_from(fig5, centre.U, centre.gamma3, 50.0)
    red = reduce_state(traj.y)
    # round-off puts h above U_min by ~eps * U; that is an oscillation of amplitude
    # sqrt(2 eps U / U'') ~ 2e-9 in gamma3 (and ~2e-8 in w_tau): it stays there, not drifts
    amplitude = math.sqrt(2 * 8 * np.finfo(float).eps * centre.U / centre.U2)
    assert np.max(np.abs(red["gamma3"] - centre.gamma3)) < amplitude
    assert np.max(np.abs(red["w_tau"])) < 10 * amplitude * centre.frequency
    # what the body does there: spin, precession rate, CoM speed and circle
    np.testing.assert_allclose(traj.omega[:, 2], centre.spin, rtol=1e-12)
    psi = np.unwrap(euler_angles(traj.y)["psi"])
    assert np.polyfit(traj.t, psi, 1)[0] == pytest.approx(centre.precession_rate, rel=1e-9)
    velocity = np.stack([np.sum(traj.v * traj.alpha, 1), np.sum(traj.v * traj.beta, 1)], 1)
    np.testing.assert_allclose(np.hypot(*velocity.T), centre.com_speed, rtol=1e-7)
    # the CoM runs on a circle (algebraic least-squares fit) of the predicted radius
    X, Y = traj.position.T
    A = np.stack([X, Y, np.ones_like(X)], 1)
    cx, cy, c = np.linalg.lstsq(A, X**2 + Y**2, rcond=None)[0]
    radius = math.sqrt(c + cx**2 / 4 + cy**2 / 4)
    assert radius == pytest.approx(centre.com_radius, rel=1e-6)
    # round-off leaves a nutation of amplitude ~1e-9 whose frequency (10.42) is close to the
    # precession rate (10.46): nearly resonant, it lets the circle's centre wander by ~1e-6
    np.testing.assert_allclose(np.hypot(X - cx / 2, Y - cy / 2), radius, rtol=1e-4)


@pytest.mark.slow
def test_small_oscillation_period_is_the_limit_of_orbit_periods(fig5):
    for m in steady_motions(fig5):
        if m.type != "center":
            continue
        orbit = orbits(fig5, m.U + 1e-10 * abs(m.U))
        small = min(orbit, key=lambda o: abs(o.gamma3_min - m.gamma3))
        assert small.period == pytest.approx(m.period, rel=1e-6)
        assert small.gamma3_min <= m.gamma3 <= small.gamma3_max


@pytest.mark.parametrize("h", [3.3, 4.0, 5.5, 6.5, 12.0])
def test_period_matches_mpmath(fig5, paper_body, h):
    with mp.workdps(30):
        for o in orbits(fig5, h):
            lo, hi = plain.turning_points(paper_body, 1, 0.5, -2, h, [o.gamma3_min, o.gamma3_max])
            assert o.gamma3_min == pytest.approx(float(lo), abs=1e-13)
            assert o.gamma3_max == pytest.approx(float(hi), abs=1e-13)
            expected = plain.period(paper_body, 1, 0.5, -2, h, lo, hi)
            assert o.period == pytest.approx(float(expected), rel=PERIOD_RTOL)
            assert o.kind == "periodic" and o.period_error < PERIOD_RTOL * o.period


@pytest.mark.parametrize("h", [4.0, 5.5])
@pytest.mark.filterwarnings("ignore::rollingtop.ContactLostWarning")  # the upper well at 5.5
def test_period_matches_the_full_simulation(fig5, h):
    for o in orbits(fig5, h):
        traj = simulate_from(fig5, h, o.gamma3_min + 1e-3 * (o.gamma3_max - o.gamma3_min),
                             t_end=5.5 * o.period, events="w_tau")  # fmt: skip
        y = traj.event_y
        g3 = y[:, 14]
        # events alternate between the two turning points
        tops, bottoms = traj.event_t[g3 > np.mean(g3)], traj.event_t[g3 < np.mean(g3)]
        assert len(tops) >= 4 and len(bottoms) >= 4
        for times in (tops, bottoms):
            np.testing.assert_allclose(np.diff(times), o.period, rtol=SIM_PERIOD_RTOL)
        np.testing.assert_allclose(g3[g3 > np.mean(g3)], o.gamma3_max, atol=1e-10)
        np.testing.assert_allclose(g3[g3 < np.mean(g3)], o.gamma3_min, atol=1e-10)


def test_separatrix(fig5):
    saddle = steady_motions(fig5)[1]
    on = orbits(fig5, saddle.U)
    assert len(on) == 1 and on[0].kind == "separatrix" and math.isinf(on[0].period)
    assert "grows without bound" in on[0].note
    # above it: one big orbit, period growing like log(1/gap) (equal increments per decade)
    T = [orbits(fig5, saddle.U + gap)[0].period for gap in (1e-3, 1e-4, 1e-5)]
    assert T[0] < T[1] < T[2]
    assert (T[2] - T[1]) == pytest.approx(T[1] - T[0], rel=1e-2)
    assert (T[2] - T[1]) == pytest.approx(2 * math.log(10) / saddle.growth_rate, rel=2e-2)
    # below it: two orbits, one per well, each with a long period and an honest error bar
    below = orbits(fig5, saddle.U - 1e-8)
    assert len(below) == 2
    for o in below:
        assert o.kind == "periodic" and "near a separatrix" in o.note
        assert o.period_error / o.period > 1e-10


def test_steady_orbit_and_no_motion(fig5):
    centre = steady_motions(fig5)[0]
    (o,) = [o for o in orbits(fig5, centre.U) if o.kind == "steady"]
    assert o.gamma3_min == pytest.approx(centre.gamma3) and o.period == centre.period
    with pytest.raises(LevelSetError, match="h is below the minimum of the effective potential"):
        orbits(fig5, 3.0)
