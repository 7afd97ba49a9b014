"""The reductions of the smooth, rough and rubber models (rollingtop.reduction.smooth, .rough,
.rubber) against
independent sources: the full equations of tests/dynamics/reference.py integrated by solve_ivp,
mpmath quadrature, and the integrals of the full state."""

import math
import tomllib
from dataclasses import replace

import mpmath as mp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import INTEGRALS, ScenarioError, initial_state
from rollingtop.dynamics.integrals import evaluate
from rollingtop.reduction import (
    RoughLevel,
    RubberLevel,
    ShellRotorLevel,
    SmoothLevel,
    orbits,
    reduction_of,
    state_from_level,
    states_on_level,
    steady_motions,
)
from rollingtop.scenario import Scenario

from ..dynamics import reference

FULL_RTOL = 1e-12  # solve_ivp's rtol for the full system (issue 24: <= 1e-12)
AGREE = 1e-8  # issue 24: turning points, period and delta_psi against the full system
QUAD_RTOL = 1e-10  # the period's quadrature against mpmath
STEADY_DRIFT = 1e-9  # issue 24: gamma3 on a steady motion over 10 periods
STATE_TOL = 1e-12  # integrals of a reconstructed state
#: A critical point at the pole theta = 0 (an O(1) angle): a few ulps.
POLE_THETA_ATOL = 1e-15


MODELS = ["smooth", "rough", "rubber", "shell-rotor"]
#: The shell of the shell-rotor pair (a thin shell: Js = 2/3 ms R^2), as examples/shell_rotor.toml
SHELL = {"shell_mass": 0.2, "shell_inertia": 0.2 * 2 / 3}


@pytest.fixture(params=[0.1, -0.1], ids=["com_above", "com_below"])
def body(request, paper_body):
    """The paper's body with its centre of mass above (a3 > 0) or below the sphere's centre;
    inside a shell for a test of the shell-rotor pair (its ``model`` parameter)."""
    callspec = getattr(request.node, "callspec", None)
    shell = SHELL if callspec is not None and callspec.params.get("model") == "shell-rotor" else {}
    return replace(paper_body, a3=request.param, **shell)


def _state(model, body, gamma, omega):
    free = {"smooth": {"v_horizontal": (0.25, 0.0)}, "shell-rotor": {"v_tau": 0.3}}.get(model)
    if model == "rubber":  # no spin about the normal: the horizontal part of omega
        g = np.asarray(gamma, dtype=float) / np.linalg.norm(gamma)
        omega = np.asarray(omega, dtype=float) - np.dot(omega, g) * g
    return initial_state(body, model, gamma=gamma, omega=omega, free=free)


def _residuals(model, body, y):
    """The model's constraints at ``y`` (the pair: its shell's rolling,
    ``v - a3 w x e3 - R Omega x gamma = 0``, ``Omega = w + delta e3``)."""
    if model != "shell-rotor":
        return reference.residuals(model, body.params, y)
    w, gamma = y[3:6], y[12:15]
    e3 = np.array([0.0, 0.0, 1.0])
    return y[0:3] - body.a3 * np.cross(w, e3) - body.R * np.cross(w + y[17] * e3, gamma)


def _random_level(model, body, rng):
    """A level of ``model`` from a random state (every level a state can have)."""
    while True:
        g = rng.normal(size=3)
        g /= np.linalg.norm(g)
        if abs(g[2]) < 0.9:
            y = _state(model, body, g, rng.normal(size=3))
            return reduction_of(model).level_of_state(body, y), y


def _full_run(model, body, y0, t_end):
    """The full system of ``model`` (reference.rhs, not the package's kernels) by solve_ivp,
    with the maxima and the minima of gamma3 as events."""
    p = body.params

    def f(t, y):
        if model == "shell-rotor":  # Newton-Euler for rotor and shell
            return reference.shell_rotor_rhs(p, y)[0]
        return reference.rhs(model, p, y)[0]

    def top(t, y):  # gamma3' = (gamma x w)_3 turning from + to -
        return y[12] * y[4] - y[13] * y[3]

    def bottom(t, y):
        return top(t, y)

    top.direction = -1
    bottom.direction = 1
    return solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=FULL_RTOL, atol=1e-13,
                     events=(top, bottom), dense_output=True)  # fmt: skip


@pytest.mark.parametrize("model", MODELS)
def test_a_reconstructed_state_has_its_level_and_energy(model, body, rng):
    """state_from_level: on the model's constraints, with the level's integrals, and the energy
    computed from the full state (the model's, integrals.evaluate) is the level's full_energy(h)."""
    reduction = reduction_of(model)
    for _ in range(20):
        level, _ = _random_level(model, body, rng)
        theta = rng.uniform(0.3, 2.8)
        h = float(level.U(theta)) + rng.uniform(0.0, 1.0)
        y = state_from_level(level, h, math.cos(theta), branch=int(rng.choice([-1, 1])),
                             phi=rng.uniform(0, 6), psi=rng.uniform(0, 6))  # fmt: skip
        assert np.max(np.abs(_residuals(model, body, y))) < STATE_TOL
        E = evaluate(body, y, ["energy"], model=model)["energy"]
        assert E == pytest.approx(level.full_energy(h), rel=STATE_TOL, abs=STATE_TOL)
        values = reduction.integrals(body, y)
        for name, expected in level.values().items():
            assert values[name] == pytest.approx(expected, abs=STATE_TOL)
        assert values["h"] == pytest.approx(h, abs=STATE_TOL)


