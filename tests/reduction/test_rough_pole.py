"""The rough model's pole levels (issue 36 item 5): the sleeping top and the motions through the
vertical are reduced, classified and timed, against mpmath, the full equations and the
vertical spin's stability threshold."""

import json

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.reduction import RoughLevel, orbits, steady_motions

from ..test_cli import run_cli

#: Periods by the reduction's quadrature against mpmath's tanh-sinh at 40 digits.
PERIOD_RTOL = 1e-10
#: gamma3's turning point against mpmath's root.
TURNING_ABS = 1e-12
#: Half the orbit's period against the time between gamma3's minima of a full run (rtol 1e-12,
#: minima located by a parabola through three samples 1e-3 apart).
RUN_RTOL = 1e-7
#: gamma3 = cos(theta) of the steady motion at the pole theta = 0: within a few ulps of 1.
POLE_ATOL = 1e-15

BODY = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)


@pytest.fixture(autouse=True)
def digits40():
    """Every mpmath computation here at 40 digits (restored after each test)."""
    with mp.workdps(40):
        yield


def mp_level(body, w1, w3, pole=1):
    """Jellett's and Routh's integrals, h, U and rho of the state at the pole ``gamma3 = pole``
    with ``omega = (w1, 0, w3)``, written out (no reduction code)."""
    R, m, g, a3, I1, I3 = (mp.mpf(getattr(body, k)) for k in ("R", "m", "g", "a3", "I1", "I3"))
    c0 = mp.mpf(pole)
    k0 = R * c0 + a3

    def f(theta):
        k = R * mp.cos(theta) + a3
        return I1 * I3 + m * I1 * R**2 * mp.sin(theta) ** 2 + m * I3 * k**2

    jellett = -I3 * k0 * w3  # (I w, r) with r = -(R c0 + a3) e3 at the pole
    routh = w3 * mp.sqrt(f(mp.acos(c0)))

    def U(theta):
        s, c = mp.sin(theta), mp.cos(theta)
        k = R * c + a3
        spin = routh / mp.sqrt(f(theta))
        w_n = (jellett + I3 * k * spin) / (I1 * R * s)
        return (I1 * w_n**2 + I3 * spin**2 + m * (R * s * spin + k * w_n) ** 2) / 2 + m * g * a3 * c

    def rho(theta):
        return I1 + m * (R**2 + a3**2 + 2 * a3 * R * mp.cos(theta))

    theta0 = mp.acos(c0)
    h = (I3 * w3**2) / 2 + m * g * a3 * c0 + rho(theta0) * mp.mpf(w1) ** 2 / 2
    return float(jellett), float(routh), h, U, rho


@pytest.mark.parametrize("pole", [1, -1])
def test_a_motion_through_the_vertical_has_the_quadratures_period(pole):
    """Through the pole: U is even about it, so the orbit is [-theta1, theta1] about the pole and
    its period is 4 times the integral from the pole to the turning point of
    sqrt(rho / (2 (h - U)))."""
    jellett, routh, h, U, rho = mp_level(BODY, 0.5, 2.0, pole)
    level = RoughLevel(BODY, jellett=jellett, routh=routh)
    assert level.pole == ("south" if pole == 1 else "north")
    (orbit,) = orbits(level, float(h))
    assert orbit.pole_passage and orbit.kind == "periodic"
    theta_p = mp.mpf(0) if pole == 1 else mp.pi
    turn = mp.findroot(lambda t: U(t) - h, theta_p + mp.mpf("0.4") * pole)
    # the real part: tanh-sinh nodes within round-off of the turning point see h - U < 0
    period = 4 * mp.re(
        mp.quad(lambda t: mp.sqrt(rho(t) / (2 * (h - U(t)))), sorted([theta_p, turn]))
    )
    assert orbit.period == pytest.approx(float(period), rel=PERIOD_RTOL)
    edge = orbit.gamma3_min if pole == 1 else orbit.gamma3_max
    assert edge == pytest.approx(float(mp.cos(turn)), abs=TURNING_ABS)


