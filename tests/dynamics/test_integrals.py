"""First integrals: conserved where docs/model.md says, and the models differ where physics says."""

import math

import numpy as np
import pytest

from rollingtop import SphericalTop, get_model, simulate
from rollingtop.dynamics.integrals import INTEGRALS, evaluate, natural_scales
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario

from ..conftest import FREE, GAMMA0, OMEGA0, PAPER_BODY, admissible_omega

#: Issue 2: paper's body, t = 1000, rtol 1e-12: relative drift <= 1e-10, residuals <= 1e-12.
DRIFT_REL = 1e-10
RESIDUAL = 1e-12
#: An integral counts as *not* conserved when it varies by more than this (relative).
VARIES = 1e-3


def run(model, *, t_end=1000.0, I2=None, rtol=1e-12, atol=1e-14, samples=2001):
    body = SphericalTop(**PAPER_BODY, I2=I2)
    omega = admissible_omega(get_model(model), GAMMA0, OMEGA0)
    sc = Scenario(
        body,
        model,
        InitialConditions(gamma=GAMMA0, omega=omega, free=FREE[model]),
        IntegrationOptions(t_end=t_end, rtol=rtol, atol=atol, samples=samples),
    )
    return simulate(sc)


@pytest.fixture(scope="module", params=["meridian", "smooth", "rough", "rubber"])
def long_run(request):
    return run(request.param)


def rel_variation(values):
    return np.max(np.abs(values - values[0])) / np.max(np.abs(values))


def test_declared_integrals(long_run):
    expected = {
        "meridian": {"energy", "lagrange", "jellett", "area", "F6"},
        "smooth": {"energy", "lagrange", "jellett", "area", "momentum_x", "momentum_y"},
        "rough": {"energy", "jellett", "routh"},
        "rubber": {"energy", "rubber_spin"},
    }[long_run.model.name]
    assert set(long_run.integrals) == expected


def test_every_reported_integral_is_conserved(long_run):
    for name, values in long_run.integrals.items():
        assert rel_variation(values) <= DRIFT_REL, name
    s = long_run.summary()
    for name, row in s["integrals"].items():
        assert row["initial"] != 0 and row["max_rel_drift"] <= DRIFT_REL, name
    assert s["constraints"]["max_abs_residual"] <= RESIDUAL
    assert s["constraints"]["orthonormality_max_error"] <= RESIDUAL
    assert long_run.t[-1] == 1000.0


def test_models_differ_where_physics_says(long_run):
    """smooth conserves horizontal momentum, rough Routh's integral, meridian F6: not the others."""
    everything = evaluate(long_run.body, long_run.y, INTEGRALS)
    own = {"meridian": "F6", "smooth": "momentum_x", "rough": "routh"}
    for model, name in own.items():
        variation = rel_variation(everything[name])
        if model == long_run.model.name:
            assert variation <= DRIFT_REL, name
        else:
            assert variation > VARIES, (long_run.model.name, name)


def test_every_integral_not_declared_varies(long_run):
    """What a model does not declare is not conserved (symmetric body): every other integral of
    the package varies by more than VARIES along the long run. For rubber rolling this is
    everything but the energy and its own rubber_spin: the torque about the normal that keeps
    ``(w, gamma) = 0`` changes the Jellett, area and Lagrange integrals (their time derivatives
    do not vanish on the constraint manifold, tests/symbolic)."""
    declared = set(long_run.model.integrals(True))
    everything = evaluate(long_run.body, long_run.y, INTEGRALS)
    for name in set(INTEGRALS) - declared:
        assert rel_variation(everything[name]) > VARIES, (long_run.model.name, name)


def test_jellett_area_lagrange_identity(long_run):
    """docs/model.md: F4 + a3 F3 + R F5 = 0 holds identically (it is a kinematic identity)."""
    body = long_run.body
    F = evaluate(body, long_run.y, ["jellett", "lagrange", "area"])
    np.testing.assert_allclose(
        F["jellett"] + body.a3 * F["lagrange"] + body.R * F["area"], 0, atol=1e-14
    )


@pytest.mark.parametrize("model", ["meridian", "smooth", "rough", "rubber"])
def test_general_body_keeps_only_what_holds(model):
    """With I2 != I1 the symmetric integrals are dropped, and what is kept is conserved."""
    traj = run(model, t_end=200.0, I2=0.4, samples=401)
    expected = {
        "meridian": {"energy", "area"},
        "smooth": {"energy", "area", "momentum_x", "momentum_y"},
        "rough": {"energy"},
        "rubber": {"energy"},
    }[model]
    assert set(traj.integrals) == expected
    for name, values in traj.integrals.items():
        assert rel_variation(values) <= DRIFT_REL, name
    everything = evaluate(traj.body, traj.y, INTEGRALS)
    for name in ("lagrange", "jellett", "F6", "routh", "rubber_spin"):
        assert rel_variation(everything[name]) > VARIES, name