@pytest.mark.parametrize("model", MODELS)
def test_states_on_level_are_the_states_of_state_from_level(model, body, rng):
    level, _ = _random_level(model, body, rng)
    c = steady_motions(level)[0].theta
    theta = np.array([c - 0.05, c, c + 0.05])
    w_tau = np.array([0.3, -0.1, 0.0])
    Y = states_on_level(level, np.cos(theta), w_tau)
    for t, wt, y in zip(theta, w_tau, Y, strict=True):
        h = float(level.energy(t, wt))
        expected = state_from_level(level, h, math.cos(t), branch=1 if wt >= 0 else -1)
        np.testing.assert_allclose(y[:15], expected[:15], atol=1e-12)


def _mp_pair_potential(level):
    """The pair's U and rho in mpmath from its vectors (not the module's coefficients): at
    w_tau = 0, Omega3 from F6 = C2 (N, Phi as in rollingtop.symbolic.shell_rotor.f6_pair),
    w_n from the Jellett integral (K_G, r_G) solved as a linear equation in w_n, then
    U = T + m g a3 gamma3 - M3^2/(2 I3) with T = m v^2/2 + (w, I w)/2 + ms v_O^2/2 + Js Omega^2/2.
    """
    b = level.body
    m, ms, Js, R, a3 = b.m, b.shell_mass, b.shell_inertia, b.R, b.a3
    K = (m + ms) * b.I1 + m * ms * a3**2
    alpha = Js * (b.I1 + Js + ms * R**2 + m * R**2 + m * a3**2) + R**2 * K
    beta, kappa, p = 2 * Js * m * R * a3, R**2 * K, (m + ms) * R

    def vectors(t, w_n):
        s, c = mp.sin(t), mp.cos(t)
        N = alpha + beta * c - kappa * c**2
        arc = mp.acos((2 * kappa * c - beta) / mp.sqrt(beta**2 + 4 * alpha * kappa))
        phi = -p / kappa * mp.sqrt(N) - (m * a3 + p * beta / (2 * kappa)) / mp.sqrt(kappa) * arc
        Om3 = (level.C2 - R * level.M3 * phi) / mp.sqrt(N)
        w3 = level.M3 / b.I3
        gamma, e3 = mp.matrix([-s, 0, c]), mp.matrix([0, 0, 1])
        w = mp.matrix([w_n, 0, w3])  # n = (1, 0, 0), tau = (0, -1, 0) at this azimuth
        Om = w + (Om3 - w3) * e3
        v_O = R * _mp_cross(Om, gamma)
        v = v_O + a3 * _mp_cross(w, e3)
        return gamma, e3, w, Om, v_O, v

    def jellett(t, w_n):
        gamma, e3, w, Om, v_O, v = vectors(t, w_n)
        O = -a3 * e3
        G = ms * O / (m + ms)
        Iw = mp.matrix([b.I1 * w[0], b.I1 * w[1], b.I3 * w[2]])
        K_G = Iw + Js * Om + m * _mp_cross(-G, v) + ms * _mp_cross(O - G, v_O)
        r_G = -R * gamma - a3 * e3 - G
        return sum(K_G[i] * r_G[i] for i in range(3))

    def U(t):
        j0, j1 = jellett(t, 0), jellett(t, 1)  # linear in w_n
        gamma, e3, w, Om, v_O, v = vectors(t, (level.jellett - j0) / (j1 - j0))
        T = (m * sum(x**2 for x in v) + b.I1 * (w[0] ** 2 + w[1] ** 2) + b.I3 * w[2] ** 2
             + ms * sum(x**2 for x in v_O) + Js * sum(x**2 for x in Om)) / 2  # fmt: skip
        return T + m * b.g * a3 * mp.cos(t) - level.M3**2 / (2 * b.I3)

    def rho(t):
        return b.I1 + Js + ms * R**2 + m * (R**2 + a3**2 + 2 * a3 * R * mp.cos(t))

    return U, rho


def _mp_cross(a, b):
    return mp.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0]])  # fmt: skip