def test_the_sleeping_tops_type_changes_at_the_stability_threshold(capsys, tmp_path):
    """The sleeping top is the centre of its pole level above the critical spin of
    `rollingtop stability` (its closed form) and a saddle below it."""
    path = tmp_path / "s.toml"
    path.write_text(
        "[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
        '[contact]\nmodel = "rough"\n[initial]\ngamma = [0.0, 0.0, 1.0]\n'
        "omega = [0.0, 0.0, 2.0]\n"
    )
    code, out, err = run_cli(capsys, "stability", str(path), "--json")
    assert code == 0, err
    (south,) = [v for v in json.loads(out)["vertical_spin"] if v["pole"] == "south"]
    critical = south["omega3_closed_form"]
    for factor, kind in ((0.9, "saddle"), (1.1, "center")):
        w3 = factor * critical
        jellett, routh, _, _, _ = mp_level(BODY, 0.0, w3)
        motions = steady_motions(RoughLevel(BODY, jellett=jellett, routh=routh))
        at_pole = [m for m in motions if m.gamma3 == pytest.approx(1.0, abs=POLE_ATOL)]
        assert len(at_pole) == 1 and at_pole[0].type == kind, (factor, motions)


def test_a_run_through_the_vertical_has_half_the_orbits_period(tmp_path, capsys):
    """gamma3's minima of a full run (rtol 1e-12) through the upright vertical come every half
    period of the reduced orbit (theta passes the pole, so gamma3 = cos(theta) repeats twice)."""
    from rollingtop.scenario import load_scenario
    from rollingtop.simulate import simulate

    path = tmp_path / "t.toml"
    path.write_text(
        "[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
        '[contact]\nmodel = "rough"\n[initial]\ngamma = [0.0, 0.0, 1.0]\n'
        "omega = [0.5, 0.0, 2.0]\n[integration]\nt_end = 30.0\nrtol = 1e-12\n"
        "atol = 1e-14\nsamples = 30001\n"
    )
    code, out, err = run_cli(capsys, "orbits", str(path), "--json")
    assert code == 0, err
    (orbit,) = json.loads(out)["orbits"]
    run = simulate(load_scenario(path))
    g3, t = run.y[:, 14], run.t
    i = np.flatnonzero((g3[1:-1] < g3[:-2]) & (g3[1:-1] <= g3[2:])) + 1
    dt = t[1] - t[0]
    minima = t[i] + 0.5 * (g3[i - 1] - g3[i + 1]) / (g3[i - 1] - 2 * g3[i] + g3[i + 1]) * dt
    assert len(minima) >= 8
    half = (minima[-1] - minima[0]) / (len(minima) - 1)
    assert half == pytest.approx(orbit["period"] / 2, rel=RUN_RTOL)
    assert g3.min() == pytest.approx(orbit["gamma3_min"], abs=1e-9)


def test_no_spin_is_both_poles_and_rolls_over(capsys, tmp_path):
    """``omega = (1, 0, 0)`` at gamma = (0, 0.6, 0.8): jellett = routh = 0, both poles; U = m g a3
    cos(theta) with the rolling's rho: the period of rolling over against mpmath."""
    path = tmp_path / "r.toml"
    path.write_text(
        "[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
        '[contact]\nmodel = "rough"\n[initial]\ngamma = [0.0, 0.6, 0.8]\n'
        "omega = [1.0, 0.0, 0.0]\n"
    )
    code, out, err = run_cli(capsys, "orbits", str(path), "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["level"]["pole"] == "both"
    (orbit,) = result["orbits"]
    rho = lambda t: mp.mpf("0.3") + (1 + mp.mpf("0.01") + 2 * mp.mpf("0.1") * mp.cos(t))  # noqa: E731
    theta0 = mp.acos(mp.mpf("0.8"))
    h = mp.mpf("0.1") * mp.mpf("0.8") + rho(theta0) / 2  # w_tau = 1 at the start
    U = lambda t: mp.mpf("0.1") * mp.cos(t)  # noqa: E731
    period = mp.quad(lambda t: mp.sqrt(rho(t) / (2 * (h - U(t)))), [-mp.pi, 0, mp.pi])
    assert result["level"]["h"] == pytest.approx(float(h), rel=1e-14)
    assert orbit["period"] == pytest.approx(float(period), rel=PERIOD_RTOL)
