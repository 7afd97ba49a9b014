"""Symbolic layer: the derived equations equal the compiled kernel; the claims are proved; a wrong
claim fails; the discovery helper finds F6."""

import dataclasses
import json

import numpy as np
import pytest
import sympy as sp

from rollingtop.contact import MODELS
from rollingtop.symbolic import check, claims_for, discover_linear_integrals, rhs_function, verify
from rollingtop.symbolic.claims import Claim, _integrals, s_sym, theta_sym
from rollingtop.symbolic.equations import SYMBOLS
from tests import kernels as _kernel

from ..dynamics.test_kernel import random_body, random_state
from ..test_cli import run_cli

AGREE_RTOL = 1e-12  # issue 6: symbolic right-hand side vs compiled kernel


@pytest.mark.parametrize("model", [n for n, m in MODELS.items() if not m.own_inertia])
def test_derived_equations_match_the_kernel(model, rng):
    """(The shell-rotor pair's own derivation is held to the kernel in test_shell_rotor.py.)"""
    general = rhs_function(model, symmetric=False)
    symmetric = rhs_function(model, symmetric=True)
    dy = np.empty(18)
    ws = _kernel.new_workspace()
    for _ in range(40):
        body = random_body(rng)
        y = random_state(rng, body, model)
        _kernel.rhs(MODELS[model].code, body.params, y, dy, ws)
        got = np.array(general(body.params, y), dtype=float)
        scale = np.max(np.abs(dy[:15]))
        np.testing.assert_allclose(got, dy[:15], rtol=0, atol=AGREE_RTOL * scale)
        # the symmetric derivation is the general one with I2 = I1
        p = body.params.copy()
        p[4] = p[5] = max(p[4], p[5])  # symmetric, triangle inequality kept
        sym_body = type(body)(R=p[0], m=p[1], g=p[2], a3=p[3], I1=p[4], I3=p[6])
        y = random_state(rng, sym_body, model)
        _kernel.rhs(MODELS[model].code, p, y, dy, ws)
        got = np.array(symmetric(p, y), dtype=float)
        np.testing.assert_allclose(got, dy[:15], rtol=0, atol=AGREE_RTOL * np.abs(dy).max())


@pytest.mark.slow
def test_every_claim_is_proved():
    results = verify()
    assert results and all(r.result == "proved" for r in results), [
        r for r in results if r.result != "proved"
    ]
    names = " ".join(r.name for r in results)
    for word in ("energy", "lagrange", "jellett", "area", "F6", "routh", "momentum_x",
                 "momentum_y", "invariant measure"):  # fmt: skip
        assert word in names


def test_wrong_claims_fail():
    F = _integrals()
    S = SYMBOLS
    perturbed = F["F6"] + sp.Rational(1, 10) * S.a3 * S.I3 * S.w[2] * theta_sym
    for claim in (
        Claim("F6 perturbed (a3 -> 1.1 a3 in its arccos term)", "meridian", perturbed),
        Claim("lagrange integral, general body", "meridian", F["lagrange"], symmetric=False),
        Claim("momentum_x integral on the meridian model", "meridian", F["momentum_x"]),
        Claim("F6 integral on the rough model", "rough", F["F6"]),
        Claim("identity with a wrong sign", "meridian",
              F["jellett"] - S.a3 * F["lagrange"] + S.R * F["area"], "identity"),
    ):  # fmt: skip
        result = check(claim)
        assert result.result == "failed", claim.name
        assert result.method  # says which method decided


@pytest.mark.parametrize("model", list(MODELS))
def test_the_manifold_satisfies_every_constraint(model):
    """The parametrisation on which the claims are decided lies on the model's constraint
    manifold: every constraint (contact rows and, for rubber rolling, ``(w, gamma) = 0``)
    vanishes identically on it."""
    from rollingtop.symbolic.claims import _manifold
    from rollingtop.symbolic.equations import constraints

    sub = _manifold(model)
    for c in constraints(model):
        assert sp.cancel(sp.together(c.xreplace(sub))) == 0, c


