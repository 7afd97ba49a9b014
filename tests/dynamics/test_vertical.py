"""Vertical starts (the sleeping top): accepted by every model; under the meridian model started
in the pole variant that carries ``nu``; a spin above the threshold stays vertical, one below
falls.

The threshold is derived here independently of the package, from docs/model.md's effective potential
(section "One degree of freedom") written in the signed nutation angle: on the pole level of a
vertical start (``C1 = +-M3``; ``v_tau = 0`` gives ``C2 = I1 v_tau - M3 a3 theta_pole``)
``U'(pole) = 0`` and the sleeping top is stable iff ``U''(pole) > 0``, which sympy reduces to

    U''(pole) = M3^2 rho_pole / (4 I1^2) - m g a3 gamma3,   rho_pole = I1 + m (R + a3 gamma3)^2

(``gamma3 = +1``: south, ``-1``: north; ``a3 gamma3`` is the height of the CoM above the centre,
``R + a3 gamma3`` the distance from the CoM to the contact point). Critical spin, when the CoM is
above the centre (``a3 gamma3 > 0``): ``M3_c = 2 I1 sqrt(m g a3 gamma3 / rho_pole)``; paper body
(``R = m = g = 1, a3 = 0.1, I1 = 0.3, I3 = 0.5``), axis up: ``M3_c = 0.1544055``,
``w3_c = 0.308811`` (the smooth plane's ``sqrt(4 I1 m g a3) / I3 = 0.692820`` is 2.24 times
higher). With the CoM below the centre it is stable at any spin.
"""

import math

import numpy as np
import pytest
import sympy as sp

from rollingtop import InitialStateError, SphericalTop, initial_state
from rollingtop.contact import get_model, meridian
from rollingtop.dynamics import integrals
from rollingtop.dynamics.integrals import reduced_components
from rollingtop.dynamics.state import constraint_residuals, project_state
from rollingtop.integrate import integrate
from rollingtop.reduction import LevelSet
from tests import kernels as _kernel

from ..conftest import PAPER_BODY

#: Kernel codes of the meridian model's pole variants.
SOUTH_CODE, NORTH_CODE = (k.code for k in meridian.MODEL.kernels[1:])

EXACT = 1e-14  # round-off level for constructed states
D2U_RTOL = 1e-9  # closed form against LevelSet.d2U (complex step: exact to round-off)
SEED = 1e-6  # horizontal angular velocity that seeds the departure from the vertical
AMPLITUDE_RTOL = 0.02  # max (1 - |gamma3|) against the linear theory eps^2 rho / (2 U'')
DRIFT = 1e-12  # integrals over the stable runs, absolute (all are O(1))
#: F6 near the pole, and every integral of a fall (which starts with a long stay near the
#: pole, moving radially, where the carried direction is not re-synchronised with the tilt)
NEAR_POLE_DRIFT = 3e-8
RTOL, ATOL = 1e-11, 1e-13

LOW_COM = dict(PAPER_BODY, a3=-0.1)  # the paper's body with the CoM below the centre


def u2_closed_form(b, M3, gamma3):
    """``U''`` at the pole ``gamma3 = +-1`` of its pole level (module docstring)."""
    rho = b.I1 + b.m * (b.R + b.a3 * gamma3) ** 2
    return M3**2 * rho / (4 * b.I1**2) - b.m * b.g * b.a3 * gamma3


def critical_w3(b, gamma3):
    """Critical ``w3`` of the sleeping top at the pole ``gamma3`` (CoM above the centre)."""
    rho = b.I1 + b.m * (b.R + b.a3 * gamma3) ** 2
    return 2 * b.I1 * math.sqrt(b.m * b.g * b.a3 * gamma3 / rho) / b.I3


