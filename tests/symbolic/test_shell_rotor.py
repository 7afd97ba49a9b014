"""The shell-rotor pair's symbolic module (rollingtop.symbolic.shell_rotor): its claims are proved,
wrong ones fail, and the equations derived from the Lagrangian (multipliers eliminated with the
full inverse of the mass matrix) equal the compiled kernel (an independent formulation: ``v``
solved from the constraints, a 4x4 system in ``(w, delta)``)."""

import numpy as np
import pytest
import sympy as sp

from rollingtop import SphericalTop, initial_state, simulate
from rollingtop.contact import MODELS
from rollingtop.symbolic import check, rhs_function
from rollingtop.symbolic import shell_rotor as P
from rollingtop.symbolic.claims import Claim
from rollingtop.symbolic.equations import SYMBOLS as S
from tests import kernels as _kernel

AGREE_RTOL = 1e-12  # derived accelerations vs the compiled kernel, relative to max |y'|
LIMIT_EPS = 1e-8  # ms, Js = LIMIT_EPS * (their random values): the numerical limit
LIMIT_RTOL = 1e-5  # pair vs meridian there: O(LIMIT_EPS), at most 3e-7 seen in 300 states
N_BODIES = 30
TRAJECTORY_T = 20.0
INTEGRAL_ATOL = 1e-8  # drift over TRAJECTORY_T at rtol 1e-11 (seen: 3e-10 over t = 50)

#: A word of each claim's name, one test per group (every claim is in one: a test).
GROUPS = ("energy", "axial spin w3", "ms = Js = 0", "det =", "Jellett", "F6")


@pytest.fixture(scope="module")
def pair_claims():
    return P.claims()


@pytest.fixture(scope="module")
def pair_rhs():
    """``f(params, y) -> (v', w', delta')`` of :func:`derive_pair` (symmetric rotor)."""
    d = P.derive_pair(True)
    params = (*S.params, P.MS, P.JS)
    state = (*S.v, *S.w, *S.gamma, P.DELTA)
    f = sp.lambdify([params, state], list(d.udot), "numpy", cse=True)

    def rhs(p, y):
        return np.array(f(tuple(p[:9]), (*y[0:6], *y[12:15], y[17])), dtype=float)

    return rhs


def _random_body(rng, shell=1.0):
    R = rng.uniform(0.5, 2.0)
    I1 = rng.uniform(0.1, 1.0)
    return SphericalTop(
        R=R,
        m=rng.uniform(0.5, 3.0),
        g=rng.uniform(0.0, 2.0),
        a3=rng.uniform(-0.8, 0.8) * R,
        I1=I1,
        I3=rng.uniform(0.1, 1.9) * I1,
        shell_mass=shell * rng.uniform(0.05, 2.0),
        shell_inertia=shell * rng.uniform(0.02, 1.0),
    )


def _random_state(rng, body):
    while True:
        gamma = rng.normal(size=3)
        gamma /= np.linalg.norm(gamma)
        if abs(gamma[2]) < 0.95:
            break
    y = initial_state(body, "shell-rotor", gamma=gamma, omega=rng.uniform(-2.0, 2.0, 3),
                      free={"v_tau": rng.uniform(-1.0, 1.0)})  # fmt: skip
    y[17] = rng.uniform(-2.0, 2.0)
    code = MODELS["shell-rotor"].code
    _kernel.project(code, body.params, y, _kernel.new_workspace())
    return y


@pytest.mark.slow  # ~15 s; rollingtop verify proves them too (test_every_claim_is_proved)
@pytest.mark.parametrize("group", GROUPS)
def test_claims_are_proved(pair_claims, group):
    chosen = [c for c in pair_claims if group in c.name]
    assert chosen
    for claim in chosen:
        result = check(claim)
        assert result.result == "proved", (claim.name, result.method)


def test_every_claim_is_in_a_group(pair_claims):
    assert all(c.model == "shell-rotor" for c in pair_claims)
    assert all(any(g in c.name for g in GROUPS) for c in pair_claims)


def _identity(name, expr, symmetric=True, params=()):
    return Claim(name, "shell-rotor", P.on_manifold(expr), "identity", symmetric, params)


def test_energy_without_the_shells_spin_is_not_conserved():
    d = P.derive_pair(True)
    Omega = S.w + P.DELTA * sp.Matrix([0, 0, 1])
    wrong = d.energy - P.JS * Omega.dot(Omega) / 2
    assert check(_identity("wrong energy", P.rate(wrong, d.field))).result == "failed"


def test_w3_is_not_conserved_for_an_asymmetric_rotor():
    d = P.derive_pair(False)
    assert check(_identity("w3", d.field[S.w[2]], symmetric=False)).result == "failed"


def test_the_bodys_jellett_form_needs_a_massless_shell():
    """``(I w + Js Omega, r)`` (about the rotor's centre of mass) is conserved only at
    ``ms = 0``; about the pair's centre of mass it is (a claim)."""
    d = P.derive_pair(True)
    Omega = S.w + P.DELTA * sp.Matrix([0, 0, 1])
    r = -S.R * S.gamma - S.a3 * sp.Matrix([0, 0, 1])
    naive = P.rate((sp.diag(S.I1, S.I1, S.I3) * S.w + P.JS * Omega).dot(r), d.field)
    assert check(_identity("naive jellett", naive)).result == "failed"
    assert check(_identity("naive jellett, ms = 0", naive, params=((P.MS, 0),))).result == (
        "proved"
    )