def _mp_potential(level):
    """The level's U and rho written again in mpmath from the module docstrings' formulas."""
    b = level.body
    if isinstance(level, SmoothLevel):
        M3, C1 = level.M3, level.C1

        def U(t):
            return ((C1 - M3 * mp.cos(t)) ** 2 / (2 * b.I1 * mp.sin(t) ** 2)
                    + b.m * b.g * b.a3 * mp.cos(t) + level.p_horizontal**2 / (2 * b.m))  # fmt: skip

        def rho(t):
            return b.I1 + b.m * b.a3**2 * mp.sin(t) ** 2

        return U, rho
    if isinstance(level, ShellRotorLevel):  # the pair's T at w_tau = 0, from its vectors
        return _mp_pair_potential(level)
    if isinstance(level, RubberLevel):  # T of a horizontal w with w_tau = 0, w = Omega nu

        def U(t):
            s, c, k = mp.sin(t), mp.cos(t), b.R * mp.cos(t) + b.a3
            J = b.I1 * c**2 + b.I3 * s**2 + b.m * (b.R + b.a3 * c) ** 2
            w3 = level.rubber_spin / mp.sqrt(b.I3 * J)
            w_n = w3 * c / s
            return (b.I1 * w_n**2 + b.I3 * w3**2 + b.m * (b.R * s * w3 + k * w_n) ** 2) / 2 + (
                b.m * b.g * b.a3 * c
            )

        def rho(t):
            return b.I1 + b.m * (b.R**2 + b.a3**2 + 2 * b.a3 * b.R * mp.cos(t))

        return U, rho
    J, D = level.jellett, level.routh

    def U(t):
        s, k = mp.sin(t), b.R * mp.cos(t) + b.a3
        w3 = D / mp.sqrt(b.I1 * b.I3 + b.m * b.I1 * b.R**2 * s**2 + b.m * b.I3 * k**2)
        w_n = (J + b.I3 * k * w3) / (b.I1 * b.R * s)
        return (b.I1 * w_n**2 + b.I3 * w3**2 + b.m * (b.R * s * w3 + k * w_n) ** 2) / 2 + (
            b.m * b.g * b.a3 * mp.cos(t)
        )

    def rho(t):
        return b.I1 + b.m * (b.R**2 + b.a3**2 + 2 * b.a3 * b.R * mp.cos(t))

    return U, rho


@pytest.mark.parametrize("model", MODELS)
def test_the_period_agrees_with_mpmath(model, body, rng):
    """T = 2 int sqrt(rho / (2 (h - U))) dtheta between the turning points, by mpmath's
    tanh-sinh rule (which takes the endpoint singularities) at 30 digits, with U and rho
    written again from the formulas."""
    level, _ = _random_level(model, body, rng)
    h = float(steady_motions(level)[0].U) + 0.3
    o = orbits(level, h)[0]
    U, rho = _mp_potential(level)
    with mp.workdps(30):
        lo = mp.findroot(lambda t: U(t) - h, o.theta_min)
        hi = mp.findroot(lambda t: U(t) - h, o.theta_max)
        T = 2 * mp.quad(lambda t: mp.sqrt(rho(t) / (2 * (h - U(t)))), [lo, hi])
    assert o.theta_min == pytest.approx(float(lo), abs=1e-13)
    assert o.theta_max == pytest.approx(float(hi), abs=1e-13)
    assert o.period == pytest.approx(float(T), rel=QUAD_RTOL)


