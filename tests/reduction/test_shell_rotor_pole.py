"""The shell-rotor pair's pole levels (issue 36 item 5): the pair's sleeping top and its motions
through the vertical are reduced and timed, against mpmath (``Phi`` by integrating its
derivative, not its closed form) and the full equations."""

import json
import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.contact._shell_pair import pair_weight
from rollingtop.reduction import ShellRotorLevel, orbits, steady_motions
from rollingtop.reduction.level import LevelSetError

from ..test_cli import run_cli

#: Periods by the reduction's quadrature against mpmath's tanh-sinh at 40 digits.
PERIOD_RTOL = 1e-10
#: gamma3's turning point against mpmath's root.
TURNING_ABS = 1e-12
#: U and the precession next to the pole against mpmath (the cancellation-free form).
NEAR_POLE_RTOL = 1e-12
#: U''(0) by the reduction's complex step against mpmath's difference quotient.
CURVATURE_RTOL = 1e-9
#: Half the orbit's period against the time between gamma3's minima of a full run (rtol 1e-12,
#: minima located by a parabola through three samples 1e-3 apart).
RUN_RTOL = 1e-7

BODY = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5, shell_mass=0.2,
                    shell_inertia=0.13333333333333333)  # fmt: skip
SHELL = '[shell]\nmass = 0.2\ninertia = 0.13333333333333333\n[contact]\nmodel = "shell-rotor"\n'
BODY_TOML = "[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n" + SHELL


@pytest.fixture(autouse=True)
def digits40():
    """Every mpmath computation here at 40 digits (restored after each test)."""
    with mp.workdps(40):
        yield


def mp_pair(body, M3, omega30, pole=1):
    """The pole level with Lagrange's ``M3`` and the shell's spin ``omega30`` at the pole
    ``gamma3 = pole``, written out from the module docstring's ``U`` (no reduction code):
    ``Omega3`` from ``F6`` with ``Phi - Phi(pole)`` the quadrature of ``Phi' = k_p / sqrt(N)``.
    Returns the level's ``(jellett, C2)`` and mpmath's ``U``, ``rho`` and ``psi'``."""
    R, m, g, a3, I1, I3 = (mp.mpf(getattr(body, k)) for k in ("R", "m", "g", "a3", "I1", "I3"))
    ms, Js = mp.mpf(body.shell_mass), mp.mpf(body.shell_inertia)
    M3, omega30 = mp.mpf(M3), mp.mpf(omega30)
    M = m + ms
    K = M * I1 + m * ms * a3**2
    D0 = K + M * Js
    alpha = Js * (I1 + Js + ms * R**2 + m * R**2 + m * a3**2) + R**2 * K
    beta, kappa = 2 * Js * m * R * a3, R**2 * K

    def N(c):
        return alpha + beta * c - kappa * c**2

    def kp(c):
        return M * R * c + m * a3

    c0 = mp.mpf(pole)
    jellett = -kp(c0) * (M3 + Js * omega30) / M

    # Phi - Phi(pole) as the solution of Phi' = k_p / sqrt(N) (mpmath's Taylor-series ODE
    # solver, with u = |c - c0| >= 0 as its forward variable; cached between evaluations)
    phi_u = mp.odefun(lambda u, y: c0 * -kp(c0 - c0 * u) / mp.sqrt(N(c0 - c0 * u)), 0, 0)

    def omega3(theta):
        c = mp.cos(theta)
        dphi = phi_u(abs(c - c0))
        return (omega30 * mp.sqrt(N(c0)) - R * M3 * dphi) / mp.sqrt(N(c))

    def w_n(theta):
        c, s = mp.cos(theta), mp.sin(theta)
        if s == 0:  # its limit at the pole (the numerator's round-off over s is not)
            return mp.mpf(0)
        return (M * jellett + kp(c) * (M3 + Js * omega3(theta))) / (R * s * D0)

    def U(theta):
        c, s = mp.cos(theta), mp.sin(theta)
        A = I1 + Js + M * R**2 * c**2 + 2 * m * R * a3 * c + m * a3**2
        om, wn = omega3(theta), w_n(theta)
        return (A * wn**2 / 2 + R * s * kp(c) * wn * om + (Js + M * R**2 * s**2) * om**2 / 2
                + m * g * a3 * c)  # fmt: skip

    def rho(theta):
        return I1 + Js + ms * R**2 + m * (R**2 + a3**2 + 2 * a3 * R * mp.cos(theta))

    def psi_dot(theta):
        return -w_n(theta) / mp.sin(theta)

    N0, phi0 = pair_weight(body, float(pole))
    C2 = float(omega30) * math.sqrt(float(N0)) + body.R * float(M3) * float(phi0)
    return float(jellett), C2, U, rho, psi_dot