@pytest.mark.slow
def test_threshold_derived_with_sympy():
    """U''(pole) from docs/model.md's U by sympy series, against the closed form (both poles)."""
    th, phi = sp.symbols("theta phi", real=True)
    M3, I1, m, g, R = sp.symbols("M3 I1 m g R", positive=True)
    a3 = sp.symbols("a3", real=True)
    for gamma3, pole in ((1, 0), (-1, sp.pi)):
        C1 = gamma3 * M3
        C2 = -M3 * a3 * pole  # F6 at the pole with v_tau = 0, w_n = 0, s = 0, theta = pole
        t = pole + phi
        c, s = sp.cos(t), sp.sin(t)
        P = (R * (M3 - C1 * c) + a3 * (M3 * c - C1)) / s + C2 + M3 * a3 * t
        U = (C1 - M3 * c) ** 2 / (2 * I1 * s**2) + m * P**2 / (2 * I1**2) + m * g * a3 * c
        series = sp.series(U, phi, 0, 3).removeO()
        assert sp.simplify(series.coeff(phi, 1)) == 0  # U'(pole) = 0: an equilibrium
        U2 = sp.simplify(2 * series.coeff(phi, 2))
        rho = I1 + m * (R + a3 * gamma3) ** 2
        assert sp.simplify(U2 - (M3**2 * rho / (4 * I1**2) - m * g * a3 * gamma3)) == 0
        # the critical spin, CoM above the centre (a3 gamma3 = 0.1), against the closed form
        b = SphericalTop(**dict(PAPER_BODY, a3=0.1 * gamma3))
        vals = {I1: b.I1, m: b.m, g: b.g, R: b.R, a3: b.a3}
        roots = [complex(r.subs(vals)) for r in sp.solve(U2, M3)]
        (root,) = [r.real for r in roots if abs(r.imag) < 1e-15 and r.real > 0]
        assert root == pytest.approx(critical_w3(b, gamma3) * b.I3, rel=1e-14)
    # the numbers quoted in the module docstring
    b = SphericalTop(**PAPER_BODY)
    assert critical_w3(b, 1) * b.I3 == pytest.approx(0.1544055, abs=1e-7)
    assert critical_w3(b, 1) == pytest.approx(0.308811, abs=1e-6)


@pytest.mark.parametrize("gamma3", [1.0, -1.0])
@pytest.mark.parametrize("M3", [0.05, 0.2, 1.0])
def test_threshold_against_level_set_d2U(paper_body, gamma3, M3):
    """Cross-check: the reduction's numerical U'' on the pole level of a vertical start."""
    C2 = 0.0 if gamma3 > 0 else -math.pi * paper_body.a3 * M3
    level = LevelSet(paper_body, M3, gamma3 * M3, C2)
    theta = 0.0 if gamma3 > 0 else math.pi
    assert float(level.dU(theta)) == pytest.approx(0.0, abs=1e-14)
    assert float(level.d2U(theta)) == pytest.approx(u2_closed_form(paper_body, M3, gamma3),
                                                    rel=D2U_RTOL)  # fmt: skip


def residuals(body, code, y):
    """Constraint residuals ``J_k u`` under kernel ``code`` (a pole variant carries nu)."""
    J, bias, dirs, _, _ = _kernel.new_workspace()
    nc = _kernel.constraint_rows(code, body.params, np.asarray(y, dtype=float), J, bias, dirs)
    return J[:nc] @ y[:6]


def sleeping_run(body, gamma3, w3, t_end, seed=SEED, samples=501):
    y0 = initial_state(body, "meridian", gamma=(0, 0, gamma3), omega=(seed, 0.0, w3))
    code = meridian.MODEL.kernel_code(body, y0)
    res = integrate(code, body.params, y0, np.linspace(0, t_end, samples), rtol=RTOL, atol=ATOL)
    return y0, code, res.y


def assert_integrals_conserved(body, Y, code, drift=DRIFT):
    pole = {SOUTH_CODE: "south", NORTH_CODE: "north"}[code]
    names = meridian.MODEL.integrals(True)
    for name, values in integrals.evaluate(body, Y, names, pole).items():
        assert np.ptp(values) < (NEAR_POLE_DRIFT if name == "F6" else drift), name