@pytest.mark.parametrize("name", ["lagrange", "jellett", "area"])
def test_rubber_rolling_loses_the_integrals_of_the_spin(name):
    """Rubber rolling (symmetric body) conserves the energy (proved by ``verify``) but not the
    Lagrange, Jellett or area integral: the time derivative of each along the derived equations
    does not vanish on the constraint manifold (``decide`` finds it nonzero; the numerical
    counterpart is tests/dynamics/test_integrals.py)."""
    from rollingtop.symbolic.claims import _time_derivative, decide
    from rollingtop.symbolic.equations import derive

    assert name not in MODELS["rubber"].integrals_symmetric
    rate = _time_derivative(_integrals()[name], derive("rubber", True).field)
    holds, method = decide(rate, "rubber", symmetric=True)
    assert not holds, method
    energy = _time_derivative(_integrals()["energy"], derive("rubber", True).field)
    assert decide(energy, "rubber", symmetric=True)[0]


def test_claims_are_not_vacuous_on_the_manifold():
    """The manifold parametrisation keeps s = |e3 x gamma| consistent (rational, exact)."""
    from rollingtop.symbolic.claims import _manifold

    sub = _manifold("meridian")
    g = [sub[x] for x in SYMBOLS.gamma]
    assert sp.simplify(g[0] ** 2 + g[1] ** 2 + g[2] ** 2 - 1) == 0
    assert sp.simplify(sub[s_sym] ** 2 - g[0] ** 2 - g[1] ** 2) == 0


def test_discovery_finds_F6(rng):
    found = discover_linear_integrals()
    assert len(found.constants) == 3  # F6, the area integral and the Lagrange integral
    assert found.coefficients["C"] == 0  # gravity forbids a w_tau term
    f = sp.lambdify([found.q, *sp.symbols("v_tau w_n w_tau w3"), *SYMBOLS.params,
                     *found.constants], found.integral)  # fmt: skip
    for _ in range(5):
        q = rng.uniform(0.1, 3)
        theta = 2 * np.arctan(q)
        g3, s = np.cos(theta), np.sin(theta)
        vt, wn, wt, w3 = rng.normal(size=4)
        R, m, g, a3, I1, I2, I3 = 1.2, 1.1, 0.9, 0.13, 0.3, 0.3, 0.5
        F6 = I1 * (vt - (R * g3 + a3) * wn) - I3 * w3 * (R * s + a3 * theta)
        got = complex(f(q, vt, wn, wt, w3, R, m, g, a3, I1, I2, I3, 1, 0, 0))
        # C1 = 1 gives F6 / I1 up to a multiple of the Lagrange integral (a3 pi M3 / I1)
        assert got.imag == pytest.approx(0, abs=1e-12)
        assert got.real == pytest.approx(F6 / I1 + np.pi * a3 * I3 * w3 / I1, rel=1e-12)
        area = g3 * I3 * w3 - I1 * s * wn
        got2 = complex(f(q, vt, wn, wt, w3, R, m, g, a3, I1, I2, I3, 0, 1, 0)).real
        assert got2 == pytest.approx(-(area + I3 * w3) / (2 * I1), rel=1e-12)


def test_cli_verify(capsys):
    code, out, err = run_cli(capsys, "verify", "--model", "rough", "--json")
    assert code == 0, err
    claims = json.loads(out)["claims"]
    assert {c["model"] for c in claims} == {"rough"}
    for c in claims:
        assert set(c) == {"name", "model", "result", "method", "seconds"}
        assert c["result"] == "proved"
    assert any("routh" in c["name"] for c in claims)
    assert len(claims_for("rough")) == len(claims)


LOST = [
    ("parallel", {"lagrange", "area"}),
    ("rough", {"lagrange", "area"}),
    ("rubber", {"lagrange", "jellett", "area"}),
]


@pytest.mark.parametrize(("model", "lost"), LOST)
def test_verify_shows_the_lost_integrals_vary(model, lost):
    """The classical integrals a model does not claim are claims of their own, "not conserved",
    proved by a nonzero rate; the same negated claim of a conserved integral fails."""
    negated = {c.name: c for c in claims_for(model) if not c.vanishes}
    assert set(negated) == {f"{n} integral not conserved" for n in lost}
    for claim in negated.values():
        assert check(claim).result == "proved", claim.name
    energy = next(c for c in claims_for(model) if c.name == "energy integral conserved")
    wrong = dataclasses.replace(energy, name="energy not conserved", vanishes=False)
    assert check(wrong).result == "failed"


