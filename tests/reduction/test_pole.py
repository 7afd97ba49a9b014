"""Pole cases C1 = +-M3: the pole touches the plane. The reduction says so and stays finite; the
full simulation passes through the pole with every integral conserved."""

import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import IntegrationError, simulate
from rollingtop.contact import meridian
from rollingtop.integrate import integrate
from rollingtop.reduction import LevelSet, orbits
from rollingtop.scenario import IntegrationOptions, LevelSpec, Scenario

#: Kernel codes of the meridian model's pole variants.
SOUTH_CODE, NORTH_CODE = (k.code for k in meridian.MODEL.kernels[1:])

CASES = [  # (C1, C2): south pole (C1 = M3) and north pole (C1 = -M3) cases, M3 = 1
    (1.0, -0.3),
    (1.0, 0.5),
    (-1.0, 0.3),
    (-1.0, -0.3),
]
DRIFT_REL = 1e-10
SIM_PERIOD_RTOL = 1e-9


def pole_h(level):
    return float(level.U(level.pole_theta)) + 0.5  # above the potential at the pole: passage


def U_theta_plain(b, M3, C1, C2, theta):
    """docs/model.md's U with s = sin(theta), arccos -> theta (signed), evaluated with mpmath."""
    s, c = mp.sin(theta), mp.cos(theta)
    P = (b.R * (M3 - C1 * c) + b.a3 * (M3 * c - C1)) / s + C2 + M3 * b.a3 * theta
    return (
        (C1 - M3 * c) ** 2 / (2 * b.I1 * s**2) + b.m * P**2 / (2 * b.I1**2) + b.m * b.g * (b.a3 * c)
    )


@pytest.mark.parametrize(("C1", "C2"), CASES)
def test_reduced_orbit_through_the_pole(paper_body, C1, C2):
    level = LevelSet(paper_body, M3=1.0, C1=C1, C2=C2)
    assert level.pole == ("south" if C1 > 0 else "north")
    h = pole_h(level)
    with np.errstate(all="raise"):
        (orbit,) = orbits(level, h)
    assert orbit.pole_passage and "passes through the pole" in orbit.note
    assert (orbit.gamma3_max if C1 > 0 else orbit.gamma3_min) == (1.0 if C1 > 0 else -1.0)
    assert orbit.theta_min < level.pole_theta < orbit.theta_max
    # period against mpmath in the signed angle, docs/model.md's formula with C1 = +-M3 exactly
    with mp.workdps(30):

        def f(t):
            return mp.sqrt(
                (
                    paper_body.I1
                    + paper_body.m
                    * (
                        paper_body.a3**2
                        + paper_body.R**2
                        + 2 * paper_body.a3 * paper_body.R * mp.cos(t)
                    )
                )
                / (2 * (h - U_theta_plain(paper_body, 1, C1, C2, t)))
            )

        t1 = mp.findroot(
            lambda t: U_theta_plain(paper_body, 1, C1, C2, t) - h,
            (orbit.theta_min - 1e-9, orbit.theta_min + 1e-9),
            solver="anderson",
        )
        t2 = mp.findroot(
            lambda t: U_theta_plain(paper_body, 1, C1, C2, t) - h,
            (orbit.theta_max - 1e-9, orbit.theta_max + 1e-9),
            solver="anderson",
        )
        expected = 2 * mp.quad(f, [t1, level.pole_theta, t2])
        assert orbit.period == pytest.approx(float(expected), rel=1e-10)


@pytest.mark.parametrize(("C1", "C2"), CASES)
def test_full_simulation_passes_through_the_pole(paper_body, C1, C2):
    level = LevelSet(paper_body, M3=1.0, C1=C1, C2=C2)
    h = pole_h(level)
    (orbit,) = orbits(level, h)
    sc = Scenario(
        paper_body,
        "meridian",
        None,
        IntegrationOptions(t_end=30.0, rtol=1e-12, atol=1e-14, samples=3001),
        level=LevelSpec(1.0, C1, C2, h=h),
    )
    traj = simulate(sc, events="w_tau", event_direction=1)
    assert traj.pole_case == level.pole
    g3 = traj.gamma[:, 2]
    assert (1 - g3.max() if C1 > 0 else 1 + g3.min()) < 1e-5  # it reaches the pole
    for name, values in traj.integrals.items():
        assert np.ptp(values) <= DRIFT_REL * np.max(np.abs(values)), name
    s = traj.summary()
    assert s["constraints"]["max_abs_residual"] < 1e-12
    assert traj.integrals["F6"][0] == pytest.approx(C2, abs=1e-12)
    np.testing.assert_allclose(np.diff(traj.event_t), orbit.period, rtol=SIM_PERIOD_RTOL)
    # The paper's unsigned F6 (s = |e3 x gamma|, arccos) flips to -C2 after each passage: the
    # passage reverses tau and n. The reported F6 follows the carried side and stays C2.
    y = traj.y
    su = np.hypot(y[:, 12], y[:, 13])
    tau = np.stack([-y[:, 13], y[:, 12], 0 * su], 1) / su[:, None]
    n = -np.stack([y[:, 12], y[:, 13], 0 * su], 1) / su[:, None]
    v_tau, w_n = np.sum(y[:, 0:3] * tau, 1), np.sum(y[:, 3:6] * n, 1)
    b = paper_body
    F6u = b.I1 * (v_tau - (b.R * g3 + b.a3) * w_n) - b.I3 * y[:, 5] * (
        b.R * su + b.a3 * np.arccos(g3)
    )
    far = su > 0.1
    if C1 < 0:  # north: the unsigned angle is measured from the other side, arccos -> 2pi - ...
        F6u = np.where(
            np.cos(y[:, 17] - np.arctan2(y[:, 11], y[:, 8])) < 0,
            F6u + 2 * math.pi * b.a3 * b.I3 * y[:, 5],
            F6u,
        )
    assert np.any(np.abs(F6u[far] - C2) < 1e-8) and np.any(np.abs(F6u[far] + C2) < 1e-8)


def test_geometric_direction_cannot_pass_the_pole(paper_body):
    """Why nu is carried: with nu computed from the orientation alone the integrator stalls at
    the first near-miss of the pole."""
    level = LevelSet(paper_body, M3=1.0, C1=1.0, C2=-0.3)
    sc = Scenario(
        paper_body,
        "meridian",
        None,
        IntegrationOptions(t_end=10.0),
        level=LevelSpec(1.0, 1.0, -0.3, h=pole_h(level)),
    )
    assert meridian.MODEL.kernel_code(paper_body, sc.y0) == SOUTH_CODE
    with pytest.raises(IntegrationError, match="step size underflow"):
        integrate(
            meridian.MODEL.code,
            paper_body.params,
            sc.y0,
            np.array([0.0, 10.0]),
            rtol=1e-12,
            atol=1e-14,
        )
