"""Projection onto the level set of the integrals (issue 26; rollingtop._compiled._integrals and
rollingtop._compiled._template.invariants): the compiled integrals against their numpy
definitions, their gradients against gradients written here, the drift of every claimed
integral with projection, and the period against the reduction's quadrature."""

import subprocess
import sys
from dataclasses import replace

import numba
import numpy as np
import pytest

from rollingtop import ScenarioError, initial_state, simulate
from rollingtop._compiled import _integrals
from rollingtop._jit import call
from rollingtop.contact import get_model
from rollingtop.dynamics.integrals import evaluate
from rollingtop.integrate.options import IntegrationOptions
from rollingtop.reduction import orbits, reduction_of
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES, FREE, GAMMA0, OMEGA0

#: Issue 26: every claimed integral within this, relative, with projection (here to t = 1e4).
HELD_RTOL = 1e-12
T_LONG = 1e4
MODELS = ["meridian", "smooth", "rough", "rubber", "parallel"]


def _state(body, model, rng=None):
    gamma, omega = np.array(GAMMA0), np.array(OMEGA0)
    if rng is not None:
        gamma = gamma + 0.2 * rng.normal(size=3)
        omega = omega + 0.5 * rng.normal(size=3)
        gamma /= np.linalg.norm(gamma)
    if model == "rubber":  # no spin about the normal
        omega = omega - np.dot(omega, gamma) * gamma
    return initial_state(body, model, gamma=gamma, omega=omega, free=FREE[model])


@pytest.mark.parametrize("model", MODELS)
def test_the_compiled_integrals_are_the_numpy_ones(paper_body, model, rng):
    """integral_value against rollingtop.dynamics.integrals (numpy, vectorised) on states of
    every model, to round-off."""
    for _ in range(5):
        y = _state(paper_body, model, rng)
        p = paper_body.params
        want = evaluate(paper_body, y, _integrals.CODES)
        for name, code in _integrals.CODES.items():
            got = call(_integrals.integral_value, code, p, y)
            if name == "slip_nu" and model != "parallel":  # (v_P, nu) = 0: its sign is round-off
                got, want[name] = abs(got), abs(want[name])
            assert got == pytest.approx(float(want[name]), rel=1e-13, abs=1e-14), name


def test_the_velocity_gradients_are_exact(paper_body, rng):
    """velocity_gradient (central differences) against the gradients in u = (v, w) written here:
    energy M u, Lagrange (0, 0, 0, 0, 0, I3), Jellett I r, area I gamma, momentum_x m alpha."""
    b = paper_body
    y = _state(b, "meridian", rng)
    p = b.params
    inertia = np.array([b.I1, b.I2, b.I3])
    r = -b.R * y[12:15] - np.array([0.0, 0.0, b.a3])
    expected = {
        "energy": np.concatenate([b.m * y[0:3], inertia * y[3:6]]),
        "lagrange": np.array([0, 0, 0, 0, 0, b.I3], dtype=float),
        "jellett": np.concatenate([np.zeros(3), inertia * r]),
        "area": np.concatenate([np.zeros(3), inertia * y[12:15]]),
        "momentum_x": np.concatenate([b.m * y[6:9], np.zeros(3)]),
    }
    out = np.zeros(6)
    for name, g in expected.items():
        keep = y.copy()
        call(_integrals.velocity_gradient, _integrals.CODES[name], p, y, out)
        np.testing.assert_array_equal(y, keep)  # restored
        np.testing.assert_allclose(out, g, rtol=1e-12, atol=1e-13, err_msg=name)


@pytest.fixture(params=[0.1, -0.1], ids=["com_above", "com_below"])
def body(request, paper_body):
    return replace(paper_body, a3=request.param)


@pytest.mark.parametrize("model", MODELS)
def test_projection_holds_every_claimed_integral(body, model):
    """Issue 26: with project_integrals every integral the model claims for the body stays
    within HELD_RTOL of its initial value to t = 1e4 (relative to its size, or to the
    energy's scale for an integral that starts at 0), at every sample; the constraints stay at
    round-off; without projection the drift is orders larger (so the test can fail)."""
    y0 = _state(body, model)
    names = get_model(model).integrals_for(body)
    # parallel below the centre: a step-size underflow at a passage of the vertical near
    # t = 4100, with or without projection (issue 26, item 4, still open): to t = 3000 there
    t_end = 3000.0 if model == "parallel" and body.a3 < 0 else T_LONG
    held = simulate(body, model, y0, t_end=t_end, samples=201, project_integrals=True)
    free = simulate(body, model, y0, t_end=t_end, samples=201)
    scale = float(np.max(np.abs(y0[:6])))
    worst_free = 0.0
    for name, values in evaluate(body, held.y, names).items():
        size = max(abs(float(values[0])), 1e-3 * scale)
        drift = float(np.max(np.abs(values - values[0]))) / size
        assert drift < HELD_RTOL, (name, drift)
        v_free = evaluate(body, free.y, [name])[name]
        worst_free = max(worst_free, float(np.max(np.abs(v_free - v_free[0]))) / size)
    assert worst_free > 100 * HELD_RTOL
    assert np.max(np.abs(held.constraint_residuals)) < 1e-12
    assert held.stats["projection_passes"] >= held.stats["steps"]
    assert held.summary()["stats"]["projection_passes"] == held.stats["projection_passes"]