@pytest.mark.parametrize(
    ("body", "gamma3"),
    [(PAPER_BODY, 1.0), (LOW_COM, -1.0)],
    ids=["a3>0 axis up", "a3<0 axis down"],
)
def test_fast_spin_stays_vertical(body, gamma3):
    """1.5x the threshold with the CoM on top: the axis stays within 1e-9 of the vertical, and
    the small nutation has the amplitude of the linear theory, theta_max = eps sqrt(rho/U'')."""
    b = SphericalTop(**body)
    w3 = 1.5 * critical_w3(b, gamma3)
    y0, code, Y = sleeping_run(b, gamma3, w3, t_end=50.0)
    assert code == (SOUTH_CODE if gamma3 > 0 else NORTH_CODE)
    dev = 1 - gamma3 * Y[:, 14]
    assert dev.max() < 1e-9
    rho = b.I1 + b.m * (b.R + b.a3 * gamma3) ** 2
    expected = SEED**2 * rho / (2 * u2_closed_form(b, b.I3 * w3, gamma3))
    assert dev.max() == pytest.approx(expected, rel=AMPLITUDE_RTOL)
    assert_integrals_conserved(b, Y, code)


@pytest.mark.parametrize(
    ("body", "gamma3"),
    [(PAPER_BODY, 1.0), (LOW_COM, -1.0)],
    ids=["a3>0 axis up", "a3<0 axis down"],
)
def test_slow_spin_falls(body, gamma3):
    """0.5x the threshold: the seed grows like exp(lambda t), lambda = sqrt(-U''/rho), and the top
    falls (gamma3 far from the pole); the fall happens when the linear theory says."""
    b = SphericalTop(**body)
    w3 = 0.5 * critical_w3(b, gamma3)
    seed = 1e-4  # larger than SEED so that the fall happens within the run
    y0, code, Y = sleeping_run(b, gamma3, w3, t_end=50.0, seed=seed, samples=5001)
    g = gamma3 * Y[:, 14]
    assert g.min() < 0.9
    rho = b.I1 + b.m * (b.R + b.a3 * gamma3) ** 2
    lam = math.sqrt(-u2_closed_form(b, b.I3 * w3, gamma3) / rho)
    # theta(t) = (eps / lambda) sinh(lambda t) while small: 1 - |gamma3| reaches 1e-4 at
    t_small = math.asinh(math.sqrt(2e-4) * lam / seed) / lam
    t = np.linspace(0, 50.0, 5001)
    t_sim = t[np.argmax(1 - g > 1e-4)]
    assert t_sim == pytest.approx(t_small, abs=0.02)
    # integrals until the first fall (the lowest point), before the motion comes back to the pole
    first = np.argmax(g < 0.9)
    assert_integrals_conserved(b, Y[:first], code, drift=NEAR_POLE_DRIFT)


@pytest.mark.parametrize(
    ("body", "gamma3"),
    [(PAPER_BODY, -1.0), (LOW_COM, 1.0)],
    ids=["a3>0 axis down", "a3<0 axis up"],
)
@pytest.mark.parametrize("w3", [0.0, 0.1, 2.0])
def test_low_centre_of_mass_is_stable_at_any_spin(body, gamma3, w3):
    """CoM below the centre: U''(pole) > 0 for every spin; the nutation has the linear amplitude."""
    b = SphericalTop(**body)
    y0, code, Y = sleeping_run(b, gamma3, w3, t_end=50.0)
    dev = 1 - gamma3 * Y[:, 14]
    rho = b.I1 + b.m * (b.R + b.a3 * gamma3) ** 2
    expected = SEED**2 * rho / (2 * u2_closed_form(b, b.I3 * w3, gamma3))
    assert dev.max() == pytest.approx(expected, rel=AMPLITUDE_RTOL)


@pytest.mark.parametrize("factor", [1.05, 1.5])
def test_fast_spin_stays_vertical_long_run(paper_body, factor):
    """Between the meridian threshold and the smooth-plane one (M3^2 < 4 I1 m g a3) too: the
    carried direction is re-synchronised with the tilt where the axis precesses near the pole
    (meridian.RESYNC_ANGLE), so round-off in the tilt's azimuth cannot grow (before that, the
    axis left the vertical after t ~ 70 at 1.5x)."""
    w3 = factor * critical_w3(paper_body, 1.0)
    assert paper_body.I3 * w3 < math.sqrt(4 * paper_body.I1 * paper_body.m * paper_body.a3)
    _, code, Y = sleeping_run(paper_body, 1.0, w3, t_end=300.0, samples=3001)
    assert (1 - Y[:, 14]).max() < 1e-9


