"""The shell-rotor pair (rollingtop.contact.shell_rotor) against a Newton-Euler implementation of
the two bodies written in the tests (tests/dynamics/reference.py: rotor and shell each with its
momentum and angular-momentum balance, the bearing's force and torque as unknowns), its
integrals, its initial state, and its limit: the meridian model as the shell's mass and inertia
vanish, at first order."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import RollingTopError, ScenarioError, SphericalTop, initial_state, simulate
from rollingtop.contact import MODELS
from rollingtop.dynamics.integrals import evaluate
from rollingtop.scenario import Scenario
from tests import kernels as _kernel

from ..conftest import EXAMPLES
from ..dynamics import reference

MODEL = MODELS["shell-rotor"]
RHS_RTOL = 1e-12  # compiled accelerations vs the 15x15 Newton-Euler solve (relative to max)
FINAL_ATOL = 1e-9  # final state after t = 20, both at rtol 1e-12
DRIFT = 1e-9  # relative drift of energy and axial spin over t = 50 at rtol 1e-11
RATE = (0.97, 1.03)  # fitted exponent of the distance to the meridian model (first order)
PAPER = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}
STATE = {"gamma": [0.0, math.sqrt(0.19), 0.9], "omega": [2.0, -0.2, 3.0], "free": {"v_tau": 0.3}}


def _random_pair(rng):
    I1, I2 = rng.uniform(0.2, 1.0, size=2)
    I2 = I1 if rng.random() < 0.5 else I2
    I3 = rng.uniform(abs(I1 - I2) + 0.05, I1 + I2 - 0.05)
    R = rng.uniform(0.5, 2.0)
    ms = rng.uniform(0.01, 1.0)
    return SphericalTop(R=R, m=rng.uniform(0.5, 3), g=rng.uniform(0, 10),
                        a3=rng.uniform(-0.9, 0.9) * R, I1=I1, I2=I2, I3=I3, shell_mass=ms,
                        shell_inertia=ms * R**2 * rng.uniform(0.4, 0.67))  # fmt: skip


def _random_state(rng, body):
    gamma = rng.normal(size=3)
    free = {"v_tau": float(rng.normal())}
    y = initial_state(body, MODEL, gamma=gamma / np.linalg.norm(gamma),
                      omega=2 * rng.normal(size=3), free=free)  # fmt: skip
    y[17] = rng.normal()  # any shell spin: the velocity follows by the projection
    _kernel.project(MODEL.code, body.params, y, _kernel.new_workspace())
    return y


def test_rhs_matches_newton_euler_at_random_states(rng):
    dy, ws = np.empty(18), _kernel.new_workspace()
    for _ in range(50):
        body = _random_pair(rng)
        y = _random_state(rng, body)
        nc = _kernel.rhs(MODEL.code, body.params, y, dy, ws)
        expected, force = reference.shell_rotor_rhs(body.params, y)
        scale = np.max(np.abs(expected))
        np.testing.assert_allclose(dy, expected, rtol=0, atol=RHS_RTOL * scale)
        N, T = _kernel.reaction(nc, y, ws)
        gamma = y[12:15]
        assert N == pytest.approx(force @ gamma, rel=1e-10, abs=RHS_RTOL * scale)
        assert T == pytest.approx(np.linalg.norm(force - (force @ gamma) * gamma), rel=1e-9,
                                  abs=RHS_RTOL * scale)  # fmt: skip
        # the bearing's torque of the outputs: the reference's unknown, perpendicular to e3
        torque = MODEL.state_outputs(body, y[None])["bearing_torque"][0]
        np.testing.assert_allclose(torque, reference.shell_rotor_rhs.bearing_torque,
                                   rtol=0, atol=RHS_RTOL * 10 * scale)  # fmt: skip


@pytest.mark.filterwarnings("ignore::rollingtop.ContactLostWarning")  # random: the force is not
@pytest.mark.parametrize("seed", [1, 2, 3])  # what is compared
def test_final_state_matches_solve_ivp_on_newton_euler(seed):
    rng = np.random.default_rng(seed)
    body = _random_pair(rng)
    y0 = _random_state(rng, body)
    tr = simulate(body, MODEL, y0, t_end=20.0, rtol=1e-12, atol=1e-14, samples=5)
    sol = solve_ivp(lambda t, y: reference.shell_rotor_rhs(body.params, y)[0], (0.0, 20.0), y0,
                    method="DOP853", rtol=1e-12, atol=1e-14, t_eval=tr.t)  # fmt: skip
    assert sol.success
    np.testing.assert_allclose(tr.y, sol.y.T, rtol=0, atol=FINAL_ATOL * max(1.0, np.abs(y0).max()))


def test_initial_state_is_the_rotors_meridian_state():
    """The rotor starts exactly as under the meridian model; the shell's spin is the one with
    which the shell's contact point is at rest: delta = slip across / (R s)."""
    body = SphericalTop(**PAPER, shell_mass=0.2, shell_inertia=0.2 * 2 / 3)
    y = initial_state(body, MODEL, **STATE)
    y_m = initial_state(SphericalTop(**PAPER), "meridian", **STATE)
    np.testing.assert_allclose(y[:17], y_m[:17], rtol=0, atol=1e-15)
    gamma, w, v = y[12:15], y[3:6], y[0:3]
    omega = w + y[17] * np.array([0.0, 0.0, 1.0])
    v_centre = v - np.cross(w, [0.0, 0.0, body.a3])
    contact = v_centre + np.cross(omega, -body.R * gamma)
    np.testing.assert_allclose(contact, 0.0, atol=1e-15)