def test_the_period_with_projection_is_no_worse(paper_body):
    """Issue 26: gamma3's period averaged over ~3300 periods (the rising zeros of w_tau) against
    the reduction's quadrature: with projection its error does not grow (measured: 2e-11
    against 2e-9 without)."""
    sc = load_scenario(EXAMPLES / "paper.toml")
    y0 = sc.require_state()
    reduction = reduction_of("meridian")
    level, h = reduction.level_of_state(sc.body, y0), reduction.reduced_energy(sc.body, y0)
    (orbit,) = [o for o in orbits(level, h) if o.gamma3_min <= y0[14] <= o.gamma3_max]
    errors = {}
    for proj in (False, True):
        tr = simulate(sc, t_end=T_LONG, samples=2, events="w_tau", event_direction=1,
                      project_integrals=proj)  # fmt: skip
        te = tr.event_t
        mean = (te[-1] - te[0]) / (len(te) - 1)
        errors[proj] = abs(mean - orbit.period) / orbit.period
    assert errors[True] <= errors[False]
    assert errors[True] < 1e-10


def test_the_option_is_validated_and_read_from_scenarios(tmp_path, capsys):
    from ..test_cli import run_cli

    with pytest.raises(ScenarioError, match="project_integrals = 'yes' must be true or false"):
        IntegrationOptions(project_integrals="yes")
    text = (EXAMPLES / "paper.toml").read_text().replace(
        "[integration]", "[integration]\nproject_integrals = true")  # fmt: skip
    path = tmp_path / "held.toml"
    path.write_text(text)
    assert load_scenario(path).integration.project_integrals is True
    code, out, err = run_cli(capsys, "simulate", str(path), "--t-end", "50", "--json")
    assert code == 0, err
    import json

    data = json.loads(out)
    assert data["stats"]["projection_passes"] > 0
    assert all(v["max_rel_drift"] < HELD_RTOL for v in data["integrals"].values())
    code, out, err = run_cli(capsys, "simulate", str(EXAMPLES / "paper.toml"), "--t-end", "50",
                             "--project-integrals", "--json")  # fmt: skip
    assert code == 0 and json.loads(out)["stats"]["projection_passes"] > 0


def test_the_shell_rotor_pair_is_refused_in_one_line(capsys):
    from ..test_cli import run_cli

    code, out, err = run_cli(capsys, "simulate", str(EXAMPLES / "shell_rotor.toml"),
                             "--t-end", "1", "--project-integrals")  # fmt: skip
    assert code == 2 and "not for the shell-rotor model" in err
    assert len([ln for ln in err.splitlines() if "error" in ln]) == 1


def test_a_failed_projection_is_an_error_with_its_reason():
    from rollingtop._compiled import _dop853 as dop
    from rollingtop._errors import IntegrationError
    from rollingtop.integrate.driver import _raise_for_status

    ctrl = np.array([12.5, 0.1, 100.0, 1e-10, 1e-12, 0.0])
    with pytest.raises(IntegrationError, match="projection onto the integrals.*t = 12.5"):
        _raise_for_status(dop.PROJECTION_FAILED, ctrl, np.zeros(dop.N_COUNTS, dtype=np.int64))


# ---- the normal force between steps (issue 26, item 3) ---------------------------------------

#: The meridian state whose normal force dips to about -0.002 near t = 0.894 (omega x 2.95).
DIP_OMEGA = 2.95 * np.array([0.7, -0.3, 2.0])


def _dip_state(body):
    return initial_state(body, "meridian", gamma=GAMMA0, omega=DIP_OMEGA, free=FREE["meridian"])