def test_rubber_rollings_linear_integral_and_its_ode_are_proved():
    """Rubber rolling's integral beyond the energy (rollingtop.reduction.rubber): the rate of
    Omega = (w, nu) is A(gamma3) gamma3' Omega along the full equations (a linear ODE in gamma3),
    f = s sqrt(J) solves f' = -A f, and rubber_spin = w3 sqrt(I3 J) is conserved (its square).
    The same claims with J built on (I gamma, gamma) instead of (I nu, nu), or the ODE's
    coefficient without its J'/(2J) term, fail: the proofs can tell."""
    from rollingtop.symbolic.rubber import ode_coefficient

    claims = {c.name: c for c in claims_for("rubber")}
    names = [n for n in claims if "rubber_spin" in n or "ODE" in n or "f = s sqrt" in n
             or "kinetic energy" in n]  # fmt: skip
    assert len(names) == 4, names
    for name in names:
        assert check(claims[name]).result == "proved", name
    S = SYMBOLS
    g1, g2, g3 = S.gamma
    I = sp.diag(S.I1, S.I1, S.I3)
    r = -S.R * S.gamma - sp.Matrix([0, 0, S.a3])
    wrong_J = S.gamma.dot(I * S.gamma) + S.m * r.dot(S.gamma) ** 2
    assert check(Claim("w3^2 I3 (I gamma, gamma)-J", "rubber",
                       S.w[2] ** 2 * S.I3 * wrong_J)).result == "failed"  # fmt: skip
    omega = (S.w[2] - g3 * S.w.dot(S.gamma)) / s_sym
    g3_dot = g1 * S.w[1] - g2 * S.w[0]
    A = ode_coefficient(g3)
    A_wrong = g3 / s_sym**2
    assert A.has(S.I3)  # the right coefficient carries J'/(2J)
    wrong = Claim("ODE without J'/(2J)", "rubber", (omega, A_wrong * g3_dot * omega), "reduced")
    assert check(wrong).result == "failed"


def test_the_graph_evaluation_is_sympys_value_at_the_point():
    """The random points' evaluation (each distinct subexpression once, in Fractions) gives
    exactly sympy's own value of the substituted expression at the same point: a rate of
    10^5 nodes once on the manifold (rubber rolling's Jellett rate), and a parameter case."""
    import random
    from fractions import Fraction

    from rollingtop.symbolic.claims import (
        _draw,
        _manifold,
        _on_manifold,
        _rational_value,
        _time_derivative,
    )
    from rollingtop.symbolic.equations import derive

    rate = _time_derivative(_integrals()["jellett"], derive("rubber", True).field)
    for params in ((), ((SYMBOLS.a3, sp.Rational(1, 3) * SYMBOLS.R), (SYMBOLS.I3, SYMBOLS.I1))):
        subs = _manifold("rubber")
        on = _on_manifold(rate, "rubber", True, params, subs)
        rng = random.Random(7)
        drawn = set(on.free_symbols) | (rate.free_symbols - set(subs) - {SYMBOLS.I2})
        drawn -= {a for a, _ in params}  # eliminated by the parameters (g with a3 = 0) or not
        point = {x: _draw(rng, x) for x in sorted(drawn, key=lambda x: x.name)}
        expected = sp.nsimplify(on.xreplace(point))  # sympy's arithmetic on the tree
        values = {x: Fraction(int(v.p), int(v.q)) for x, v in point.items()}
        values[SYMBOLS.I2] = values[SYMBOLS.I1]
        for a, b in params:
            values[a] = _rational_value(sp.sympify(b), values)
        values.update({x: _rational_value(image, values) for x, image in subs.items()
                       if x in rate.free_symbols})  # fmt: skip
        got = _rational_value(rate, values)
        assert expected != 0 and sp.Rational(got.numerator, got.denominator) == expected


def test_a_wrong_large_claim_fails_at_a_rational_point():
    """A claim too large for the exact route (rubber rolling's energy, 10^5 operations), made
    wrong by a term of the size of round-off in floats, is refused at the first point."""
    F = _integrals()
    wrong = F["energy"] + sp.Rational(1, 10**12) * SYMBOLS.w[0] * SYMBOLS.gamma[2]
    result = check(Claim("energy with a small wrong term", "rubber", wrong))
    assert result.result == "failed" and result.method.startswith("exact evaluation: nonzero")