def test_the_pairs_integrals_are_conserved_the_rotors_own_are_not():
    """Energy, axial spin, Jellett about the pair's centre of mass and the pair's F6 (proved by
    rollingtop.symbolic.shell_rotor) hold; the rotor's own energy and Jellett form do not."""
    body = SphericalTop(**PAPER, shell_mass=0.2, shell_inertia=0.2 * 2 / 3)
    tr = simulate(body, MODEL, initial_state(body, MODEL, **STATE), t_end=50.0, rtol=1e-11,
                  samples=501)  # fmt: skip
    assert tr.model.integrals_for(body) == ("energy", "lagrange", "jellett", "F6")
    for name, values in tr.integrals.items():
        assert np.ptp(values) < DRIFT * max(1.0, abs(values[0])), name
    rotor = dataclasses.replace(body, shell_mass=0.0, shell_inertia=0.0)
    for name, values in evaluate(rotor, tr.y, ["energy", "jellett"]).items():
        assert np.ptp(values) > 1e-2, name


def test_the_pairs_integrals_are_the_models_and_a_shell_without_it_is_refused(rng):
    """The integrals module evaluates the pair's energy under the model's name
    (ContactModel.own.integrals), the rotor's plus the shell's ms v_O^2/2 + Js |Omega|^2/2 written
    here with vectors; without the model a body with a shell is refused, not given the rotor's
    value."""
    for _ in range(5):
        body = _random_pair(rng)
        y = _random_state(rng, body)
        pair = evaluate(body, y, ["energy"], model="shell-rotor")["energy"]
        v, w, gamma, delta = y[0:3], y[3:6], y[12:15], y[17]
        e3 = np.array([0.0, 0.0, 1.0])
        r = -body.R * gamma - body.a3 * e3  # contact point from the rotor's centre of mass
        rotor = (0.5 * body.m * v @ v + 0.5 * w @ (np.array(body.inertia) * w)
                 - body.m * body.g * r @ gamma)  # fmt: skip
        v_O = v - np.cross(w, body.a3 * e3)
        omega = w + delta * e3
        shell = 0.5 * body.shell_mass * v_O @ v_O + 0.5 * body.shell_inertia * omega @ omega
        assert pair == pytest.approx(rotor + shell, rel=1e-13)
        for name in ("energy", "jellett", "F6"):
            with pytest.raises(ValueError, match="model='shell-rotor'"):
                evaluate(body, y, [name])


def _distance(eps, t_end=10.0):
    body = SphericalTop(**PAPER, shell_mass=eps, shell_inertia=eps)
    pair = simulate(body, MODEL, initial_state(body, MODEL, **STATE), t_end=t_end, rtol=1e-13,
                    atol=1e-15, samples=2).y[-1]  # fmt: skip
    plain = SphericalTop(**PAPER)
    mer = simulate(plain, "meridian", initial_state(plain, "meridian", **STATE), t_end=t_end,
                   rtol=1e-13, atol=1e-15, samples=2).y[-1]  # fmt: skip
    axis = np.linalg.norm(pair[[8, 11, 14]] - mer[[8, 11, 14]])
    return axis


def test_the_meridian_model_is_the_limit_of_a_weightless_shell_at_first_order():
    eps = np.array([1e-4, 1e-5, 1e-6, 1e-7])
    d = np.array([_distance(e) for e in eps])
    slope = np.polyfit(np.log(eps), np.log(d), 1)[0]
    assert RATE[0] < slope < RATE[1], (slope, d)