def test_the_limit_needs_the_limit():
    """The meridian model's accelerations do not solve the pair's equations with a shell."""
    poincare, _ = P._limit_residuals(True)
    expr = P._squares(poincare)
    assert check(_identity("limit at ms = 0 only", expr, params=((P.MS, 0),))).result == "failed"
    assert check(_identity("limit at Js = 0 only", expr, params=((P.JS, 0),))).result == "failed"


def test_the_f6_pair_reduces_to_f6():
    """At ``ms = Js = 0``: ``sqrt(N) = R s sqrt(m I1)``, ``Phi = -sqrt(m/I1) (R s + a3 theta)/R``,
    so ``sqrt(I1/m)`` times the pair's integral is ``I1 R s Omega3 - I3 w3 (R s + a3 theta)``:
    the paper's ``F6`` if ``R s Omega3 = v_tau - (R gamma3 + a3) w_n`` on the manifold."""
    zero = {P.MS: 0, P.JS: 0}
    g1, g2, g3 = S.gamma
    s = sp.sqrt(g1**2 + g2**2)
    assert sp.simplify(P.on_manifold(P.spin_weight().xreplace(zero) - S.R**2 * s**2 * S.m * S.I1)
                       ) == 0  # fmt: skip
    v_tau = (-g2 * S.v[0] + g1 * S.v[1]) / s
    w_n = -(g1 * S.w[0] + g2 * S.w[1]) / s
    diff = S.R * s * (S.w[2] + P.DELTA) - (v_tau - (S.R * g3 + S.a3) * w_n)
    assert sp.simplify(P.on_manifold(diff)) == 0


def test_derived_equations_match_the_kernel(rng, pair_rhs):
    code = MODELS["shell-rotor"].code
    dy = np.empty(18)
    ws = _kernel.new_workspace()
    for _ in range(N_BODIES):
        body = _random_body(rng)
        y = _random_state(rng, body)
        _kernel.rhs(code, body.params, y, dy, ws)
        want = np.array([*dy[0:6], dy[17]])
        got = pair_rhs(body.params, y)
        np.testing.assert_allclose(got, want, rtol=0, atol=AGREE_RTOL * np.abs(want).max())


def test_derived_equations_tend_to_the_meridian_model(rng, pair_rhs):
    """The limit ``ms, Js -> 0`` of :func:`derive_pair` numerically: the meridian model's
    ``(v', w')`` (:func:`rollingtop.symbolic.rhs_function`), the proved claim read literally."""
    meridian = rhs_function("meridian", symmetric=True)
    for _ in range(N_BODIES):
        body = _random_body(rng)
        y = _random_state(rng, body)
        p = body.params.copy()
        p[7:9] *= LIMIT_EPS
        got = pair_rhs(p, y)[0:6]
        want = np.array(meridian(p[:7], y)[0:6], dtype=float)
        np.testing.assert_allclose(got, want, rtol=0, atol=LIMIT_RTOL * np.abs(want).max())


def test_the_pairs_integrals_along_a_trajectory():
    """Energy, ``(K_G, r_G)`` and the pair's ``F6`` in closed form (with ``arccos``) along an
    integrated trajectory; the rotor's own Jellett form ``(I w + Js Omega, r)`` drifts."""
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.3, I1=0.3, I3=0.5, shell_mass=0.4,
                        shell_inertia=0.2)  # fmt: skip
    y = initial_state(body, "shell-rotor", gamma=(0.0, 0.6, 0.8), omega=(0.7, -0.3, 2.0),
                      free={"v_tau": 0.25})  # fmt: skip
    y[17] = 0.7
    _kernel.project(MODELS["shell-rotor"].code, body.params, y, _kernel.new_workspace())
    Y = simulate(body, "shell-rotor", y, t_end=TRAJECTORY_T, rtol=1e-11, atol=1e-12,
                 samples=500).y  # fmt: skip
    d = P.derive_pair(True)
    e3 = sp.Matrix([0, 0, 1])
    naive = (sp.diag(S.I1, S.I1, S.I3) * S.w + P.JS * (S.w + P.DELTA * e3)).dot(
        -S.R * S.gamma - S.a3 * e3
    )
    params = (*S.params, P.MS, P.JS)
    state = (*S.v, *S.w, *S.gamma, P.DELTA)
    for expr, conserved in ((d.energy, True), (P.jellett_pair(), True), (P.f6_pair(), True),
                            (naive, False)):  # fmt: skip
        f = sp.lambdify([params, state], expr.xreplace({S.I2: S.I1}), "numpy")
        values = f(tuple(body.params[:9]), tuple(Y[:, [0, 1, 2, 3, 4, 5, 12, 13, 14, 17]].T))
        drift = np.ptp(values)
        assert (drift < INTEGRAL_ATOL) == conserved, (expr, drift)
