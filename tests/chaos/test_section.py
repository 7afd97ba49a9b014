"""Poincare sections (rollingtop.chaos.section) and the level-set sampling (.level).

On the paper's model (integrable) every crossing of a trajectory must be the lower turning point
of its level, computed here from docs/model.md's plain U with mpmath (tests/reduction/plain.py);
the located crossing is compared with SciPy's event location on the independent NumPy
right-hand side (tests/dynamics/reference.py).
"""

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import InitialStateError, ScenarioError, SphericalTop, initial_state
from rollingtop.chaos import level_states, poincare_section
from rollingtop.chaos.level import LEVEL_RTOL, held_integrals, level_values
from rollingtop.dynamics.integrals import evaluate
from rollingtop.io import netcdf_bytes

from ..conftest import FREE, GAMMA0, OMEGA0, PAPER_BODY
from ..dynamics import reference
from ..reduction import plain

#: One pytest-xdist worker runs this module
#: (its module fixtures compute sections once;
#: split over two workers, the fixture would run on each).
pytestmark = pytest.mark.xdist_group("section")

PAPER = SphericalTop(**PAPER_BODY)
#: |w_tau| at a located (and polished) crossing.
W_TAU_TOL = 1e-11
#: A trajectory's crossings coincide to this (integration error over 100 periods, rtol 1e-10).
SAME_POINT_TOL = 1e-8
#: Crossing against the turning point of the reduction (docs/model.md's U, mpmath).
TURNING_POINT_TOL = 1e-9
#: Against SciPy (rtol = atol = 1e-12) on the reference rhs: first crossing's time and state.
SCIPY_TOL = 1e-8


@pytest.fixture(scope="module")
def paper_state():
    return initial_state(PAPER, "meridian", gamma=GAMMA0, omega=OMEGA0, free=FREE["meridian"])


@pytest.fixture(scope="module")
def meridian_section(paper_state):
    return poincare_section(PAPER, "meridian", paper_state, crossings=100, trajectories=6)


def test_level_states_hold_every_integral(paper_state, chaotic):
    for body, model, y0 in ((PAPER, "meridian", paper_state), chaotic):
        names = held_integrals(body, model)
        target = level_values(body, model, y0, names)
        Y = level_states(body, model, y0, 12, seed=3)
        assert Y.shape == (12, 18)
        np.testing.assert_array_equal(Y[0], y0)
        got = np.array([level_values(body, model, y, names) for y in Y])
        assert np.all(np.abs(got - target) <= LEVEL_RTOL * (1 + np.abs(target)))
        assert np.ptp(Y[:, 14]) > 0.05  # the orientations differ


def test_level_states_of_the_shell_rotor_pair():
    """The pair's level: the shell's spin (the state's last slot) is set with the velocities, so
    the samples hold the pair's integrals; checked here by the pair's energy written out (rotor
    + shell, docs/model.md) and by the shell's rolling without slip, and simulate takes them."""
    from rollingtop import load_scenario, simulate

    from ..conftest import EXAMPLES

    sc = load_scenario(EXAMPLES / "shell_rotor.toml")
    body, y0 = sc.body, sc.y0
    Y = level_states(body, "shell-rotor", y0, 5, seed=2)
    e3 = np.array([0.0, 0.0, 1.0])

    def pair_energy(y):
        v, w, gamma, delta = y[0:3], y[3:6], y[12:15], y[17]
        v_centre = v - body.a3 * np.cross(w, e3)  # the shell's centre, the rotor's geometric one
        shell_w = w + delta * e3  # the shell turns with the rotor but about its axis
        rotor = 0.5 * body.m * v @ v + 0.5 * w @ (np.array(body.inertia) * w)
        shell = (
            0.5 * body.shell_mass * v_centre @ v_centre
            + 0.5 * body.shell_inertia * shell_w @ shell_w
        )
        return rotor + shell + body.m * body.g * body.a3 * gamma[2], v_centre - body.R * np.cross(
            shell_w, gamma
        )

    e0, _ = pair_energy(y0)
    for y in Y:
        e, slip = pair_energy(y)
        assert e == pytest.approx(e0, abs=1e-9 * (1 + abs(e0)))
        np.testing.assert_allclose(slip, 0.0, atol=1e-12)  # the shell rolls without slipping
    assert np.ptp(Y[:, 14]) > 0.05
    run = simulate(body, "shell-rotor", Y[3], t_end=1.0)  # a consistent pair state
    assert abs(run.integrals["energy"][-1] - run.integrals["energy"][0]) < 1e-9


def test_level_states_refuse_bad_input(paper_state):
    with pytest.raises(InitialStateError, match="routh"):
        level_states(PAPER, "meridian", paper_state, 3, hold=["routh"])
    with pytest.raises(InitialStateError, match="n = 0"):
        level_states(PAPER, "meridian", paper_state, 0)


