"""The compiled right-hand side against the plain NumPy reference, and integration vs solve_ivp."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import SphericalTop, initial_state, simulate
from rollingtop.contact import KERNELS, get_model, kernel_by_code
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario
from tests import kernels as _kernel

from ..conftest import FREE, GAMMA0, OMEGA0, PAPER_BODY, admissible_omega
from . import reference

MODELS = ("meridian", "smooth", "rough", "parallel", "rubber")
RHS_RTOL = 1e-12  # relative agreement of the two right-hand sides (round-off of an 8x8 solve)
#: Rate of the residuals by central difference (h = 1e-6: truncation ~h^2, round-off ~eps/h),
#: relative to the largest component of the right-hand side (measured: at most 3e-10).
RATE_TOL = 1e-8
FINAL_STATE_TOL = 1e-8  # final-state agreement after t = 20 (both integrate at rtol 1e-12)


def random_state(rng, body, model):
    gamma = rng.normal(size=3)
    gamma /= np.linalg.norm(gamma)
    free = {
        "meridian": {"v_tau": rng.normal()},
        "smooth": {"v_horizontal": rng.normal(size=2)},
        "rough": {},
        "parallel": {"v_nu": rng.normal()},
        "rubber": {},
        "oblique": {"v_slip": rng.normal()},
    }[model]
    a = rng.normal(size=3)
    alpha = a - (a @ gamma) * gamma
    alpha /= np.linalg.norm(alpha)
    return initial_state(
        body,
        model,
        gamma=gamma,
        omega=admissible_omega(get_model(model), gamma, rng.normal(size=3) * 2),
        alpha=alpha,
        position=rng.normal(size=2),
        free=free,
    )


def random_body(rng):
    I1, I2 = rng.uniform(0.2, 1.0, size=2)
    I3 = rng.uniform(abs(I1 - I2) + 0.05, I1 + I2 - 0.05)
    R = rng.uniform(0.5, 2.0)
    return SphericalTop(
        R=R,
        m=rng.uniform(0.5, 3),
        g=rng.uniform(0, 10),
        a3=rng.uniform(-0.9, 0.9) * R,
        I1=I1,
        I3=I3,
        I2=I2,
    )


@pytest.mark.parametrize("model", MODELS)
def test_rhs_matches_reference_at_random_states(model, rng):
    dy = np.empty(18)
    ws = _kernel.new_workspace()
    code = get_model(model).code
    for _ in range(50):
        body = random_body(rng)
        y = random_state(rng, body, model)
        nc = _kernel.rhs(code, body.params, y, dy, ws)
        expected, _ = reference.rhs(model, body.params, y)
        scale = np.max(np.abs(expected))
        np.testing.assert_allclose(dy[:17], expected[:17], rtol=0, atol=RHS_RTOL * 10 * scale)
        if get_model(model).vertical.carries_direction:  # psi_nu' is the axis azimuth's rate
            a3, b3, a3d, b3d = y[8], y[11], expected[8], expected[11]
            assert dy[17] == pytest.approx((a3 * b3d - b3 * a3d) / (a3**2 + b3**2), rel=1e-12)
        else:
            assert dy[17] == 0.0
        N, T = _kernel.reaction(nc, y, ws)
        N_ref, T_ref = reference.reactions(model, body.params, y)
        assert N == pytest.approx(N_ref, rel=1e-10, abs=1e-10 * abs(scale))
        assert T == pytest.approx(T_ref, rel=1e-9, abs=1e-10 * abs(scale))


@pytest.mark.parametrize("model", MODELS)
def test_rhs_keeps_constraints_to_first_order(model, rng):
    """The compiled right-hand side keeps the constraints: along it, the time derivative of the
    reference's residuals ``(vp, d_k)`` vanishes (central difference); along the kinematics alone
    (no acceleration) it does not, so the check sees a wrong acceleration."""
    code = get_model(model).code
    dy = np.empty(18)
    ws = _kernel.new_workspace()
    for _ in range(20):
        body = random_body(rng)
        y = random_state(rng, body, model)
        _kernel.rhs(code, body.params, y, dy, ws)
        scale = np.max(np.abs(dy))
        # the state starts on the constraints (the reference's own residuals)
        assert np.max(np.abs(reference.residuals(model, body.params, y))) < RHS_RTOL * scale
        assert np.max(np.abs(residual_rate(model, body.params, y, dy))) < RATE_TOL * scale
        coasting = np.concatenate([np.zeros(6), dy[6:]])
        rate = residual_rate(model, body.params, y, coasting)
        assert np.max(np.abs(rate)) > 1e3 * RATE_TOL * scale  # measured: > 6e-4 * scale


def residual_rate(model, p, y, dy, h=1e-6):
    """Central difference of the reference's residuals along ``dy``."""
    plus = reference.residuals(model, p, y + h * dy)
    minus = reference.residuals(model, p, y - h * dy)
    return (plus - minus) / (2 * h)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("I2", [None, pytest.param(0.4, marks=pytest.mark.slow)])