def test_spin_above_both_thresholds_stays_vertical_long(paper_body):
    """Above the smooth-plane threshold too (w3 > sqrt(4 I1 m g a3) / I3) the carried variant
    holds the sleeping top for long runs."""
    w3 = 1.2 * math.sqrt(4 * paper_body.I1 * paper_body.m * paper_body.g * paper_body.a3)
    w3 /= paper_body.I3
    _, code, Y = sleeping_run(paper_body, 1.0, w3, t_end=300.0, samples=3001)
    assert (1 - Y[:, 14]).max() < 1e-9
    assert_integrals_conserved(paper_body, Y, code)


def test_exact_sleeping_top_is_an_equilibrium(paper_body):
    """No seed: the state is exactly stationary in the pole variant, even below the threshold."""
    _, code, Y = sleeping_run(paper_body, 1.0, 0.1, t_end=20.0, seed=0.0)
    assert code == SOUTH_CODE
    assert np.all(Y[:, 12:15] == (0.0, 0.0, 1.0))


# ---- construction ---------------------------------------------------------------------------
@pytest.mark.parametrize("gamma3", [1.0, -1.0])
@pytest.mark.parametrize("omega", [(0.0, 0.0, 5.0), (0.3, -0.4, 2.0), (0.3, -0.4, 0.0)])
def test_vertical_state_is_on_a_pole_level(paper_body, gamma3, omega):
    y = initial_state(paper_body, "meridian", gamma=(0, 0, gamma3), omega=omega,
                      free={"v_tau": 0.2})  # fmt: skip
    # set exactly vertical (the pole variant is chosen on gamma1 = gamma2 = 0): exact
    assert tuple(y[12:15]) == (0.0, 0.0, gamma3)
    code = meridian.MODEL.kernel_code(paper_body, y)
    if omega[2] == 0.0:  # no spin: both poles at once, the south variant
        assert code == SOUTH_CODE
    else:
        assert code == (SOUTH_CODE if gamma3 > 0 else NORTH_CODE)
    assert np.max(np.abs(residuals(paper_body, code, y))) < EXACT
    np.testing.assert_allclose(y[3:6], omega, rtol=0, atol=EXACT)  # after the projection
    c = reduced_components(y)
    assert c["v_tau"] == pytest.approx(0.2, abs=EXACT)
    assert c["w_n"] == pytest.approx(0.0, abs=EXACT)  # nu across the horizontal part of w
    assert c["s"] == 0.0  # of the exact vertical
    if omega[:2] == (0.0, 0.0):  # the defaults, set: exact
        assert y[17] == 0.0  # nu = alpha: the fixed x axis
        np.testing.assert_array_equal(y[6:9], (1.0, 0.0, 0.0))  # default alpha: e1


@pytest.mark.parametrize("gamma3", [1.0, -1.0])
def test_nu_is_the_direction_in_which_the_axis_leaves(paper_body, gamma3):
    """After the start the geometric meridian (e3 - gamma3 gamma)/s is the carried nu."""
    y0 = initial_state(paper_body, "meridian", gamma=(0, 0, gamma3), omega=(0.3, -0.4, 1.0),
                       alpha=(0.6, 0.8, 0.0))  # fmt: skip
    code = meridian.MODEL.kernel_code(paper_body, y0)
    Y = integrate(code, paper_body.params, y0, np.array([0.0, 1e-3, 0.3]), rtol=RTOL,
                  atol=ATOL).y  # fmt: skip
    for y in Y[1:]:
        s = math.hypot(y[8], y[11])
        assert s > 1e-4
        psi = math.atan2(y[11], y[8])  # azimuth of the axis' horizontal projection
        assert math.cos(y[17] - psi) == pytest.approx(1.0, abs=1e-12)  # same side: s > 0


def test_alpha_sets_nu_of_a_pure_spin(paper_body):
    alpha = (0.6, -0.8, 0.0)
    y = initial_state(paper_body, "meridian", gamma=(0, 0, 1), omega=(0, 0, 1), alpha=alpha)
    nu = math.cos(y[17]) * y[6:9] + math.sin(y[17]) * y[9:12]
    np.testing.assert_allclose(nu, alpha, atol=EXACT)


