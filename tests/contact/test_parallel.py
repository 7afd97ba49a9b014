"""The ``parallel`` model (no slip across the axis projection): which integrals it has, and its
generic passage through the vertical, held to a plain solver written here."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import SphericalTop, initial_state
from rollingtop.contact import MODELS, parallel
from rollingtop.dynamics.integrals import evaluate
from rollingtop.integrate.driver import integrate
from rollingtop.symbolic.claims import Claim, _integrals, check

from ..dynamics import reference

BODY = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
E3 = np.array([0.0, 0.0, 1.0])
#: Relative drift of energy and Jellett's integral through several pole passages (rtol 1e-11).
CONSERVED = 1e-9
#: The integrals the model does not have must vary by more than this (measured: area 5e-2,
#: Lagrange 5e-1 relative over 40 time units).
VARIES = 1e-2
#: The pole rate against the limit of -w_n / sigma of the plain solver at s = 1e-7 (measured
#: difference 9e-3 relative: K -> K* like s^q, q ~ 0.6 on this approach).
POLE_RATE_RTOL = 2e-2


def _generic_state():
    """A random state (seed 0) that reaches the north pole at t = 8.6105 (measured)."""
    rng = np.random.default_rng(0)
    gamma = rng.normal(size=3)
    omega = rng.normal(size=3)
    v_nu = rng.normal() * 0.3
    return initial_state(BODY, "parallel", gamma=gamma / np.linalg.norm(gamma), omega=omega,
                         free={"v_nu": v_nu})  # fmt: skip


def test_integrals_claimed_are_proved_and_the_others_disproved():
    F = _integrals()
    assert MODELS["parallel"].integrals_symmetric == ("energy", "jellett")
    for name in ("energy", "jellett"):
        assert check(Claim(name, "parallel", F[name])).result == "proved"
    for name in ("area", "lagrange"):
        assert check(Claim(name, "parallel", F[name])).result == "failed"


def test_generic_motion_passes_the_pole_several_times_conserving_its_integrals():
    y0 = _generic_state()
    t = np.linspace(0.0, 40.0, 40001)
    res = integrate(MODELS["parallel"].code, BODY.params, y0, t, rtol=1e-11, atol=1e-13)
    s = np.hypot(res.y[:, 12], res.y[:, 13])
    near = (s[1:-1] < s[:-2]) & (s[1:-1] < s[2:]) & (s[1:-1] < 1e-2)
    assert np.count_nonzero(near) >= 3  # passages through the vertical
    assert np.min(s) < 1e-3
    values = evaluate(BODY, res.y, ["energy", "jellett", "area", "lagrange"])
    for name, v in values.items():
        drift = np.max(np.abs(v - v[0])) / max(1.0, abs(v[0]))
        if name in ("energy", "jellett"):
            assert drift < CONSERVED, name
        else:
            assert drift > VARIES, name


def _plain(t, y, p):
    return reference.rhs("parallel", p, y)[0]


def test_arrival_in_finite_time_with_a_finite_pole_rate():
    """The plain solver (geometric tau, solve_ivp at rtol 1e-12) reaches s = 1e-7 at a finite
    time with w_tau finite (s decreasing linearly); -w_n / sigma there is the compiled pole
    rate K* of that state, and the package reaches the pole at the same time."""
    y0 = _generic_state()

    def hit(t, y, p):
        return math.hypot(y[12], y[13]) - 1e-7

    hit.terminal = True
    sol = solve_ivp(_plain, (0.0, 20.0), y0, args=(BODY.params,), method="DOP853", rtol=1e-12,
                    atol=1e-14, events=hit)  # fmt: skip
    assert sol.status == 1
    t_pole, y = sol.t[-1], sol.y[:, -1]
    assert t_pole == pytest.approx(8.61053, abs=1e-4)
    gamma, w = y[12:15], y[3:6]
    s = math.hypot(gamma[0], gamma[1])
    tau = np.cross(E3, gamma) / s
    n = np.cross(E3, tau)
    sigma = -(gamma @ n)
    assert abs(w @ tau) > 0.1  # the axis arrives with finite speed
    K = -(w @ n) / sigma
    y[17] = math.atan2(y[11], y[8])  # the carried azimuth = the geometric one here
    assert parallel.pole_rate(BODY.params, y) == pytest.approx(K, rel=POLE_RATE_RTOL)
    # the package: same arrival (before the pole both are the same equations)
    t = np.array([0.0, t_pole - 1e-3])
    res = integrate(MODELS["parallel"].code, BODY.params, y0, t, rtol=1e-12, atol=1e-14)
    ahead = res.y[-1]
    assert math.hypot(ahead[12], ahead[13]) == pytest.approx(abs(w @ tau) * 1e-3, rel=0.05)


#: Energy and Jellett drift over 50 time units of many pole passages (rtol 1e-10; measured at
#: most 1e-7 over 600 random bodies and states to t = 100, typically 1e-10).
PASSAGE_DRIFT = 1e-6


def test_random_bodies_and_states_pass_their_poles():
    """100 random bodies and states (seeded) to t = 50: every run finishes, through (measured)
    ~1000 pole passages in all, with energy and Jellett's integral conserved."""
    rng = np.random.default_rng(5)
    passages = 0
    for _ in range(100):
        I1 = rng.uniform(0.2, 1.0)
        body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=rng.uniform(-0.5, 0.5), I1=I1,
                            I3=rng.uniform(0.2, min(2 * I1, 1.5)))  # fmt: skip
        gamma = rng.normal(size=3)
        y0 = initial_state(body, "parallel", gamma=gamma / np.linalg.norm(gamma),
                           omega=rng.normal(size=3), free={"v_nu": rng.normal() * 0.5})  # fmt: skip
        res = integrate(MODELS["parallel"].code, body.params, y0, np.linspace(0.0, 50.0, 10001),
                        rtol=1e-10, atol=1e-12)  # fmt: skip
        s = np.hypot(res.y[:, 12], res.y[:, 13])
        passages += np.count_nonzero((s[1:-1] < s[:-2]) & (s[1:-1] < s[2:]) & (s[1:-1] < 1e-2))
        for v in evaluate(body, res.y, ["energy", "jellett"]).values():
            assert np.max(np.abs(v - v[0])) / max(1.0, abs(v[0])) < PASSAGE_DRIFT
    assert passages > 500
