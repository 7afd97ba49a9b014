"""Figures of a simulated motion: the plotted data against values computed here, from the
trajectory's states (docs/model.md), the NumPy reference of the dynamics and the reduction."""

import matplotlib.colors as mcolors
import numpy as np
import pytest

from rollingtop import ContactLostWarning, SphericalTop, simulate, simulate_models
from rollingtop.absolute import period_map
from rollingtop.contact import get_model
from rollingtop.plot.paths import compare_figure, path_figure, timeseries_figure
from rollingtop.reduction import LevelSet, orbits, state_from_level
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario, load_scenario

from ..conftest import EXAMPLES, PAPER_BODY
from ..dynamics import reference

#: Plotted arrays that are the samples themselves, or plain arithmetic on them.
SAME = 1e-13
#: Reactions of the NumPy reference (linalg.solve of the full system) against the plotted ones
#: (measured: 7e-15).
REACTION_RTOL = 1e-10
#: Energy written here against the package's: both round-off, relative to |E|.
ENERGY_TOL = 1e-14
#: The once-per-period CoM positions of the full simulation on the circle the reduction predicts
#: (measured: 7e-13 of the radius; tests/test_absolute.py holds the physics to 1e-8).
CIRCLE_RTOL = 1e-9
#: A conserved integral's plotted relative change at rtol 1e-12 (measured: 2e-12 at most), and
#: the least change shown by an integral the model does not conserve (measured: 0.08 at least).
CONSERVED, NOT_CONSERVED = 1e-9, 1e-6


def line(ax, label):
    (found,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
    return found


def xy(ln):
    return np.column_stack([np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)])


def energy(p, Y):
    """``m |v|^2 / 2 + (w, I w) / 2 + m g z``, the CoM at height ``z = R + a3 gamma3``."""
    R, m, g, a3, I1, I2, I3 = p[:7]
    v, w = Y[:, 0:3], Y[:, 3:6]
    kinetic = 0.5 * m * np.sum(v * v, axis=1) + 0.5 * (w**2 @ np.array([I1, I2, I3]))
    return kinetic + m * g * (R + a3 * Y[:, 14])


@pytest.fixture(scope="module")
def fig5_motion():
    """Eight periods of a meridian motion on the paper's Fig. 5 level (h = 4), its events and its
    per-period map."""
    level = LevelSet(SphericalTop(**PAPER_BODY), M3=1.0, C1=0.5, C2=-2.0)
    orbit = orbits(level, 4.0)[0]
    pm = period_map(level, 4.0, orbit)
    y0 = state_from_level(level, 4.0, 0.5 * (orbit.gamma3_min + orbit.gamma3_max), psi=0.3,
                          position=(1.0, 2.0))  # fmt: skip
    ic = InitialConditions(gamma=y0[12:15], omega=y0[3:6], alpha=y0[6:9], v=y0[0:3],
                           position=y0[15:17])  # fmt: skip
    options = IntegrationOptions(t_end=8 * pm.period, rtol=1e-12, atol=1e-14, samples=801)
    traj = simulate(Scenario(level.body, "meridian", ic, options), events="w_tau",
                    event_direction=1)  # fmt: skip
    return traj, pm


def test_path_figure_draws_the_contact_point_the_centre_of_mass_and_the_predicted_circle(
    fig5_motion,
):
    traj, pm = fig5_motion
    ax = path_figure(traj, pm).axes[0]
    Y, a3 = traj.y, traj.body.a3
    com = Y[:, 15:17]
    # the contact point lies below the geometric centre: (X - a3 alpha3, Y - a3 beta3)
    contact = com - a3 * Y[:, [8, 11]]
    np.testing.assert_allclose(xy(line(ax, "contact point")), contact, rtol=0, atol=SAME)
    np.testing.assert_allclose(xy(line(ax, "centre of mass")), com, rtol=0, atol=SAME)
    np.testing.assert_allclose(xy(line(ax, "start")), com[:1], rtol=0, atol=SAME)
    # once per period: the CoM at the rising zeros of w_tau = (gamma2 w1 - gamma1 w2) / s
    dots = xy(line(ax, "CoM once per period (min of $\\gamma_3$)"))
    assert len(dots) == 8
    E = traj.event_y
    np.testing.assert_allclose(E[:, 12] * E[:, 4] - E[:, 13] * E[:, 3], 0, atol=1e-12)
    np.testing.assert_allclose(dots, E[:, 15:17], rtol=0, atol=SAME)
    # the dashed circle (from the reduction) passes through the simulated points
    circle = xy(line(ax, "predicted circle"))
    centre = circle[:-1].mean(axis=0)
    assert np.ptp(np.hypot(*(circle - centre).T)) < SAME * pm.radius
    np.testing.assert_allclose(np.hypot(*(dots - centre).T), pm.radius, rtol=CIRCLE_RTOL)
    plus = [ln for ln in ax.get_lines() if ln.get_marker() == "+"]
    np.testing.assert_allclose(xy(plus[0])[0], centre, rtol=0, atol=1e-12 * pm.radius)