@pytest.mark.parametrize("pole", [1, -1])
def test_a_motion_through_the_vertical_has_the_quadratures_period(pole):
    """Through the pole U is even about it: the orbit is [-theta1, theta1] about the pole and its
    period 4 times the integral from the pole to the turning point of sqrt(rho / (2 (h - U)))."""
    jellett, C2, U, rho, _ = mp_pair(BODY, 1.5, 2.5, pole)
    level = ShellRotorLevel(BODY, M3=1.5, C2=C2, jellett=jellett)
    assert level.pole == ("south" if pole == 1 else "north")
    theta_p = mp.mpf(0) if pole == 1 else mp.pi
    h = U(theta_p + mp.mpf("1e-30")) + rho(theta_p) * mp.mpf("0.5") ** 2 / 2  # w_tau = 0.5
    (orbit,) = orbits(level, float(h))
    assert orbit.pole_passage and orbit.kind == "periodic"
    turn = mp.findroot(lambda t: U(t) - h, theta_p + mp.mpf("0.3") * pole)
    period = 4 * mp.re(
        mp.quad(lambda t: mp.sqrt(rho(t) / (2 * (h - U(t)))), sorted([theta_p, turn]))
    )
    assert orbit.period == pytest.approx(float(period), rel=PERIOD_RTOL)
    edge = orbit.gamma3_min if pole == 1 else orbit.gamma3_max
    assert edge == pytest.approx(float(mp.cos(turn)), abs=TURNING_ABS)


@pytest.mark.parametrize("pole", [1, -1])
def test_next_to_the_pole_U_and_the_precession_keep_their_digits(pole):
    """theta 1e-9 .. 0.5 from the pole: U and psi' (= -w_n / s, a difference of nearly equal terms
    over s^2 written out) against mpmath at 40 digits; at the pole itself their limits."""
    jellett, C2, U, _, psi_dot = mp_pair(BODY, -0.8, 1.7, pole)
    level = ShellRotorLevel(BODY, M3=-0.8, C2=C2, jellett=jellett)
    theta_p = 0.0 if pole == 1 else math.pi
    for d in (1e-9, 1e-6, 1e-3, 0.5):
        theta = theta_p + d
        exact = mp.mpf(theta_p) + mp.mpf(d)
        assert float(level.U(theta)) == pytest.approx(float(U(exact)), rel=NEAR_POLE_RTOL)
        assert float(level.psi_dot(theta)) == pytest.approx(float(psi_dot(exact)),
                                                            rel=NEAR_POLE_RTOL)  # fmt: skip
    at_pole = psi_dot(mp.mpf(theta_p) + mp.mpf("1e-14"))  # psi' even: O(1e-28) off its limit
    assert float(level.psi_dot(theta_p)) == pytest.approx(float(at_pole), rel=NEAR_POLE_RTOL)