def test_energy_by_hand(paper_body):
    """Energy of one state computed by hand: E = m v^2/2 + (w, I w)/2 + m g (R + a3 gamma3)."""
    y = np.zeros(17)
    y[0:3] = (0.1, -0.2, 0.3)
    y[3:6] = (0.5, 0.0, -1.0)
    y[12:15] = (0.0, 0.6, 0.8)
    expected = 0.5 * 0.14 + 0.5 * (0.3 * 0.25 + 0.5 * 1.0) + 1.0 * (1.0 + 0.1 * 0.8)
    assert evaluate(paper_body, y, ["energy"])["energy"] == pytest.approx(expected, rel=1e-15)


def test_natural_scales_by_hand(paper_body):
    """The natural size of each integral, written out for two states of the paper's body
    (``I1 = I2 = 0.3, I3 = 0.5, a3 = 0.1, R = m = g = 1``): the energy's is the kinetic energy
    plus |m g (r, gamma)|; a linear integral's is |grad I| |u| in the kinetic-energy metric,
    ``sqrt(sum_i I_i c_i^2) sqrt(m |v|^2 + sum_i I_i w_i^2)`` for ``I = sum_i I_i w_i c_i``."""
    Y = np.zeros((2, 18))
    Y[0, 0:6] = (0.1, -0.2, 0.3, 0.5, 0.0, -1.0)
    Y[0, 12:15] = (0.0, 0.6, 0.8)
    Y[1, 0:6] = (0.0, 0.0, 0.0, 0.2, 0.1, 2.0)
    Y[1, 12:15] = (0.6, 0.0, -0.8)
    sizes = natural_scales(paper_body, Y, ("energy", "lagrange", "jellett", "area"))
    kinetic = [0.5 * 0.14 + 0.5 * (0.3 * 0.25 + 0.5 * 1.0), 0.5 * (0.3 * 0.05 + 0.5 * 4.0)]
    potential = [1.0 + 0.1 * 0.8, 1.0 - 0.1 * 0.8]
    assert sizes["energy"] == pytest.approx(
        max(map(sum, zip(kinetic, potential, strict=True))), rel=1e-15
    )
    inertia = (0.3, 0.3, 0.5)
    speed = [math.sqrt(2 * k) for k in kinetic]  # |u|_M^2 = 2 T

    def size(coefficients):
        return max(
            math.sqrt(sum(i * c * c for i, c in zip(inertia, cs, strict=True))) * u
            for cs, u in zip(coefficients, speed, strict=True)
        )

    assert sizes["lagrange"] == pytest.approx(size([(0, 0, 1), (0, 0, 1)]), rel=1e-15)
    # jellett = (I w, r), r = -R gamma - a3 e3; area = (I w, gamma)
    assert sizes["jellett"] == pytest.approx(size([(0, -0.6, -0.9), (-0.6, 0, 0.7)]), rel=1e-15)
    assert sizes["area"] == pytest.approx(size([(0, 0.6, 0.8), (0.6, 0, -0.8)]), rel=1e-15)


def test_natural_scales_do_not_overflow_below_doubles():
    """The natural size of an integral is a norm of products: with ``I1 = 1e300`` the squares
    of its terms overflow although the norm is ~1e300. Scaled norms: finite, and equal to the
    same computation in exact rational arithmetic (``fractions``) within ``SCALE_RTOL``."""
    from fractions import Fraction

    from rollingtop import SphericalTop, initial_state
    from rollingtop.dynamics.integrals import natural_scales

    SCALE_RTOL = 1e-12
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=1e300, I3=0.5)
    y = initial_state(body, "meridian", gamma=(0.0, 0.6, 0.8), omega=(0.7, -0.3, 2.0),
                      free={"v_tau": 0.25})  # fmt: skip
    size = natural_scales(body, y[None, :], ("jellett",), model="meridian")["jellett"]
    # Jellett's integral (I w, r), r = -R gamma - a (the sign does not enter): linear in w,
    # its gradient is I_j r_j, so |grad|_(M^-1)^2 = sum I_j r_j^2 and
    # |u|_M^2 = m |v|^2 + sum I_j w_j^2, exactly
    r = [Fraction(float(body.R)) * Fraction(float(g)) for g in y[12:15]]
    r[2] += Fraction(float(body.a3))
    inertia = [Fraction(float(i)) for i in body.inertia]
    dual = sum(ii * ri * ri for ri, ii in zip(r, inertia, strict=True))
    speed = sum(Fraction(float(v)) ** 2 for v in y[0:3]) * Fraction(float(body.m))
    speed += sum(ii * Fraction(float(w)) ** 2 for ii, w in zip(inertia, y[3:6], strict=True))
    exact = math.sqrt(dual) * math.sqrt(speed)
    assert math.isfinite(size) and size == pytest.approx(exact, rel=SCALE_RTOL)