@pytest.mark.parametrize("model", MODELS)
def test_orbits_from_an_initial_state_agree_with_the_full_system(model, body):
    """Issue 24's criterion: a scenario with only [initial] has exactly one orbit through its
    gamma3, whose turning points, period and delta_psi agree with solve_ivp on the full
    equations to 1e-8."""
    y0 = _state(model, body, [0.0, 0.6, 0.8], [0.7, -0.3, 2.0])
    reduction = reduction_of(model)
    level = reduction.level_of_state(body, y0)
    h = reduction.reduced_energy(body, y0)
    found = [o for o in orbits(level, h) if o.gamma3_min <= y0[14] <= o.gamma3_max]
    assert len(found) == 1 and found[0].kind == "periodic"
    o = found[0]
    sol = _full_run(model, body, y0, 4.2 * o.period)
    t_top, y_top = sol.t_events[0], sol.y_events[0]
    assert len(t_top) >= 3
    np.testing.assert_allclose(np.diff(t_top), o.period, rtol=AGREE)
    np.testing.assert_allclose(y_top[:, 14], o.gamma3_max, atol=AGREE)
    ts = np.linspace(t_top[0], t_top[1], 4001)
    g3 = sol.sol(ts)[14]
    assert g3.min() == pytest.approx(o.gamma3_min, abs=1e-6)  # sampled: the bound only
    # the axis's azimuth (its horizontal projection in the fixed frame) over one period
    psi = [math.atan2(y[11], y[8]) for y in y_top[:2]]
    advance = sol.sol(np.linspace(t_top[0], t_top[1], 200))
    unwrapped = np.unwrap(np.arctan2(advance[11], advance[8]))
    dpsi = unwrapped[-1] - unwrapped[0]
    assert math.remainder(psi[1] - psi[0] - dpsi, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    from rollingtop.survey import survey_orbits

    (row,) = [r for r in survey_orbits(level, h) if r.orbit == o]
    assert row.period_map is not None
    assert row.period_map.delta_psi == pytest.approx(dpsi, abs=AGREE)
    if model == "smooth":  # the centre of mass drifts uniformly at |v_horizontal|
        assert row.period_map.motion == "uniform drift" and row.to_dict()["displacement"] is None
        assert row.period_map.drift_speed == pytest.approx(0.25, rel=1e-12)
    else:  # the CoM's displacement over a period: the full system's, as a vector
        # from the lowest turning point, the map's canonical start (PeriodMap: the CoM at the
        # origin and the axis azimuth 0 there)
        t_bottom = sol.t_events[1]
        start, end = sol.sol(t_bottom[0]), sol.sol(t_bottom[1])
        psi0 = math.atan2(start[11], start[8])
        moved = complex(end[15] - start[15], end[16] - start[16]) * complex(
            math.cos(psi0), -math.sin(psi0)
        )
        D = complex(*row.period_map.displacement)
        assert abs(moved - D) < 1e-7 * max(1.0, abs(D))


@pytest.mark.parametrize("model", MODELS)
def test_a_steady_motion_stays_steady(model, body, rng):
    """Started on a centre of U (w_tau = 0), the full system keeps gamma3 within 1e-9 over 10
    periods of the nearby orbits."""
    level, _ = _random_level(model, body, rng)
    m = [m for m in steady_motions(level) if m.type == "center"][0]
    y0 = state_from_level(level, m.U, m.gamma3)
    sol = _full_run(model, body, y0, 10 * m.period)
    g3 = sol.sol(np.linspace(0.0, 10 * m.period, 2001))[14]
    assert np.max(np.abs(g3 - m.gamma3)) < STEADY_DRIFT
    # and its frequency is the small oscillations' (the limit of nearby orbits' periods)
    near = [o for o in orbits(level, m.U + 1e-8) if o.theta_min <= m.theta <= o.theta_max][0]
    assert near.period == pytest.approx(m.period, rel=1e-4)


def test_a_level_table_of_the_smooth_model():
    """[level] takes the smooth model's own integrals; C2 is refused with the right names."""
    base = """
[body]
R = 1.0
m = 1.0
g = 1.0
a3 = 0.1
I1 = 0.3
I3 = 0.5
[contact]
model = "smooth"
[level]
M3 = 1.0
C1 = 0.5
h = 0.8
"""
    sc = Scenario.from_dict(tomllib.loads(base))
    level = sc.level_set()
    assert isinstance(level, SmoothLevel) and level.values() == {
        "M3": 1.0, "C1": 0.5, "p_horizontal": 0.0}  # fmt: skip
    y0 = sc.require_state()
    assert reduction_of("smooth").reduced_energy(sc.body, y0) == pytest.approx(0.8, abs=1e-12)
    with pytest.raises(ScenarioError, match=r"level\.C2 for the smooth model \(its level: M3, "
                                            r"C1, p_horizontal"):  # fmt: skip
        Scenario.from_dict(tomllib.loads(base + "C2 = -2.0\n"))


def test_models_without_a_reduction_are_refused_in_one_line():
    with pytest.raises(ScenarioError, match="parallel model has no reduction.*section.*chaos"):
        reduction_of("parallel")


def test_every_declared_reduction_is_registered_with_the_same_names():
    """ContactModel.reduction (the declaration the contact package makes) names what
    rollingtop.reduction.models builds."""
    from rollingtop.contact import MODELS
    from rollingtop.reduction import REDUCTIONS

    declared = {name: m.reduction for name, m in MODELS.items() if m.reduction}
    assert declared == {name: r.names for name, r in REDUCTIONS.items()}
    assert set(declared) == {"meridian", "smooth", "rough", "rubber", "shell-rotor"}


def test_a_rough_pole_level_is_reduced(paper_body):
    """The vertical spin's level (jellett + I3 k w3 = 0 at gamma3 = 1) is a south pole level
    (issue 36 item 5; was refused): U is finite and even about the pole, whose steady motion is
    the sleeping top (tests/reduction/test_rough_pole.py times its orbits against mpmath)."""
    b = paper_body
    k = b.R + b.a3
    routh = 1.0
    w3 = routh / math.sqrt(b.I1 * b.I3 + b.m * b.I3 * k**2)
    level = RoughLevel(b, jellett=-b.I3 * k * w3, routh=routh)
    assert level.pole == "south" and level.theta_domain == (-math.pi, math.pi)
    theta = np.array([1e-9, 1e-4, 0.3])
    assert level.U(theta) == pytest.approx(level.U(-theta), rel=1e-15)
    assert float(level.U(0.0)) == pytest.approx(0.5 * b.I3 * w3**2 + b.m * b.g * b.a3, rel=1e-15)
    assert any(m.theta == pytest.approx(0.0, abs=POLE_THETA_ATOL) for m in steady_motions(level))


@pytest.mark.parametrize("model", ["meridian", *MODELS])
def test_the_normal_force_of_a_level_is_the_full_systems(model, body, rng):
    """LevelSet.normal_force (the portraits' shading, NumPy) against the contact force of the
    full equations (reference.rhs) at the reconstructed states: its component along gamma."""
    if model == "meridian":
        level = reduction_of(model).level_of_state(
            body, initial_state(body, model, gamma=[0.0, 0.6, 0.8], omega=[0.7, -0.3, 2.0])
        )
    else:
        level, _ = _random_level(model, body, rng)
    c = steady_motions(level)[0].theta
    for theta, w_tau in ((c, 0.0), (c - 0.05, 0.4), (c + 0.05, -0.3)):
        h = float(level.energy(theta, w_tau))
        y = state_from_level(level, h, math.cos(theta), branch=1 if w_tau >= 0 else -1)
        force = (reference.shell_rotor_rhs if model == "shell-rotor" else
                 lambda p, y: reference.rhs(model, p, y))(body.params, y)[1]  # fmt: skip
        assert float(level.normal_force(theta, w_tau)) == pytest.approx(
            float(force @ y[12:15]), rel=1e-10, abs=1e-12
        )


def test_every_integral_a_reduction_uses_is_claimed_and_so_proved_by_verify():
    """The level's integrals are among the model's claimed integrals
    (ContactModel.integrals_symmetric), which `rollingtop verify` proves symbolically
    (rollingtop.symbolic.claims.claims_for) and `simulate` monitors."""
    from rollingtop.contact import get_model
    from rollingtop.reduction import REDUCTIONS
    from rollingtop.symbolic.claims import claims_for

    uses = {"M3": ("lagrange",), "C1": ("area",), "C2": ("F6",),
            "p_horizontal": ("momentum_x", "momentum_y"), "jellett": ("jellett",),
            "routh": ("routh",), "rubber_spin": ("rubber_spin",)}  # fmt: skip
    for name, reduction in REDUCTIONS.items():
        claimed = get_model(name).integrals_symmetric
        proved = " ".join(c.name for c in claims_for(name)).lower()  # "Lagrange's", "F6"
        for level_name in reduction.names:
            for integral in uses[level_name]:
                assert integral in claimed, (name, integral)
                assert integral.lower() in proved, (name, integral)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda b: SmoothLevel(b, 1.0, 0.5, p_horizontal=1e300), "too large for double"),
        (lambda b: SmoothLevel(b, 1.0, 0.5, p_horizontal=-0.1), "must be finite and >= 0"),
        (lambda b: RoughLevel(b, jellett=1e300, routh=1e300), "too large for double"),
        (lambda b: RoughLevel(b, jellett=math.nan, routh=1.0), "must be finite"),
        (lambda b: RubberLevel(b, rubber_spin=1e200), "too large for double"),
        (lambda b: RubberLevel(b, rubber_spin=math.inf), "must be finite"),
        (lambda b: RubberLevel(b, rubber_spin="1"), "must be a number"),
    ],
)
def test_levels_out_of_range_are_refused_in_one_line(paper_body, make, message):
    """Huge or invalid integrals: a LevelSetError naming the level, never an OverflowError."""
    from rollingtop.reduction import LevelSetError

    with pytest.raises(LevelSetError, match=message):
        make(paper_body)