def test_the_sleeping_top_is_a_centre_or_a_saddle_as_U_curves():
    """The pair's sleeping top is the steady motion at the pole; its type follows the sign of
    U''(0) by mpmath's derivative of the written-out U, on both sides of the threshold."""
    kinds = set()
    for omega30 in (0.2, 0.6, 1.0, 3.0):
        jellett, C2, U, _, _ = mp_pair(BODY, 0.5 * omega30, omega30)
        level = ShellRotorLevel(BODY, M3=0.5 * omega30, C2=C2, jellett=jellett)
        (at_pole,) = [m for m in steady_motions(level) if m.theta == 0.0]
        # U even: U(d) = U(0) + U''(0) d^2 / 2 + O(d^4), so O(1e-12) off with d = 1e-6
        d = mp.mpf("1e-6")
        curvature = 2 * (U(d) - U(mp.mpf(0))) / d**2
        assert at_pole.U2_theta == pytest.approx(float(curvature), rel=CURVATURE_RTOL)
        kind = "center" if curvature > 0 else "saddle"
        assert at_pole.type == kind
        kinds.add(kind)
    assert kinds == {"center", "saddle"}


def test_no_spin_is_both_poles_and_spin_at_both_poles_is_refused():
    """``M3 = jellett = C2 = 0``: both poles, U = m g a3 cos; a level with spin through both
    poles (a one-parameter family) is refused in one line naming it."""
    level = ShellRotorLevel(BODY, M3=0.0, C2=0.0, jellett=0.0)
    assert level.pole == "both"
    theta = np.array([-1.0, 0.0, 0.3, 2.0])
    assert level.U(theta) == pytest.approx(0.1 * np.cos(theta), abs=1e-16)
    # the family: (m + ms) jellett + k_p (M3 + Js Omega3) = 0 at both poles, solved for C2, j
    b, M = BODY, BODY.m + BODY.shell_mass
    rows, rhs = [], []
    for c in (1.0, -1.0):
        N, phi = pair_weight(b, c)
        kp = M * b.R * c + b.m * b.a3
        # M j + kp Js C2 / sqrt(N) = -kp (M3 - Js R M3 phi / sqrt(N)) with M3 = 1
        rows.append([M, kp * b.shell_inertia / math.sqrt(N)])
        rhs.append(-kp * (1.0 - b.shell_inertia * b.R * phi / math.sqrt(N)))
    j, C2 = np.linalg.solve(rows, rhs)
    with pytest.raises(LevelSetError, match="both poles with spin") as info:
        ShellRotorLevel(BODY, M3=1.0, C2=C2, jellett=j)
    assert "\n" not in str(info.value)


def test_a_run_through_the_vertical_has_half_the_orbits_period(tmp_path, capsys):
    """gamma3's minima of a full run (rtol 1e-12) of the pair started upright with a tilt rate
    come every half period of the reduced orbit (row 1's scenario, now classified)."""
    from rollingtop.scenario import load_scenario
    from rollingtop.simulate import simulate

    path = tmp_path / "t.toml"
    path.write_text(
        BODY_TOML + "[initial]\ngamma = [0.0, 0.0, 1.0]\nomega = [0.5, 0.0, 3.0]\nv_tau = 0.0\n"
        "[integration]\nt_end = 30.0\nrtol = 1e-12\natol = 1e-14\nsamples = 30001\n"
    )
    code, out, err = run_cli(capsys, "orbits", str(path), "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["level"]["pole"] == "south"
    (orbit,) = result["orbits"]
    assert orbit["pole_passage"]
    run = simulate(load_scenario(path))
    g3, t = run.y[:, 14], run.t
    i = np.flatnonzero((g3[1:-1] < g3[:-2]) & (g3[1:-1] <= g3[2:])) + 1
    dt = t[1] - t[0]
    minima = t[i] + 0.5 * (g3[i - 1] - g3[i + 1]) / (g3[i - 1] - 2 * g3[i] + g3[i + 1]) * dt
    assert len(minima) >= 8
    half = (minima[-1] - minima[0]) / (len(minima) - 1)
    assert half == pytest.approx(orbit["period"] / 2, rel=RUN_RTOL)
    assert g3.min() == pytest.approx(orbit["gamma3_min"], abs=1e-9)
