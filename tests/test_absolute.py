"""Motion in absolute space: reconstruction, per-period map, bounded vs drifting motion."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from rollingtop import simulate
from rollingtop.absolute import period_map, reconstruct
from rollingtop.reduction import LevelSet, orbits, reduce_state, state_from_level, steady_motions
from rollingtop.reduction.orbits import period
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario

RECONSTRUCTION_TOL = 1e-8  # issue 4: reconstruction vs full simulation's path
DPSI_TOL = 1e-9  # issue 4: Delta psi from quadrature vs measured on the simulation


def full_run(level, h, gamma3, t_end, psi=0.3, position=(1.0, 2.0), samples=601):
    y0 = state_from_level(level, h, gamma3, psi=psi, position=position)
    ic = InitialConditions(gamma=y0[12:15], omega=y0[3:6], alpha=y0[6:9], v=y0[0:3],
                           position=y0[15:17])  # fmt: skip
    sc = Scenario(
        level.body,
        "meridian",
        ic,
        IntegrationOptions(t_end=t_end, rtol=1e-13, atol=1e-15, samples=samples),
    )
    return simulate(sc, events="w_tau", event_direction=1)


@pytest.fixture
def fig5(paper_body):
    return LevelSet(paper_body, M3=1.0, C1=0.5, C2=-2.0)


def test_reconstruction_matches_the_full_simulation(fig5):
    orbit = orbits(fig5, 4.0)[0]
    traj = full_run(fig5, 4.0, 0.5 * (orbit.gamma3_min + orbit.gamma3_max), 20 * orbit.period)
    r0 = reduce_state(traj.y[0])
    rec = reconstruct(fig5, traj.t, theta0=float(r0["theta"]), w_tau0=float(r0["w_tau"]),
                      psi0=float(traj.y[0, 17]), position0=traj.y[0, 15:17])  # fmt: skip
    np.testing.assert_allclose(rec["position"], traj.position, rtol=0, atol=RECONSTRUCTION_TOL)
    np.testing.assert_allclose(rec["contact_point"], traj.contact_point, rtol=0,
                               atol=RECONSTRUCTION_TOL)  # fmt: skip
    np.testing.assert_allclose(rec["psi"], np.unwrap(traj.y[:, 17]), rtol=0, atol=1e-8)
    np.testing.assert_allclose(rec["gamma3"], traj.gamma[:, 2], rtol=0, atol=1e-10)


@pytest.mark.parametrize("h", [4.0, 5.0])
def test_per_period_map_matches_the_full_simulation(fig5, h):
    """Delta psi by quadrature equals the advance of psi between successive minima of gamma3,
    and the once-per-period CoM positions lie on the predicted circle."""
    for orbit in orbits(fig5, h):
        pm = period_map(fig5, h, orbit)
        traj = full_run(fig5, h, 0.5 * (orbit.gamma3_min + orbit.gamma3_max), 12 * pm.period)
        psi = traj.event_y[:, 17]
        measured = np.diff(psi)
        # compare modulo 2 pi (psi is an angle; the map only knows it up to whole turns)
        err = np.angle(np.exp(1j * (measured - pm.delta_psi)))
        np.testing.assert_allclose(err, 0, atol=DPSI_TOL)
        assert pm.motion == "bounded" and not pm.near_resonant
        centre = pm.center_from(psi[0], traj.event_y[0, 15:17])
        P = traj.event_y[:, 15:17]
        np.testing.assert_allclose(np.hypot(P[:, 0] - centre[0], P[:, 1] - centre[1]), pm.radius,
                                   rtol=1e-8)  # fmt: skip
        assert pm.radius == pytest.approx(
            math.hypot(*pm.displacement) / (2 * abs(math.sin(pm.delta_psi / 2))), rel=1e-12
        )


def test_resonant_orbit_drifts(paper_body):
    """On M3 = 1, C1 = 0.5, C2 = -1 the advance Delta psi changes sign between h - U_min = 1 and 2:
    at the root the axis returns to the same azimuth each period and the CoM drifts."""
    level = LevelSet(paper_body, M3=1.0, C1=0.5, C2=-1.0)
    u_min = min(m.U for m in steady_motions(level))

    def dpsi(h):
        o = orbits(level, h)[0]
        return period(level, h, o.theta_min, o.theta_max, weight="psi_dot")[0]

    h = brentq(dpsi, u_min + 1, u_min + 2, xtol=1e-15, rtol=8.9e-16)
    pm = period_map(level, h)
    assert pm.motion == "drifting" and pm.center is None
    orbit = orbits(level, h)[0]
    traj = full_run(level, h, 0.5 * (orbit.gamma3_min + orbit.gamma3_max), 10 * pm.period, psi=0.0,
                    position=(0.0, 0.0))  # fmt: skip
    P = traj.event_y[:, 15:17]
    steps = np.diff(P, axis=0)
    np.testing.assert_allclose(steps, np.broadcast_to(steps[0], steps.shape), atol=1e-8)
    velocity = np.hypot(*steps[0]) / pm.period
    assert velocity == pytest.approx(math.hypot(*pm.drift_velocity), rel=1e-7)
    # a nearby h is bounded, with a circle far larger than the sphere: near-resonant
    near = period_map(level, h + 1e-4)
    assert near.motion == "bounded" and near.near_resonant and near.radius > 100


def test_pole_orbit_map(paper_body):
    level = LevelSet(paper_body, M3=1.0, C1=1.0, C2=-0.3)
    h = float(level.U(0.0)) + 0.5
    pm = period_map(level, h)
    orbit = orbits(level, h)[0]
    traj = full_run(level, h, math.cos(pm.start_theta) + 1e-3, 6 * pm.period)
    err = np.angle(np.exp(1j * (np.diff(traj.event_y[:, 17]) - pm.delta_psi)))
    np.testing.assert_allclose(err, 0, atol=DPSI_TOL)
    assert orbit.pole_passage