@pytest.mark.parametrize("model", MODELS)
def test_the_mirrored_level_sees_the_same_motion(model, body, rng):
    """mirrored(): the body axis reversed (theta -> pi - theta, a3 -> -a3): U, rho and psi'
    agree at pi - theta (what the north-pole handling relies on)."""
    level, _ = _random_level(model, body, rng)
    mirror = level.mirrored()
    theta = np.linspace(0.3, 2.8, 11)
    np.testing.assert_allclose(mirror.U(math.pi - theta), level.U(theta), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(mirror.rho(math.pi - theta), level.rho(theta), rtol=1e-14)
    np.testing.assert_allclose(mirror.psi_dot(math.pi - theta), level.psi_dot(theta),
                               rtol=1e-11, atol=1e-12)  # fmt: skip


@pytest.mark.parametrize("model", MODELS)
def test_dU_and_d2U_are_the_derivatives_of_U(model, body, rng):
    """The analytic dU (and d2U, its complex step) against mpmath's derivatives of U written
    again from the formulas (_mp_potential)."""
    level, _ = _random_level(model, body, rng)
    U, _ = _mp_potential(level)
    with mp.workdps(30):
        for theta in (0.4, 1.1, 1.9, 2.6):
            assert float(level.dU(theta)) == pytest.approx(float(mp.diff(U, theta)),
                                                           rel=1e-10, abs=1e-10)  # fmt: skip
            assert float(level.d2U(theta)) == pytest.approx(float(mp.diff(U, theta, 2)),
                                                            rel=1e-9, abs=1e-9)  # fmt: skip


def test_no_meridian_pole_limits_are_given_for_the_other_models(paper_body):
    """Near a pole level of the smooth or rough model, no near-pole limit is reported (the
    meridian model's limits and reactions do not apply); the orbits are still computed."""
    from rollingtop.survey import survey_orbits

    smooth = SmoothLevel(paper_body, 1.0, 0.999)
    b = paper_body
    k = b.R + b.a3
    routh = 1.0
    pole_j = -b.I3 * k * routh / math.sqrt(b.I1 * b.I3 + b.m * b.I3 * k**2)
    rough = RoughLevel(paper_body, jellett=pole_j + 0.01, routh=routh)
    for level in (smooth, rough):
        h = steady_motions(level)[0].U + 0.3
        rows = survey_orbits(level, h)
        assert rows and all(r.near_pole is None for r in rows)


def test_a_uniformly_drifting_level_has_no_reconstructed_path(paper_body):
    from rollingtop.absolute import reconstruct
    from rollingtop.reduction import LevelSetError

    level = SmoothLevel(paper_body, 1.0, 0.5, p_horizontal=0.2)
    with pytest.raises(LevelSetError, match="drifts uniformly"):
        reconstruct(level, [0.0, 1.0], theta0=1.0, w_tau0=0.0)


def test_a_rough_level_near_its_north_pole_level_is_computed_on_its_mirror(paper_body):
    """Jellett's integral 1e-6 from the north pole level: the level is mirrored (near_north,
    from its own pole offsets), and its orbit's turning points and period agree with mpmath's
    quadrature of U written again from the formulas."""
    from rollingtop.reduction.level import near_north

    b = paper_body
    k = -b.R + b.a3  # at the north pole, gamma3 = -1
    routh = 1.0
    pole_j = -b.I3 * k * routh / math.sqrt(b.I1 * b.I3 + b.m * b.I3 * k**2)
    level = RoughLevel(b, jellett=pole_j + 1e-6, routh=routh)
    assert near_north(level)
    h = steady_motions(level)[0].U + 0.3
    (o,) = orbits(level, h)
    U, rho = _mp_potential(level)
    with mp.workdps(40):
        lo = mp.findroot(lambda t: U(t) - h, (o.theta_min + o.theta_max) / 2 - 0.3)
        hi = mp.findroot(lambda t: U(t) - h, (o.theta_max - 1e-7, o.theta_max + 1e-9),
                         solver="anderson")  # fmt: skip
        T = 2 * mp.quad(lambda t: mp.sqrt(rho(t) / (2 * (h - U(t)))), [lo, hi])
    assert o.theta_max == pytest.approx(float(hi), abs=1e-12)
    assert o.period == pytest.approx(float(T), rel=QUAD_RTOL)


@pytest.mark.parametrize("pole", [1, -1], ids=["south", "north"])
def test_the_smooth_reduction_has_the_vertical_spins_threshold(paper_body, pole):
    """On the smooth plane's pole level (C1 = +-M3) the vertical spin is the critical point at
    the pole; U'' there changes sign at the closed-form threshold of the contact model
    (Vertical.spin: Lagrange's top about the centre of mass, 2 sqrt(I1 m g a)/I3
    with a = pole a3): a centre above it, a saddle below (both sides within 1 %)."""
    from rollingtop.contact import get_model

    for a3 in (0.1, -0.1):
        b = replace(paper_body, a3=a3)
        critical = get_model("smooth").vertical.spin(b, pole)
        if critical == 0.0:  # a <= 0: stable at every spin; check one
            spins = [0.5]
        else:
            spins = [0.99 * critical, 1.01 * critical]
        for w3 in spins:
            M3 = b.I3 * w3
            level = SmoothLevel(b, M3, pole * M3)
            theta = 0.0 if pole > 0 else math.pi
            stable = float(level.d2U(theta)) > 0
            assert stable == (w3 > critical), (a3, w3, critical)


def test_the_rubber_pole_level_rocks_through_the_vertical_as_the_full_system(body):
    """rubber_spin = 0 (no spin: w along tau): the body rolls in a vertical plane through the
    pole below its centre of mass (U = m g a3 cos theta on the whole circle). The orbit's far
    turning point and its period (two passes of that turning point) agree with solve_ivp on the
    full equations to 1e-8."""
    pole = -1.0 if body.a3 > 0 else 1.0  # the centre of mass's low side
    gamma = [0.0, 0.6, 0.8 * pole]
    tau = np.cross([0.0, 0.0, 1.0], gamma) / 0.6
    y0 = _state("rubber", body, gamma, 0.3 * tau)
    reduction = reduction_of("rubber")
    level = reduction.level_of_state(body, y0)
    assert level.pole == "both" and level.rubber_spin == 0.0  # snapped to the pole level: exact
    (o,) = orbits(level, reduction.reduced_energy(body, y0))
    assert o.kind == "periodic" and o.pole_passage
    far = o.gamma3_min if pole > 0 else o.gamma3_max
    assert abs(far) < 0.8
    sol = _full_run("rubber", body, y0, 2.2 * o.period)
    events = sol.y_events[1] if pole > 0 else sol.y_events[0]
    times = sol.t_events[1] if pole > 0 else sol.t_events[0]
    assert len(times) >= 3
    np.testing.assert_allclose(events[:, 14], far, atol=AGREE)
    np.testing.assert_allclose(np.diff(times), o.period / 2, rtol=AGREE)
    assert np.max(np.abs(INTEGRALS["rubber_spin"](body, sol.y.T))) < 1e-12


def test_rubber_rolling_has_one_centre_on_every_level(body, rng):
    """U' = 0 reads F^2 cos = -m g a3 I3 sin^4 (module docstring of rollingtop.reduction.rubber):
    one root in (0, pi), a centre, on the side of the axis away from the centre of mass
    (gamma3 a3 < 0); the steady motion found satisfies the closed form to 1e-12."""
    for F in rng.uniform(0.05, 3.0, size=8) * rng.choice([-1, 1], size=8):
        level = RubberLevel(body, rubber_spin=float(F))
        (m,) = steady_motions(level)
        assert m.type == "center" and m.gamma3 * body.a3 < 0
        s2 = 1 - m.gamma3**2
        lhs, rhs = F**2 * m.gamma3, -body.m * body.g * body.a3 * body.I3 * s2**2
        assert lhs == pytest.approx(rhs, rel=1e-12, abs=1e-14)


@pytest.mark.parametrize("F", [1e-3, 1e-5])
def test_a_rubber_level_near_its_pole_level_keeps_its_period(body, F):
    """A small rubber_spin puts a wall of width ~ F / sqrt(I3 h) next to each pole: an orbit
    that almost rolls over (both turning points beside a pole) and one that rocks beside the low
    pole; turning points and periods against mpmath (40 digits) of U written again from the
    kinetic energy (_mp_potential), to QUAD_RTOL."""
    level = RubberLevel(body, rubber_spin=F)
    U, rho = _mp_potential(level)
    b = body
    for h in (abs(b.m * b.g * b.a3) * 1.5, abs(b.m * b.g * b.a3) * 0.5):
        (o,) = orbits(level, h)
        with mp.workdps(40):
            lo = mp.findroot(lambda t, h=h: U(t) - h, (o.theta_min * 0.999, o.theta_min * 1.001),
                             solver="anderson")  # fmt: skip
            hi = mp.findroot(lambda t, h=h: U(t) - h, (o.theta_max - 1e-9 * (mp.pi - o.theta_max),
                                                  o.theta_max + 1e-9 * (mp.pi - o.theta_max)),
                             solver="anderson")  # fmt: skip
            T = 2 * mp.quad(lambda t, h=h: mp.sqrt(rho(t) / (2 * (h - U(t)))),
                            [lo, (lo + hi) / 2, hi])  # fmt: skip
        assert o.theta_min == pytest.approx(float(lo), rel=1e-9)
        assert math.pi - o.theta_max == pytest.approx(float(mp.pi - hi), rel=1e-6)
        assert o.period == pytest.approx(float(T), rel=QUAD_RTOL)


@pytest.mark.parametrize("F", [1e-6, 1e-9, 1e-13])
def test_a_rubber_level_near_its_pole_level_keeps_its_delta_psi(body, F):
    """delta_psi next to the pole level: psi' ~ F / sin^2 swings by about pi across each wall
    (of width ~F), the two walls of an orbit that almost rolls over cancel. The north wall is
    integrated on the mirror image (pi - theta loses the wall's digits); against mpmath at
    40 digits with psi' = -F cos / (sqrt(I3 J) sin^2) written again, to 1e-10 absolute, and the
    reported error bounds the difference."""
    from rollingtop.reduction.rotation import rotation_number

    b = body
    level = RubberLevel(b, rubber_spin=F)
    U, rho = _mp_potential(level)

    def psi_dot(t):
        J = b.I1 * mp.cos(t) ** 2 + b.I3 * mp.sin(t) ** 2 + b.m * (b.R + b.a3 * mp.cos(t)) ** 2
        return -F * mp.cos(t) / (mp.sqrt(b.I3 * J) * mp.sin(t) ** 2)

    for h in (abs(b.m * b.g * b.a3) * 1.5, abs(b.m * b.g * b.a3) * 0.5):
        (o,) = orbits(level, h)
        N, err = rotation_number(level, h, o)
        with mp.workdps(40):
            ends = []
            for t, pole in ((o.theta_min, 0), (o.theta_max, mp.pi)):
                d = abs(pole - t)  # bracket the root within 30% of its distance to the pole
                ends.append(mp.findroot(lambda x, h=h: U(x) - h,
                                        (pole + (t - pole) * 0.7, pole + (t - pole) * 1.3)
                                        if d < 0.5 else (t - 1e-6, t + 1e-6),
                                        solver="anderson"))  # fmt: skip
            lo, hi = ends
            c, d = (lo + hi) / 2, (hi - lo) / 2
            # theta = c + d sin(phi): smooth at the turning points; break points at the walls
            walls = [lo + (hi - lo) * k for k in (1e-12, 1e-9, 1e-6, 1e-3, 0.5)]
            walls += [hi - (hi - lo) * k for k in (1e-3, 1e-6, 1e-9, 1e-12)]
            phis = [-mp.pi / 2, *(mp.asin((x - c) / d) for x in walls), mp.pi / 2]

            def f(phi, h=h, c=c, d=d):
                t = c + d * mp.sin(phi)
                return psi_dot(t) * 2 * mp.sqrt(rho(t) / (2 * (h - U(t)))) * d * mp.cos(phi)

            dpsi = float(mp.re(mp.quad(f, phis)))
        assert 2 * math.pi * N == pytest.approx(dpsi, abs=1e-10)
        assert abs(2 * math.pi * N - dpsi) <= 2 * math.pi * err + 1e-15


def test_a_path_too_close_to_the_vertical_is_unresolved_not_a_hang(paper_body):
    """rubber_spin = 1e-12: the axis passes within ~1e-12 of the vertical, where its azimuth
    swings at ~h / rubber_spin. The orbit and its delta_psi (quadrature) are given; the path's
    displacement is reported unresolved after a bounded number of evaluations
    (absolute.MAX_PATH_EVALUATIONS), never integrated for hours."""
    from rollingtop.survey import survey_orbits

    level = RubberLevel(paper_body, rubber_spin=1e-12)
    (row,) = survey_orbits(level, 0.5)
    assert row.orbit.kind == "periodic" and row.orbit.theta_min < 1e-11
    assert row.period_map.motion == "unresolved"
    data = row.to_dict()
    assert data["displacement"] is None and math.isfinite(data["delta_psi"])


def test_a_level_table_starts_a_rolling_over_motion(paper_body):
    """[level] without [initial] on a level whose orbit rolls over (no turning point: the
    meridian model's no-spin level above the upright energy) starts at gamma3 = 0 with the
    level's energy; near a pole (rubber_spin = 1e-12) the turning point beside the pole is kept
    as an angle (cos would round it onto the pole)."""
    from rollingtop.reduction import LevelSet
    from rollingtop.reduction.start import start_on_level

    level = LevelSet(paper_body, 0.0, 0.0, 0.0)
    y = start_on_level(level, 0.5)
    assert y[14] == pytest.approx(0.0, abs=1e-15)
    assert INTEGRALS["energy"](paper_body, y) == pytest.approx(level.full_energy(0.5), rel=1e-14)
    rubber = RubberLevel(paper_body, rubber_spin=1e-12)
    y = start_on_level(rubber, 0.5)
    assert 1e-13 < math.hypot(y[12], y[13]) < 1e-11  # off the pole by the wall's width
    assert reduction_of("rubber").reduced_energy(paper_body, y) == pytest.approx(0.5, rel=1e-9)


def test_levels_of_the_other_models_take_their_integrals_by_keyword(paper_body):
    """Only the body is positional: values in the meridian model's order (M3, C1, C2) are
    refused, not put into fields the model ignores (a silent pole level)."""
    shell_body = replace(paper_body, **SHELL)
    for make in (
        lambda: RubberLevel(paper_body, 0.7),
        lambda: RoughLevel(paper_body, 0.1, 0.2),
        lambda: ShellRotorLevel(shell_body, 1.0, 0.0, 0.5),
        lambda: RubberLevel(paper_body),  # no silent default of the integral either
    ):
        with pytest.raises(TypeError):
            make()
    assert RubberLevel(paper_body, rubber_spin=0.7).rubber_spin == 0.7


@pytest.mark.parametrize("change", [{"a3": 0.0}, {"g": 0.0}], ids=["balanced", "no_gravity"])
def test_a_flat_potential_is_refused_for_steady_motions_and_rolls_over(paper_body, change):
    """rubber_spin = 0 on a balanced body (or without gravity): U is constant, every gamma3 is
    a steady motion. steady_motions says so in one line (it listed ~20000 'degenerate' points);
    the orbit rolls over uniformly, theta' = sqrt(2 h / rho) with rho constant for a3 = 0 (closed
    form, and the trapezoid rule of 1 / theta' over a turn for g = 0)."""
    from rollingtop.reduction import LevelSetError

    body = replace(paper_body, **change)
    level = RubberLevel(body, rubber_spin=0.0)
    with pytest.raises(LevelSetError, match="U is constant") as err:
        steady_motions(level)
    assert "\n" not in str(err.value)
    h = 0.65
    (o,) = orbits(level, h)
    assert o.kind == "periodic" and o.rolls_over
    theta = np.linspace(0.0, 2 * math.pi, 20001)
    rho = body.I1 + body.m * (body.R**2 + body.a3**2 + 2 * body.a3 * body.R * np.cos(theta))
    T = np.trapezoid(np.sqrt(rho / (2 * h)), theta)  # periodic integrand: spectral accuracy
    assert o.period == pytest.approx(T, rel=1e-12)


def test_a_wall_too_thin_for_doubles_is_refused_with_the_models_own_advice(paper_body):
    """A rubber level within 1e-17 of its pole level: the wall next to the pole is thinner than
    doubles resolve near pi; the refusal names the rubber model's pole level, not the meridian
    model's C1 = +-M3."""
    from rollingtop.reduction import LevelSetError

    with pytest.raises(LevelSetError, match="rubber_spin = 0 exactly") as err:
        orbits(RubberLevel(paper_body, rubber_spin=1e-17), 0.2)
    assert "C1" not in str(err.value)