def test_final_state_matches_solve_ivp(model, I2):
    """Package (compiled DOP853 + projection) vs solve_ivp(DOP853) on the NumPy reference."""
    body = SphericalTop(**PAPER_BODY, I2=I2)
    sc = Scenario(
        body,
        model,
        InitialConditions(
            gamma=GAMMA0, omega=admissible_omega(get_model(model), GAMMA0, OMEGA0), free=FREE[model]
        ),
        IntegrationOptions(t_end=20.0, rtol=1e-12, atol=1e-14, samples=5),
    )
    traj = simulate(sc)
    sol = solve_ivp(
        lambda t, y: reference.rhs(model, body.params, y)[0],
        (0.0, 20.0),
        sc.y0,
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        t_eval=traj.t,
    )
    assert sol.success
    np.testing.assert_allclose(traj.y[:, :17], sol.y.T[:, :17], rtol=0, atol=FINAL_STATE_TOL)
    # the reference reactions at the package's samples
    for y, N, T in zip(traj.y, traj.normal_force, traj.tangential_force, strict=True):
        N_ref, T_ref = reference.reactions(model, body.params, y)
        assert N == pytest.approx(N_ref, rel=1e-10)
        assert T == pytest.approx(T_ref, rel=1e-9, abs=1e-12)


def _off_manifold_state(rng, code):
    """A state off the constraints: random velocity, nearly orthonormal frame, random psi_nu."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    y = np.empty(18)
    y[0:6] = rng.normal(size=6)
    y[6:15] = (q.T + 1e-6 * rng.normal(size=(3, 3))).ravel()  # rows alpha, beta, gamma
    y[15:17] = rng.normal(size=2)
    y[17] = rng.uniform(-np.pi, np.pi)
    return y


@pytest.mark.parametrize(
    "code", [k.code for k in KERNELS], ids=[f"{k.model}-{k.variant}" for k in KERNELS]
)
def test_closed_forms_equal_the_general_row_path(code, rng):
    """Every kernel's closed-form right-hand side, reaction and velocity projection against the
    general path (the model's rows and a Cholesky solve), also off the constraint manifold and in
    the pole variants with a carried psi_nu. (A model with its own inertia has no general path:
    ``tests/contact/test_shell_rotor.py``.)"""
    if get_model(kernel_by_code(code).model).own_inertia:
        pytest.skip("no general row path for a model with its own inertia")
    dy, dy_rows = np.empty(18), np.empty(18)
    ws = _kernel.new_workspace()
    for _ in range(30):
        p = random_body(rng).params
        y = _off_manifold_state(rng, code)
        nc = _kernel.rhs(code, p, y, dy, ws)
        N, T = _kernel.reaction(nc, y, ws)
        nc_rows = _kernel.rhs_rows(code, p, y, dy_rows, ws)
        N_rows, T_rows = _kernel.reaction(nc_rows, y, ws)
        scale = np.max(np.abs(dy_rows))
        assert nc == nc_rows
        np.testing.assert_allclose(dy, dy_rows, rtol=0, atol=RHS_RTOL * 10 * scale)
        assert N == pytest.approx(N_rows, rel=1e-10, abs=RHS_RTOL * 10 * scale)
        assert T == pytest.approx(T_rows, rel=1e-9, abs=RHS_RTOL * 10 * scale)
        closed = y.copy()
        _kernel.project(code, p, closed, ws)
        rows = np.concatenate([y[:6], closed[6:]])  # the frame step is shared; only u differs
        _kernel.project_velocity_rows(code, p, rows, ws)
        np.testing.assert_allclose(closed, rows, rtol=0, atol=RHS_RTOL * 10 * np.abs(y[:6]).max())
