"""The model battery: every registered contact model (and every kernel variant) must pass it.

A new model gets these tests by being registered (:data:`rollingtop.contact.MODULES`). Each test
holds the model to something independent of the code under test: the general constraint-row
path against the closed forms, a conservation law, the constraint residuals, time reversibility,
the registry's dispatch against the model.
"""

import dataclasses
import math

import numpy as np
import pytest

from rollingtop import InitialStateError, SphericalTop, initial_state
from rollingtop._compiled import for_code, for_model, packages_of
from rollingtop.contact import KERNELS, MODELS, kernel_by_code
from rollingtop.dynamics.integrals import evaluate
from rollingtop.dynamics.state import UNIT_TOLERANCE, constraint_residuals
from rollingtop.integrate.driver import integrate
from tests import kernels as _kernel

from ..conftest import admissible_omega

#: A symmetric body with the centre of mass below the centre, and a general (I1 != I2) one.
SYMMETRIC = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
GENERAL = SphericalTop(R=1.0, m=1.2, g=1.0, a3=-0.15, I1=0.3, I2=0.4, I3=0.5)
#: Relative drift of an integral over the runs below (rtol = 1e-11, t = 5).
DRIFT = 1e-8
#: Constraint residual |J u| after every accepted (projected) step, relative to |u|.
RESIDUAL = 1e-12
#: Closed forms against the general row path (the same equations, other round-off).
CLOSED_FORM = 1e-11

model_names = pytest.mark.parametrize("name", list(MODELS))


def _free(model, scale=0.2):
    """A non-zero value for each free velocity component of ``model``."""
    return {
        k: scale if n == 1 else [scale * (-0.5) ** i for i in range(n)]
        for k, n in model.free_velocity.items()
    }


#: The axis tilted by 0.6 rad.
TILTED = (0.0, math.sin(0.6), math.cos(0.6))


#: The shell a model with its own inertia (``shell-rotor``) is tested with: without one it
#: would be the meridian model, singular at the vertical.
SHELL = {"shell_mass": 0.2, "shell_inertia": 0.1}


def _for(model, body):
    """``body`` as the battery runs ``model``: with :data:`SHELL` for a model with its own
    inertia."""
    return dataclasses.replace(body, **SHELL) if model.own_inertia else body


def _state(body, model, gamma=TILTED, omega=(0.7, -0.3, 2.0), free=None):
    """A state of ``model``; ``omega`` loses its components that the model forbids."""
    omega = admissible_omega(model, gamma, omega)
    free = _free(model) if free is None else free
    return initial_state(body, model, gamma=gamma, omega=omega, free=free)


def _run(body, code, y0, t_end, n=201):
    return integrate(code, body.params, y0, np.linspace(0.0, t_end, n), rtol=1e-11, atol=1e-13)


def _max_drift(values):
    v = np.asarray(values)
    return float(np.max(np.abs(v - v[0])) / max(1.0, abs(v[0])))


@pytest.mark.parametrize("kernel", KERNELS, ids=[f"{k.model}-{k.variant}" for k in KERNELS])
def test_the_compiled_dispatch_agrees_with_the_model(kernel):
    """Each kernel code reaches its own model's compiled rows: as many rows as the model names
    constraints, the carried direction exactly where the kernel is a variant; codes are the
    registry's, model by model, each model's own kernel first."""
    model = MODELS[kernel.model]
    assert kernel_by_code(kernel.code) is kernel
    assert model.kernels[0].code == model.code and kernel in model.kernels
    y = _state(SYMMETRIC, model)
    J, bias, dirs, _, _ = _kernel.new_workspace()
    dispatch = for_code(kernel.code)._dispatch
    assert kernel.code in dispatch.CODES
    codes = [c for package in packages_of(model) for c in package._dispatch.CODES]
    assert codes == [k.code for k in model.kernels]  # the model's own package first
    assert for_model(model)._dispatch.CODES == (model.code,)
    assert dispatch.rows(kernel.code, SYMMETRIC.params, y, J, bias, dirs) == len(model.constraints)
    assert dispatch.carries_direction(kernel.code) == kernel.carries_direction