def test_the_shell_table_is_required_and_only_for_the_pair():
    text = (EXAMPLES / "shell_rotor.toml").read_text()
    import tomllib

    data = tomllib.loads(text)
    assert Scenario.from_dict(data).body.has_shell
    no_shell = {k: v for k, v in data.items() if k != "shell"}
    with pytest.raises(ScenarioError, match=r"needs a table \[shell\]"):
        Scenario.from_dict(no_shell)
    other = {**data, "contact": {"model": "meridian"}}
    with pytest.raises(ScenarioError, match=r"\[shell\] is for model 'shell-rotor'"):
        Scenario.from_dict(other)
    with pytest.raises(RollingTopError, match="shell_mass = -1 must be >= 0"):
        Scenario.from_dict({**data, "shell": {"mass": -1.0, "inertia": 0.1}})
    with pytest.raises(RollingTopError, match="shell_inertia = 0 with shell_mass = 0.2"):
        Scenario.from_dict({**data, "shell": {"mass": 0.2, "inertia": 0.0}})
    # switching a pair's scenario to another model drops the shell (no energy terms of it)
    assert not Scenario.from_dict(data).with_overrides(model="meridian").body.has_shell


def test_at_a_vertical_axis_the_pairs_contact_point_cannot_slip():
    """The shell's spin about the vertical does not move the contact point: the rotor's v_tau
    (its contact point's slip for the meridian model) must be 0 there, and the state is the
    rolling one, v = -w x r."""
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5, shell_mass=0.2,
                        shell_inertia=0.2 * 2 / 3)  # fmt: skip
    omega = np.array([2.0, -0.2, 3.0])
    with pytest.raises(RollingTopError, match="v_tau = 0.3: at a vertical axis"):
        initial_state(body, "shell-rotor", gamma=(0, 0, 1), omega=omega, free={"v_tau": 0.3})
    y = initial_state(body, "shell-rotor", gamma=(0, 0, 1), omega=omega)
    r = np.array([0.0, 0.0, -body.R - body.a3])  # contact point from the centre of mass
    np.testing.assert_allclose(y[0:3], -np.cross(omega, r), atol=1e-15)


def test_a_state_whose_shell_spin_disagrees_with_v_is_refused():
    """The shell's spin is in the last slot; v follows from it (no row of the model catches a
    disagreement, so simulate checks): a state edited without projecting is refused."""
    body = SphericalTop(**PAPER, shell_mass=0.2, shell_inertia=0.1)
    y = initial_state(body, MODEL, **STATE)
    y[17] += 0.5
    with pytest.raises(RollingTopError, match="the shell's spin"):
        simulate(body, MODEL, y, t_end=1.0)


def test_the_pairs_state_under_the_other_models():
    """compare / --model from a pair: the last slot is the shell's spin, not a direction; the
    other models start from the axis azimuth. The rotor's state already satisfies the meridian
    constraint (its contact point slips only across the axis: v_P = R delta e3 x gamma), so the
    meridian model takes it unchanged."""
    from rollingtop import load_scenario, simulate_models
    from rollingtop.simulate import switch_model

    sc = load_scenario(EXAMPLES / "shell_rotor.toml").with_overrides(t_end=0.5)
    y = sc.y0
    to_meridian, change = switch_model(sc, "meridian")
    np.testing.assert_allclose(change, 0.0, atol=1e-12)
    azimuth = math.atan2(y[11], y[8])
    for name in ("meridian", "parallel"):
        switched, _ = switch_model(sc, name)
        assert switched.y0[17] == pytest.approx(azimuth, abs=1e-12), name
    runs = simulate_models(sc)
    assert set(runs) == set(MODELS)
    for name, run in runs.items():
        for integral, values in run.integrals.items():
            assert abs(values[-1] - values[0]) < 1e-9, (name, integral)


def test_the_pairs_outputs_name_the_shell(tmp_path):
    """CSV and NetCDF carry the shell's angular velocity and the bearing torque as --json does,
    and the state's last slot is called the shell's spin, not a direction."""

    from rollingtop import load_scenario, simulate_ensemble

    sc = load_scenario(EXAMPLES / "shell_rotor.toml").with_overrides(t_end=0.5, samples=6)
    run = simulate(sc)
    outputs = run.model_outputs
    header = run.to_csv(tmp_path / "pair.csv").read_text().splitlines()
    header = [line for line in header if not line.startswith("#")]
    cols = header[0].split(",")
    table = np.loadtxt(header[1:], delimiter=",")
    for name in ("shell_omega", "bearing_torque"):
        idx = [cols.index(f"{name}{c}") for c in "123"]
        np.testing.assert_allclose(table[:, idx], outputs[name], rtol=1e-15, atol=1e-300)
    # the shell turns with the rotor and about the axis by the slot's spin
    np.testing.assert_allclose(outputs["shell_omega"] - run.y[:, 3:6],
                               np.outer(run.y[:, 17], [0, 0, 1]), atol=1e-14)  # fmt: skip
    ens = simulate_ensemble(sc.body, sc.model, [sc.y0], t_end=0.5, samples=3)
    ds = ens.to_xarray()
    assert list(ds["state"].values[-3:]) == ["X", "Y", "shell_spin"]
