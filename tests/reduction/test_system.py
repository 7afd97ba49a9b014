"""The reduced system (3.3): agrees with docs/model.md, with the full simulation, keeps its
integrals and its invariant measure."""

import mpmath as mp
import numpy as np
import pytest

from rollingtop import load_scenario, simulate
from rollingtop.contact import get_model
from rollingtop.reduction import (
    LevelSet,
    integrate_reduced,
    reduce_state,
    reduced_integrals,
    reduced_integrals_of,
    reduced_rhs,
)

from ..conftest import EXAMPLES
from . import plain


def random_points(rng, n=20):
    for _ in range(n):
        yield np.array([rng.uniform(-0.95, 0.95), *rng.normal(size=3)])


def test_field_matches_model_md(paper_body, rng):
    with mp.workdps(30):
        for x in random_points(rng):
            expected = [float(v) for v in plain.field(paper_body, 1.3, [mp.mpf(c) for c in x])]
            np.testing.assert_allclose(
                reduced_rhs(paper_body, 1.3, x), expected, rtol=1e-13, atol=1e-14
            )


def test_invariant_measure(paper_body, rng):
    """div(rho * field) = 0 at random points (mpmath derivatives at 30 digits)."""
    with mp.workdps(30):
        for x in random_points(rng, 10):
            x = [mp.mpf(c) for c in x]
            div = 0
            for i in range(4):

                def component(t, i=i, x=x):
                    z = list(x)
                    z[i] = t
                    return plain.rho(paper_body, z[0]) * plain.field(paper_body, 1.3, z)[i]

                div += mp.diff(component, x[i])
            assert abs(div) < 1e-20
        # and the density matters: without rho the divergence does not vanish
        x = [mp.mpf(c) for c in (0.4, 0.3, -0.7, 0.9)]
        div0 = sum(
            mp.diff(lambda t, i=i: plain.field(paper_body, 1.3, x[:i] + [t] + x[i + 1 :])[i], x[i])
            for i in range(4)
        )
        assert abs(div0) > 1e-3


def test_full_simulation_follows_the_reduced_system():
    traj = simulate(
        load_scenario(EXAMPLES / "paper.toml"), t_end=30.0, rtol=1e-12, atol=1e-14, samples=301
    )
    red = reduce_state(traj.y)
    x_full = np.array([red["gamma3"], red["v_tau"], red["w_n"], red["w_tau"]])
    M3 = float(reduced_integrals(traj.body, traj.y[0])["M3"])
    x_red = integrate_reduced(traj.body, M3, x_full[:, 0], traj.t)
    np.testing.assert_allclose(x_red, x_full, rtol=0, atol=1e-9)
    ints = reduced_integrals_of(traj.body, M3, x_red)
    full = reduced_integrals(traj.body, traj.y)
    for name in ("h", "C1", "C2"):
        assert np.ptp(ints[name]) < 1e-11, name
        assert ints[name][0] == pytest.approx(float(full[name][0]), abs=1e-14)


def test_level_set_is_the_reduced_system_on_a_level(paper_body):
    """LevelSet's one-degree-of-freedom description (``P``, ``w_n``, ``flow``, ``energy``,
    ``w_tau``) is eq. (3.3) restricted to ``(M3, C1, C2)``: the integrals of its states are the
    level's, and its flow is ``reduced_rhs`` there (``gamma3 = cos theta``, ``theta' = -w_tau``)."""
    level = LevelSet(paper_body, M3=1.0, C1=0.5, C2=-2.0)
    for theta in (0.4, 1.1, 2.0, 2.7):
        h = float(level.U(theta)) + 0.8
        w_tau = float(level.w_tau(theta, h))
        assert float(level.energy(theta, w_tau)) == pytest.approx(h, rel=1e-14)
        x = np.array([np.cos(theta), level.v_tau(theta), level.w_n(theta), -w_tau])
        ints = reduced_integrals_of(paper_body, level.M3, x)
        assert float(ints["C1"]) == pytest.approx(level.C1, rel=1e-13)
        assert float(ints["C2"]) == pytest.approx(level.C2, rel=1e-13)
        assert float(ints["h"]) == pytest.approx(h, rel=1e-13)
        theta_dot, w_tau_dot = level.flow(theta, -w_tau)
        g3_dot, _, _, w_tau_dot_33 = reduced_rhs(paper_body, level.M3, x)
        assert -np.sin(theta) * theta_dot == pytest.approx(g3_dot, rel=1e-13)
        assert w_tau_dot == pytest.approx(w_tau_dot_33, rel=1e-12)


#: The closed-form normal force against the compiled right-hand side and reaction: round-off.
NORMAL_FORCE_RTOL = 1e-11


def test_normal_force_in_closed_form_matches_the_compiled_reaction(rng):
    """N = m (g + a3 gamma3'') from the reduced field, at random points of two level sets'
    phase planes, against the meridian model's compiled right-hand side and reaction at the
    full states there (rollingtop.reduction.states_on_level, itself held to state_from_level)."""
    from rollingtop.reduction import state_from_level, states_on_level
    from rollingtop.reduction.system import normal_force

    from ..kernels import contact_forces

    body = load_scenario(EXAMPLES / "fig5.toml").body
    for M3, C1, C2 in [(1.0, 0.5, -2.0), (-0.7, 0.2, 1.3)]:
        level = LevelSet(body, M3, C1, C2)
        g3 = rng.uniform(-0.95, 0.95, size=40)
        w = rng.normal(size=40)
        Y = states_on_level(level, g3, w)
        for k in range(3):  # the vectorised states are state_from_level's
            h = float(level.energy(np.arccos(g3[k]), w[k]))
            y = state_from_level(level, h, float(g3[k]), branch=1 if w[k] >= 0 else -1)
            np.testing.assert_allclose(Y[k], y, rtol=0, atol=1e-13)
        theta = np.arccos(g3)
        N = normal_force(body, M3, np.array([g3, level.v_tau(theta), level.w_n(theta), w]))
        out = np.empty((len(Y), 2))
        contact_forces(get_model("meridian").code, body.params, np.ascontiguousarray(Y), out)
        np.testing.assert_allclose(N, out[:, 0], rtol=NORMAL_FORCE_RTOL, atol=1e-13)
        assert np.ptp(N) > 0.1  # the points differ: the comparison is not of constants