@model_names
@pytest.mark.parametrize("body", [SYMMETRIC, GENERAL], ids=["symmetric", "general"])
def test_constraints_and_claimed_integrals_are_preserved(name, body):
    model = MODELS[name]
    body = _for(model, body)
    y0 = _state(body, model)
    kernel = model.kernel(body, y0)
    res = _run(body, kernel.code, y0, 5.0)
    scale = np.linalg.norm(res.y[:, :6], axis=1)
    residuals = np.array([np.max(np.abs(constraint_residuals(body, model, y))) for y in res.y])
    assert np.all(residuals <= RESIDUAL * scale)
    names = model.integrals(body.symmetric)
    assert "energy" in names
    values = evaluate(body, res.y, names, pole=kernel.variant, model=model)
    for integral in names:
        assert _max_drift(values[integral]) < DRIFT, integral


@pytest.mark.parametrize("kernel", KERNELS, ids=[f"{k.model}-{k.variant}" for k in KERNELS])
def test_closed_form_matches_the_general_rows(kernel, rng):
    """``rhs`` (the model's closed form, where it has one) against ``rhs_rows`` (its constraint
    rows and a Cholesky solve), and the same for the velocity projection. A model with its own
    inertia (``shell-rotor``) has no general path: ``tests/contact/test_shell_rotor.py`` holds
    it to a Newton-Euler implementation instead."""
    model = MODELS[kernel.model]
    if model.own_inertia:
        pytest.skip("no general row path for a model with its own inertia")
    for _ in range(20):
        gamma = rng.normal(size=3)
        y = _state(SYMMETRIC, model, gamma=gamma / np.linalg.norm(gamma), omega=rng.normal(size=3))
        y[17] = rng.uniform(-math.pi, math.pi)  # a carried direction anywhere
        p, ws = SYMMETRIC.params, _kernel.new_workspace()
        fast, rows = np.zeros(18), np.zeros(18)
        assert _kernel.rhs(kernel.code, p, y, fast, ws) == _kernel.rhs_rows(
            kernel.code, p, y, rows, ws
        )
        assert np.allclose(fast, rows, rtol=CLOSED_FORM, atol=CLOSED_FORM)
        # velocity projection of a state pushed off the constraints
        off = y.copy()
        off[:6] += rng.normal(size=6)
        a, b = off.copy(), off.copy()
        _kernel.project(kernel.code, p, a, ws)
        b[6:15] = a[6:15]  # the same frame and psi_nu as the full projection produced
        b[17] = a[17]
        _kernel.project_velocity_rows(kernel.code, p, b, ws)
        assert np.allclose(a, b, rtol=CLOSED_FORM, atol=CLOSED_FORM)


@pytest.mark.parametrize("kernel", KERNELS, ids=[f"{k.model}-{k.variant}" for k in KERNELS])
def test_projection_is_idempotent(kernel, rng):
    model = MODELS[kernel.model]
    body = _for(model, SYMMETRIC)
    p, ws = body.params, _kernel.new_workspace()
    for _ in range(20):
        y = _state(body, model, omega=rng.normal(size=3))
        y[:6] += 1e-3 * rng.normal(size=6)
        y[6:15] += 1e-9 * rng.normal(size=9)
        _kernel.project(kernel.code, p, y, ws)
        again = y.copy()
        _kernel.project(kernel.code, p, again, ws)
        assert np.allclose(again, y, rtol=1e-14, atol=1e-14)
        assert np.max(np.abs(constraint_residuals(body, model, y))) < 1e-14 * np.linalg.norm(y[:6])


