"""No spin, ``M3 = C1 = 0``: planar rocking and rolling over, through either pole.

Both poles are pole levels at once; the simulator takes the south variant, whose carried
direction must then not turn (``psi_nu' = 0``), also at the north pole where its formula
``M3 / (I1 (1 + gamma3))`` is 0/0, and also when round-off leaves ``w3`` a few ulps off 0.

Independent reference: with ``M3 = C1 = 0`` and ``v_tau = 0`` (so ``C2 = 0``) docs/model.md's
reduced system is a pendulum of variable mass, ``h = rho(theta) theta'^2 / 2 + m g a3 cos(theta)``,
``rho = I1 + m (a3^2 + R^2 + 2 a3 R cos(theta))``; its period, ``T = 2 int sqrt(rho / (2 (h - U)))
dtheta`` between the turning points (rocking about ``gamma3 = -1``, where the CoM is lowest for
``a3 > 0``: height ``R + a3 gamma3``), or over a full turn (rolling over), is computed with mpmath.
"""

import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import initial_state
from rollingtop.contact import meridian
from rollingtop.dynamics import integrals
from rollingtop.dynamics.integrals import reduced_components
from rollingtop.integrate import integrate

#: Kernel codes of the meridian model's pole variants.
SOUTH_CODE, NORTH_CODE = (k.code for k in meridian.MODEL.kernels[1:])

RTOL, ATOL = 1e-12, 1e-14
PERIOD_RTOL = 1e-8  # simulated period (events / interpolation) against the mpmath quadrature
DRIFT = 1e-9  # integrals, absolute (all O(1))

ORIENTATIONS = {  # a coordinate plane keeps w3 exactly 0; a general one leaves round-off in w3
    "coordinate plane": (0.0, 0.6, 0.8),
    "general": (0.36, 0.48, 0.8),
}


def start(body, gamma, w_tau):
    """State with the axis at ``gamma``, rotating about ``tau = e3 x gamma / s`` only."""
    gamma = np.asarray(gamma)
    tau = np.cross((0.0, 0.0, 1.0), gamma)
    tau /= np.linalg.norm(tau)
    return initial_state(body, "meridian", gamma=gamma, omega=w_tau * tau)


@mp.workdps(30)  # a local context: the global precision is left alone
def reference_period(b, h):
    """Period of gamma3 of the variable-mass pendulum at energy ``h`` (mpmath)."""
    mga = b.m * b.g * b.a3

    def f(t):
        rho = b.I1 + b.m * (b.a3**2 + b.R**2 + 2 * b.a3 * b.R * mp.cos(t))
        return mp.sqrt(rho / (2 * (h - mga * mp.cos(t))))

    if h < mga:  # rocking about theta = pi between the turning points cos(theta*) = h / (m g a3)
        t_star = mp.acos(h / mga)
        return float(4 * mp.quad(f, [t_star, mp.pi]))
    return float(mp.quad(f, [0, mp.pi, 2 * mp.pi]))  # rolling over: a full turn


def run(body, y0, t_end, samples, events=None):
    code = meridian.MODEL.kernel_code(body, y0)
    res = integrate(code, body.params, y0, np.linspace(0, t_end, samples), rtol=RTOL, atol=ATOL,
                    events=events, event_direction=1)  # fmt: skip
    return code, res


def assert_conserved(body, Y):
    names = meridian.MODEL.integrals(True)
    for name, values in integrals.evaluate(body, Y, names, "south").items():
        assert np.ptp(values) < DRIFT, name
    assert np.all(np.isfinite(Y))


@pytest.mark.parametrize("gamma", ORIENTATIONS.values(), ids=ORIENTATIONS.keys())
def test_small_rocking_about_the_low_pole(paper_body, gamma):
    """Small energy: the axis rocks through gamma3 = -1 (the carried direction never turns)."""
    gamma = (gamma[0], gamma[1], -gamma[2])  # 37 degrees from the low pole
    y0 = start(paper_body, gamma, 0.05)
    assert meridian.MODEL.kernel_code(paper_body, y0) == SOUTH_CODE  # "both"
    code, res = run(paper_body, y0, 200.0, 4001, events="w_tau")
    Y = res.y
    h = float(integrals.energy(paper_body, Y[:1])[0]) - paper_body.m * paper_body.g * paper_body.R
    assert h < paper_body.m * paper_body.g * paper_body.a3  # below the top: rocking
    assert Y[:, 14].min() < -1 + 1e-4  # passes the low pole (samples 0.05 apart)
    assert Y[:, 14].max() == pytest.approx(h / (paper_body.m * paper_body.g * paper_body.a3),
                                           abs=1e-9)  # fmt: skip
    assert np.ptp(Y[:, 17]) < 1e-11  # psi_nu does not turn (resynchronised to round-off)
    assert_conserved(paper_body, Y)
    periods = np.diff(res.event_t)
    assert len(periods) >= 5
    np.testing.assert_allclose(periods, reference_period(paper_body, h), rtol=PERIOD_RTOL)