def test_timeseries_figure_plots_gamma3_the_energy_drift_and_the_reference_reactions(
    fig5_motion,
):
    traj, _ = fig5_motion
    ax1, ax2, ax3 = timeseries_figure(traj).axes
    t, Y, p = traj.t, traj.y, traj.body.params
    (g3,) = ax1.get_lines()
    np.testing.assert_allclose(xy(g3), np.column_stack([t, Y[:, 14]]), rtol=0, atol=SAME)
    # reactions: the NumPy reference's, at every sample
    N_ref, T_ref = np.array([reference.reactions("meridian", p, y) for y in Y]).T
    N, T = xy(line(ax3, "normal force N")), xy(line(ax3, "tangential force T"))
    np.testing.assert_allclose(N[:, 0], t, rtol=0, atol=0)
    np.testing.assert_allclose(N[:, 1], N_ref, rtol=REACTION_RTOL)
    np.testing.assert_allclose(T[:, 1], T_ref, rtol=REACTION_RTOL, atol=1e-12)
    # the energy's relative drift, floored at 1e-17 for the log axis
    E = energy(p, Y)
    drift = np.maximum(np.abs(E - E[0]) / np.max(np.abs(E)), 1e-17)
    np.testing.assert_allclose(xy(line(ax2, "energy"))[:, 1], drift, rtol=0, atol=ENERGY_TOL)
    assert ax2.get_yscale() == "log"
    assert {ln.get_label() for ln in ax2.get_lines()} == set(traj.model.integrals(True))


def test_timeseries_figure_marks_the_loss_of_contact():
    """A top with a3 = 0.5 spun about a horizontal axis lifts off (tests/integrate): the dashed
    line lies between the samples where the plotted normal force changes sign."""
    body = SphericalTop(R=1, m=1, g=1, a3=0.5, I1=0.3, I3=0.5)
    sc = Scenario(body, "meridian", InitialConditions(gamma=(0.0, 0.6, 0.8), omega=(1.4, 0, 0.3)),
                  IntegrationOptions(t_end=4, samples=201))  # fmt: skip
    with pytest.warns(ContactLostWarning, match="normal reaction turns negative"):
        traj = simulate(sc)
    ax3 = timeseries_figure(traj).axes[2]
    N = xy(line(ax3, "normal force N"))
    k = np.flatnonzero(N[:, 1] < 0)[0]
    (lost,) = [ln for ln in ax3.get_lines() if ln.get_label().startswith("contact lost")]
    x = np.asarray(lost.get_xdata(), float)
    assert N[k - 1, 0] < x[0] == x[1] <= N[k, 0]


def test_compare_figure_draws_each_models_path_and_integrals():
    """Every model's CoM path in the model's colour, from the same start; each integral panel
    flat exactly for the models that conserve it (the energy: all), written out here."""
    runs = simulate_models(load_scenario(EXAMPLES / "paper.toml"), t_end=10.0, rtol=1e-12,
                           atol=1e-14, samples=401)  # fmt: skip
    fig = compare_figure(runs)
    paths, *panels = fig.axes
    for name, run in runs.items():
        path = line(paths, name)
        np.testing.assert_allclose(xy(path), run.position, rtol=0, atol=SAME)
        assert mcolors.same_color(path.get_color(), get_model(name).colour)
        np.testing.assert_allclose(run.position[0], (0.0, 0.0), atol=0)
    shown = [ax.get_ylabel().split(":")[0] for ax in panels]
    assert shown == ["energy", "F6", "momentum_x", "routh"]
    for ax, integral in zip(panels, shown, strict=True):
        for name, run in runs.items():
            conserved = integral in get_model(name).integrals(True)
            ln = line(ax, name + (" (conserved)" if conserved else ""))
            change = xy(ln)[:, 1]
            np.testing.assert_allclose(xy(ln)[:, 0], run.t, rtol=0, atol=0)
            assert ln.get_linestyle() == ("-" if conserved else "--")
            if conserved:
                assert np.max(np.abs(change)) < CONSERVED, (integral, name)
            else:
                assert np.max(np.abs(change)) > NOT_CONSERVED, (integral, name)
            if integral == "energy":
                E = energy(run.body.params, run.y)
                np.testing.assert_allclose(change, (E - E[0]) / abs(E[0]), rtol=0,
                                           atol=ENERGY_TOL)  # fmt: skip