def test_axis_within_pole_tolerance_is_set_vertical(paper_body):
    """Within POLE_TOLERANCE of the vertical the axis counts as vertical (meridian model only)."""
    tilt = 0.5 * meridian.POLE_TOLERANCE
    gamma = (tilt, 0.0, math.sqrt(1 - tilt**2))
    alpha = (math.sqrt(1 - tilt**2), 0.0, -tilt)
    y = initial_state(paper_body, "meridian", gamma=gamma, omega=(0, 0.2, 1.0), alpha=alpha)
    assert tuple(y[12:15]) == (0.0, 0.0, 1.0)  # set exactly vertical, alpha re-orthogonalised
    assert y[8] == 0.0 and y[11] == 0.0
    assert meridian.MODEL.kernel_code(paper_body, y) == SOUTH_CODE
    # beyond the tolerance: kept as given
    tilt = 2 * meridian.POLE_TOLERANCE
    gamma = (tilt, 0.0, math.sqrt(1 - tilt**2))
    y = initial_state(paper_body, "meridian", gamma=gamma, omega=(0, 0, 1.0))
    assert y[12] == pytest.approx(tilt, rel=1e-12)
    # other models keep a near-vertical axis as given
    y = initial_state(paper_body, "rough", gamma=(1e-9, 0, 1), omega=(0, 0, 1.0))
    assert y[12] == pytest.approx(1e-9, rel=1e-6)


def test_project_state_at_the_vertical(paper_body):
    """A smooth-plane vertical state projected onto the meridian model: nu across w's horizontal
    part, constraints exact, the pole variant chosen."""
    y = initial_state(paper_body, "smooth", gamma=(0, 0, 1), omega=(0.3, 0.1, 2.0),
                      free={"v_horizontal": (0.2, -0.1)})  # fmt: skip
    p = project_state(paper_body, "meridian", y)
    code = meridian.MODEL.kernel_code(paper_body, p)
    assert code == SOUTH_CODE
    assert np.max(np.abs(residuals(paper_body, code, p))) < EXACT
    assert reduced_components(p)["w_n"] == pytest.approx(0.0, abs=EXACT)


def test_vertical_refused_for_an_asymmetric_body():
    b = SphericalTop(**dict(PAPER_BODY, I2=0.35))
    with pytest.raises(InitialStateError, match="not dynamically symmetric"):
        initial_state(b, "meridian", gamma=(0, 0, 1), omega=(0, 0, 1))
    initial_state(b, "meridian", gamma=(0, 0.6, 0.8), omega=(0, 0, 1))  # tilted: fine


# ---- the other models ------------------------------------------------------------------------
@pytest.mark.parametrize("model", ["smooth", "rough"])
@pytest.mark.parametrize("gamma3", [1.0, -1.0])
def test_other_models_accept_a_vertical_start(paper_body, model, gamma3):
    """Smooth and rough planes are regular at the vertical: a spin of twice the smooth-plane
    threshold (the classical M3^2 > 4 I1 m g a3, CoM kept on the vertical line) keeps the axis
    up under both, no spin falls from the high-CoM pole and stays at the low one."""
    free = {"smooth": {"v_horizontal": (0.0, 0.0)}, "rough": {}}[model]
    fast = 2.0 * math.sqrt(4 * paper_body.I1 * paper_body.m * paper_body.g * paper_body.a3)
    fast /= paper_body.I3
    for w3, stays in ((fast, True), (0.0, gamma3 < 0)):
        y0 = initial_state(paper_body, model, gamma=(0, 0, gamma3), omega=(SEED, 0, w3),
                           free=free)  # fmt: skip
        code = get_model(model).kernel_code(paper_body, y0)
        assert np.max(np.abs(constraint_residuals(paper_body, model, y0))) < EXACT
        Y = integrate(code, paper_body.params, y0, np.linspace(0, 60, 601), rtol=RTOL,
                      atol=ATOL).y  # fmt: skip
        dev = 1 - gamma3 * Y[:, 14]
        assert (dev.max() < 1e-9) if stays else (dev.max() > 0.1), (w3, dev.max())
