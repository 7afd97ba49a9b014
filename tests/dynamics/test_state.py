"""Initial states: built constraint-consistent, or refused with an error naming the problem."""

import numpy as np
import pytest

from rollingtop import InitialStateError, initial_state
from rollingtop.dynamics.integrals import reduced_components
from rollingtop.dynamics.state import constraint_residuals

from ..conftest import GAMMA0, OMEGA0

EXACT = 1e-14  # round-off level for constructed states


@pytest.mark.parametrize(
    ("model", "free"),
    [("meridian", {"v_tau": 0.25}), ("smooth", {"v_horizontal": (0.3, -0.2)}), ("rough", {})],
)
def test_constructed_state_satisfies_constraints(paper_body, model, free):
    y = initial_state(paper_body, model, gamma=GAMMA0, omega=OMEGA0, free=free, position=(1, 2))
    assert np.max(np.abs(constraint_residuals(paper_body, model, y))) < EXACT
    np.testing.assert_allclose(y[3:6], OMEGA0, atol=EXACT)
    np.testing.assert_allclose(y[12:15], GAMMA0, atol=EXACT)
    np.testing.assert_allclose(y[15:17], (1, 2))
    Q = y[6:15].reshape(3, 3)
    np.testing.assert_allclose(Q @ Q.T, np.eye(3), atol=EXACT)
    assert np.linalg.det(Q) == pytest.approx(1.0)  # right-handed: beta = gamma x alpha
    # contact-point velocity vp = v + w x r, checked directly
    r = -paper_body.R * y[12:15] - np.array([0, 0, paper_body.a3])
    vp = y[0:3] + np.cross(y[3:6], r)
    assert abs(vp @ y[12:15]) < EXACT
    if model == "meridian":
        assert reduced_components(y)["v_tau"] == pytest.approx(0.25, abs=EXACT)
    if model == "smooth":
        np.testing.assert_allclose([y[0:3] @ y[6:9], y[0:3] @ y[9:12]], (0.3, -0.2), atol=EXACT)
    if model == "rough":
        np.testing.assert_allclose(vp, 0, atol=EXACT)


def test_default_alpha_points_along_the_axis_projection(paper_body):
    """Default: fixed x axis along the axis projection, so psi = atan2(beta3, alpha3) = 0."""
    y = initial_state(paper_body, "meridian", gamma=GAMMA0, omega=OMEGA0)
    alpha, beta = y[6:9], y[9:12]
    assert np.arctan2(beta[2], alpha[2]) == pytest.approx(0.0, abs=EXACT)
    assert alpha[2] > 0


def test_full_velocity_accepted_when_consistent(paper_body):
    y = initial_state(paper_body, "meridian", gamma=GAMMA0, omega=OMEGA0, free={"v_tau": 0.4})
    again = initial_state(paper_body, "meridian", gamma=GAMMA0, omega=OMEGA0, v=y[0:3] + 1e-11)
    np.testing.assert_allclose(again, y, atol=1e-10)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (dict(gamma=(0, 0.6, 0.81)), "gamma .* is not a unit vector"),
        (dict(gamma=(0, 0.6)), "gamma .* must be a list of 3 numbers"),
        (dict(omega=(0, "x", 1)), "omega .* must be a list of 3 numbers"),
        (dict(omega=(0, float("nan"), 1)), "omega .* must be finite"),
        (dict(alpha=(1, 0, 0.001)), "alpha .* is not a unit vector"),
        (dict(alpha=(0.8, 0.6, 0.0)), "alpha .* is not orthogonal to gamma"),
        (dict(free={"v_horizontal": (1, 0)}), "v_horizontal is not a free velocity component"),
        (dict(v=(0.0, 0.0, 0.0)), r"violates the constraint contact \(vp, gamma\) = 0"),
        (dict(v=(-0.25, -0.63, 0.42 + 1e-3)), r"violates the constraint contact"),
        (dict(v=(-0.25, -0.63, 0.42), free={"v_tau": 1.0}), "either v or the free velocity"),
        (dict(free={"v_tau": "fast"}), "v_tau = 'fast' must be a number"),
    ],
)
def test_bad_initial_conditions(paper_body, kwargs, message):
    args = dict(gamma=GAMMA0, omega=OMEGA0) | kwargs
    with pytest.raises(InitialStateError, match=message):
        initial_state(paper_body, "meridian", **args)


def test_velocity_violating_only_the_meridian_row(paper_body):
    """A velocity consistent with contact but slipping along nu names the meridian constraint."""
    y = initial_state(
        paper_body, "smooth", gamma=GAMMA0, omega=OMEGA0, free={"v_horizontal": (0.5, 0.5)}
    )
    with pytest.raises(InitialStateError, match=r"no slip along the axis projection \(vp, nu\)"):
        initial_state(paper_body, "meridian", gamma=GAMMA0, omega=OMEGA0, v=y[0:3])


def test_rough_has_no_free_components(paper_body):
    with pytest.raises(InitialStateError, match="it has: none"):
        initial_state(paper_body, "rough", gamma=GAMMA0, omega=OMEGA0, free={"v_tau": 0.1})


def test_vertical_axis_allowed_off_the_meridian_model(paper_body):
    y = initial_state(paper_body, "rough", gamma=(0, 0, 1), omega=(0.1, 0, 3))
    assert np.max(np.abs(constraint_residuals(paper_body, "rough", y))) < EXACT