def test_the_normal_force_between_steps_is_the_reference_solutions(paper_body):
    """The monitored minimum of the normal force and the first loss of contact, against the
    plain equations (tests/dynamics/reference.py) integrated by solve_ivp at rtol 1e-12 and
    sampled densely (the minimum refined by Brent's method, the loss by brentq on the dense
    solution), to 1e-8; the package's run at its default tolerance, 1e-10."""
    import warnings

    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq, minimize_scalar

    from ..dynamics import reference

    y0 = _dip_state(paper_body)
    p = paper_body.params
    sol = solve_ivp(lambda t, y: reference.rhs("meridian", p, y)[0], (0.0, 1.5), y0,
                    method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)  # fmt: skip

    def normal(t):
        return reference.reactions("meridian", p, sol.sol(t))[0]

    ts = np.linspace(0.0, 1.5, 3001)
    ns = np.array([normal(t) for t in ts])
    k = int(np.argmin(ns))
    best = minimize_scalar(normal, bracket=(ts[k - 1], ts[k], ts[k + 1]), tol=1e-12)
    first = int(np.flatnonzero(ns < 0)[0])
    t_lost = brentq(normal, ts[first - 1], ts[first], xtol=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the ContactLostWarning: the point of the test
        tr = simulate(paper_body, "meridian", y0, t_end=1.5, samples=3)
    sr = tr.step_reactions
    assert sr["min_normal_force"] == pytest.approx(best.fun, abs=1e-8)
    assert sr["t_min_normal_force"] == pytest.approx(best.x, abs=1e-5)  # a flat minimum
    assert sr["contact_lost_at"] == pytest.approx(t_lost, abs=1e-8)


def test_a_dip_below_zero_inside_a_step_is_found_on_the_dense_output(paper_body):
    """At rtol 1e-3 (steps of ~0.15 time units) the dip of the normal force below zero lasts
    less than a step: its loss of contact is found inside the step, at a root of the normal
    force on the dense interpolant to 1e-10 (the interpolant sampled just before and after:
    the same steps, since the samples do not change them)."""
    from rollingtop._compiled import for_code
    from rollingtop.integrate import integrate

    y0 = _dip_state(paper_body)
    p = paper_body.params
    run = integrate(0, p, y0, np.array([0.0, 1.5]), rtol=1e-3, atol=1e-5)
    t_lost = run.reactions["contact_lost_at"]
    assert t_lost is not None and run.steps < 20
    probe = integrate(0, p, y0, np.array([0.0, t_lost - 1e-10, t_lost + 1e-10, 1.5]),
                      rtol=1e-3, atol=1e-5)  # fmt: skip
    assert probe.steps == run.steps
    diag = np.zeros((4, 8))
    call(for_code(0).dynamics.diagnostics, 0, p, np.ascontiguousarray(probe.y), diag)
    assert diag[1, 0] >= 0.0 > diag[2, 0]
    # the dip is shorter than the steps around it: sampled at 2001 points of the interpolant
    dense = integrate(0, p, y0, np.linspace(0.0, 1.5, 2001), rtol=1e-3, atol=1e-5)
    diag = np.zeros((2001, 8))
    call(for_code(0).dynamics.diagnostics, 0, p, np.ascontiguousarray(dense.y), diag)
    below = np.linspace(0.0, 1.5, 2001)[diag[:, 0] < 0]
    assert below.size and below[-1] - below[0] < 1.5 / run.steps


#: A global the pruning test below branches on (numba reads a global as a constant).
_NEVER = False


def test_a_run_without_projection_never_compiles_it():
    """Issue 26's cold-start cost: the projection lives in the ``stepper_held`` copy of the
    stepper (``HELD = True``); the plain stepper has ``HELD = False``, and numba prunes a branch
    on a false global before typing, so the plain run never compiles ``project_integrals``
    (shown here on a branch that could not even be typed). In a fresh process a plain run
    compiles or loads the plain stepper only, a held run the held one."""
    from rollingtop._compiled import for_model

    def untypable(x):
        return x.no_such_attribute

    @numba.njit
    def pruned(x):
        if _NEVER:
            return numba.njit(untypable)(x)
        return x + 1.0

    assert pruned(1.0) == 2.0
    k = for_model("meridian")
    assert k.stepper.HELD is False and k.stepper_held.HELD is True
    code = (
        "from rollingtop import simulate, load_scenario\n"
        "from rollingtop._compiled import for_model\n"
        f"sc = load_scenario({str(EXAMPLES / 'paper.toml')!r})\n"
        "k = for_model('meridian')\n"
        "simulate(sc, t_end=1.0)\n"
        "print(len(k.stepper.run_rows.signatures), len(k.stepper_held.run_rows.signatures))\n"
        "simulate(sc, t_end=1.0, project_integrals=True)\n"
        "print(len(k.stepper_held.run_rows.signatures))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["1", "0", "1"], out.stdout + out.stderr