@pytest.mark.parametrize("gamma", ORIENTATIONS.values(), ids=ORIENTATIONS.keys())
def test_rolling_over_through_both_poles(paper_body, gamma):
    """Large energy: the body rolls over, through the north and the south pole in turn."""
    y0 = start(paper_body, gamma, 1.5)
    code, res = run(paper_body, y0, 60.0, 60001)
    Y = res.y
    assert code == SOUTH_CODE
    assert Y[:, 14].min() < -1 + 1e-6 and Y[:, 14].max() > 1 - 1e-6
    assert_conserved(paper_body, Y)
    h = float(integrals.energy(paper_body, Y[:1])[0]) - paper_body.m * paper_body.g * paper_body.R
    # theta (signed, in the carried basis) grows monotonically; its full turns give the period
    theta = np.unwrap(reduced_components(Y, "south")["theta"])
    assert np.all(np.diff(theta) * np.sign(theta[-1] - theta[0]) > 0)
    turns = np.abs(theta - theta[0]) / (2 * math.pi)
    k = np.arange(1, int(turns[-1]) + 1)
    t_turn = np.interp(k, turns, res.t)  # fine samples: linear interpolation error ~1e-9
    idx = np.searchsorted(turns, k)
    t_turn = np.array([np.polyval(np.polyfit(turns[i - 2:i + 2] - kk, res.t[i - 2:i + 2], 3), 0.0)
                       for i, kk in zip(idx, k, strict=True)])  # fmt: skip
    np.testing.assert_allclose(np.diff(np.concatenate([[0.0], t_turn])),
                               reference_period(paper_body, h), rtol=PERIOD_RTOL)  # fmt: skip


def test_w3_stays_exactly_zero_in_a_coordinate_plane(paper_body):
    y0 = start(paper_body, ORIENTATIONS["coordinate plane"], 1.5)
    _, res = run(paper_body, y0, 20.0, 201)
    assert np.all(res.y[:, 5] == 0.0)


def test_round_off_spin_counts_as_none(paper_body):
    """A general orientation leaves C1 and M3 at round-off, not 0: still the no-spin level, and
    the carried direction's rate is exactly 0 even with w3 a few ulps off 0."""
    y0 = start(paper_body, ORIENTATIONS["general"], 0.3)
    Iw = paper_body.inertia * y0[3:6]
    C1 = float(Iw @ y0[12:15])
    assert C1 != 0.0 or y0[5] != 0.0  # round-off present
    assert meridian.pole_case(paper_body.I3 * y0[5], C1, np.linalg.norm(Iw)) == "both"
    assert meridian.pole_case(paper_body.I3 * y0[5], C1) != "both" or C1 == y0[5] == 0.0
    y = y0.copy()
    y[5] = 1e-16  # round-off spin
    y[12:15] = (0.0, math.sin(1e-9), -math.cos(1e-9))  # next to the north pole
    assert meridian.psi_nu_rate(paper_body.params, y, False) == 0.0
    y[12:15] = (0.0, 0.0, -1.0)  # at it: 0/0 without the no-spin rule
    y[5] = 0.0
    assert meridian.psi_nu_rate(paper_body.params, y, False) == 0.0


@pytest.mark.parametrize("gamma3", [1.0, -1.0])
def test_vertical_start_without_spin(paper_body, gamma3):
    """Vertical with a horizontal angular velocity only: the body rocks (or rolls over) in the
    plane of nu = (w x e3)/|w x e3|; at the north pole the south variant's rate is 0, not 0/0."""
    y0 = initial_state(paper_body, "meridian", gamma=(0, 0, gamma3), omega=(0.3, 0.4, 0.0))
    code, res = run(paper_body, y0, 50.0, 5001)
    assert code == SOUTH_CODE
    assert_conserved(paper_body, res.y)
    assert np.ptp(res.y[:, 17]) < 1e-12  # psi_nu fixed (resynchronised modulo pi only)