@model_names
def test_pole_passage(name):
    """Through the vertical and on: a motion leaving the vertical, reversed in time (the
    equations are reversible: ``u -> -u`` maps solutions to solutions), passes the pole at
    ``t = 0.3`` and goes on with its constraints and integrals intact."""
    model = MODELS[name]
    body = _for(model, SYMMETRIC)
    # the shell-rotor pair's contact point cannot slip at a vertical axis: its v_tau is 0 there
    free = {} if model.own_inertia else None
    y0 = _state(body, model, gamma=(0.0, 0.0, 1.0), omega=(1.0, 0.5, 3.0), free=free)
    kernel = model.kernel(body, y0)
    out = _run(body, kernel.code, y0, 0.3, n=2).y[-1]
    back = out.copy()
    back[:6] *= -1.0
    if model.own_inertia:
        back[17] *= -1.0  # the model's own velocity reverses too
    res = _run(body, kernel.code, back, 0.6, n=601)
    s = np.hypot(res.y[:, 12], res.y[:, 13])
    k = int(np.argmin(s))
    assert abs(res.t[k] - 0.3) < 2e-3 and s[k] < 2e-3  # it passed through the pole
    assert 0.05 < s[-1]  # and left it again
    back_at_start = res.y[300]
    assert np.allclose(back_at_start[:6], -y0[:6], atol=1e-8)  # reversed motion retraced
    values = evaluate(body, res.y, model.integrals(True), pole=kernel.variant, model=model)
    for integral, v in values.items():
        assert _max_drift(v) < DRIFT, integral


@model_names
def test_bad_free_components_are_refused_with_their_name(name):
    model = MODELS[name]
    gamma = (0.0, 0.6, 0.8)
    omega = admissible_omega(model, gamma, (0.3, 0.0, 1.0))
    with pytest.raises(InitialStateError, match="v_nonsense"):
        initial_state(SYMMETRIC, model, gamma=gamma, omega=omega, free={"v_nonsense": 1.0})
    for key, n in model.free_velocity.items():
        wrong = [0.1] * (n + 1)
        with pytest.raises(InitialStateError, match=key):
            initial_state(SYMMETRIC, model, gamma=gamma, omega=omega, free={key: wrong})


@pytest.mark.parametrize(
    "name", [n for n, m in MODELS.items() if m.spin_directions is not None] or [None]
)
def test_an_omega_against_a_spin_constraint_is_refused(name):
    """A model that constrains the angular velocity alone (rubber rolling: ``(w, gamma) = 0``)
    refuses an initial ``omega`` that violates it, naming the constraint and its residual,
    beyond ``UNIT_TOLERANCE |omega|``, and accepts it within (then the state satisfies it to
    round-off): it does not project ``omega`` silently."""
    if name is None:
        pytest.skip("no registered model constrains the angular velocity alone")
    model = MODELS[name]
    gamma = np.array(TILTED)
    good = admissible_omega(model, gamma, (0.7, -0.3, 2.0))
    for label, d in model.spin_directions(gamma).items():
        d = np.asarray(d) / np.linalg.norm(d)
        bad = good + 0.5 * d
        with pytest.raises(InitialStateError) as err:
            initial_state(SYMMETRIC, model, gamma=gamma, omega=bad)
        message = str(err.value)
        assert label in message and "0.5" in message and "tolerance" in message
        assert len(message.splitlines()) == 1
        inside = good + 0.1 * UNIT_TOLERANCE * np.linalg.norm(good) * d
        y = initial_state(SYMMETRIC, model, gamma=gamma, omega=inside)
        assert abs(y[3:6] @ d) < 1e-15 * np.linalg.norm(good)
        np.testing.assert_allclose(y[3:6], good, atol=UNIT_TOLERANCE * np.linalg.norm(good))


def test_every_model_has_its_own_colour():
    """compare draws every model in its colour: no two alike."""
    colours = [model.colour.lower() for model in MODELS.values()]
    assert len(set(colours)) == len(colours), colours