def test_meridian_crossings_are_the_turning_point_of_the_level(meridian_section):
    ds = meridian_section
    assert int(ds["n_crossings"].min()) == 100
    assert np.nanmax(np.abs(ds["w_tau"].values)) <= W_TAU_TOL
    g3 = ds["gamma3"].values
    assert np.max(np.ptp(g3, axis=1)) <= SAME_POINT_TOL
    assert np.max(np.ptp(ds["w_n"].values, axis=1)) <= SAME_POINT_TOL
    Y = ds["crossing_state"].values
    for name in ("energy", "lagrange", "area", "F6"):
        start = ds[f"level_{name}"].values[:, None]
        along = evaluate(PAPER, Y, [name])[name]
        assert np.max(np.abs(along - start)) <= 1e-9 * (1 + np.abs(start).max())
    # docs/model.md: h = E - I3 w3^2/2 - m g R, and at w_tau = 0, h = U(gamma3)
    b = PAPER
    M3 = float(ds["level_lagrange"][0])
    C1 = float(ds["level_area"][0])
    C2 = float(ds["level_F6"][0])
    h = float(ds["level_energy"][0]) - M3**2 / (2 * b.I3) - b.m * b.g * b.R
    with mp.workdps(30):
        (root,) = plain.turning_points(b, M3, C1, C2, h, [float(g3[0, 0])])
        assert float(root) == pytest.approx(g3[0, 0], abs=TURNING_POINT_TOL)
        # a minimum of gamma3: U decreasing there (the orbit lies above it)
        assert float(plain.U(b, M3, C1, C2, root + 1e-4)) < h
    s = math.sqrt(1 - g3[0, 0] ** 2)
    assert ds["w_n"].values[0, 0] == pytest.approx((M3 * g3[0, 0] - C1) / (b.I1 * s), abs=1e-9)
    assert np.all(g3 <= ds["initial_state"].values[:, 14, None] + 1e-12)


def test_first_crossing_agrees_with_scipy_on_the_reference_rhs(paper_state):
    ds = poincare_section(PAPER, "meridian", paper_state[None, :], crossings=1)
    t_ours = float(ds["t"][0, 0])
    p = PAPER.params

    def crossing(t, y):
        return y[12] * y[4] - y[13] * y[3]  # s w_tau

    crossing.direction = 1
    crossing.terminal = True
    sol = solve_ivp(
        lambda t, y: reference.rhs("meridian", p, y)[0],
        (0.0, 50.0),
        paper_state,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        events=crossing,
    )
    (t_ref,) = sol.t_events[0]
    (y_ref,) = sol.y_events[0]
    assert t_ours == pytest.approx(t_ref, abs=SCIPY_TOL)
    y_ours = ds["crossing_state"].values[0, 0]
    np.testing.assert_allclose(y_ours[:15], y_ref[:15], atol=SCIPY_TOL)


def test_chaotic_section_fills_an_area_and_writes_netcdf(chaotic):
    body, model, y0 = chaotic
    ds = poincare_section(body, model, y0, crossings=300, trajectories=4, seed=1)
    assert int(ds["n_crossings"].sum()) == 1200
    assert np.nanmax(np.abs(ds["w_tau"].values)) <= W_TAU_TOL
    assert float(ds["min_normal_force"].min()) > 0
    # the chaotic trajectory (the given state) does not repeat a point: its gamma3 values spread
    assert np.ptp(ds["gamma3"].values[0]) > 0.3
    assert len(netcdf_bytes(ds)) > 0


def test_trajectories_stopped_early_name_the_stepper_status(paper_state):
    """A trajectory out of steps is listed with the stepper's status name; one that reached
    t_max with fewer crossings, as such; a complete one not at all."""
    from rollingtop.chaos.section import section_summary

    states = np.array([paper_state, paper_state])
    ds = poincare_section(PAPER, "meridian", states, crossings=5, max_steps=3)
    summary = section_summary(ds)
    assert summary["incomplete"] == 2
    first = summary["stopped_early"][0]
    assert (first["trajectory"], first["status"], first["reason"]) == (0, 1, "max_steps reached")
    np.testing.assert_array_equal(first["gamma"], paper_state[12:15])
    np.testing.assert_array_equal(first["omega"], paper_state[3:6])
    assert first["crossings"] == int(ds["n_crossings"][0]) < 5
    ds = poincare_section(PAPER, "meridian", states, crossings=5, t_max=1.0)
    assert {s["reason"] for s in section_summary(ds)["stopped_early"]} == {"t_max reached"}
    ds = poincare_section(PAPER, "meridian", states, crossings=2)
    assert section_summary(ds)["stopped_early"] == []


def test_section_refuses_bad_input(paper_state):
    with pytest.raises(ScenarioError, match="crossings"):
        poincare_section(PAPER, "meridian", paper_state, crossings=0)
    with pytest.raises(InitialStateError, match="shape"):
        poincare_section(PAPER, "meridian", np.zeros((2, 5)))
    bad = paper_state.copy()
    bad[2] += 1.0  # v3: along gamma and nu, both constrained
    with pytest.raises(InitialStateError, match="constraint"):
        poincare_section(PAPER, "meridian", bad[None, :])
