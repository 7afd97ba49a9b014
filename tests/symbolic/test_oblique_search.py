"""The oblique family's search for a measure and integrals (rollingtop.symbolic.oblique_search,
issue 39 item 2).

The exact reduced field against the independent NumPy equations (tests/dynamics/reference.py)
by the chain rule at random states; the searches' answers at the ends of the family against
what is known there by other means (the paper's measure and integrals at ``phi = 0``; the
companion model's, found by :mod:`rollingtop.symbolic.parallel`'s separate method, at
``phi = pi/2``), including the particular body where the companion model gains an integral.
"""

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from rollingtop.symbolic import oblique_search as search
from rollingtop.symbolic.equations import PHI_T

from ..dynamics import reference

PAPER = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}
OTHER = {"R": 0.8, "m": 2.0, "g": 1.5, "a3": -0.25, "I1": 0.4, "I3": 0.2}
#: The exact reduced rates (evaluated in floats) against the chain rule on the reference
#: equations, with the frame's rates by central differences (step 1e-6: error ~1e-11).
RATE_TOL = 1e-8


def _frame(gamma, phi):
    e3 = np.array([0.0, 0.0, 1.0])
    s = math.hypot(gamma[0], gamma[1])
    tau = np.cross(e3, gamma) / s
    n = -np.array([gamma[0], gamma[1], 0.0]) / s
    nu = (e3 - gamma[2] * gamma) / s
    return tau, n, -math.sin(phi) * nu + math.cos(phi) * tau


def _float(red, p, point):
    """A ring element at a point: ``point`` maps q and the velocities to floats."""
    total = 0.0
    for mon, c in p.terms():
        value = float(c.numer.as_expr().subs(point)) / float(c.denom.as_expr().subs(point))
        for x, k in zip(search.VELOCITIES, mon, strict=True):
            value *= point[x] ** k
        total += value
    return total


@pytest.mark.parametrize("body", [PAPER, OTHER])
@pytest.mark.parametrize("t", [Fraction(0), Fraction(1, 3), Fraction(1), Fraction(-2)])
def test_the_reduced_field_follows_from_the_reference_equations(body, t, rng):
    exact = search.as_rational_body(body)
    red = search.reduced_field(exact, t)
    phi = 2 * math.atan(t)
    p = [body[k] for k in ("R", "m", "g", "a3", "I1")] + [body["I1"], body["I3"]]
    name = f"oblique:{phi!r}"
    for _ in range(3):
        q = float(rng.uniform(0.2, 3.0))
        wt, wn, w3, u = rng.normal(size=4)
        s, g3 = 2 * q / (1 + q * q), (1 - q * q) / (1 + q * q)
        gamma = np.array([s, 0.0, g3])
        w = np.array([-wn, wt, w3])
        r = -body["R"] * gamma - np.array([0.0, 0.0, body["a3"]])
        tau, n, e = _frame(gamma, phi)
        v = -np.cross(w, r) + u * e
        alpha = np.cross(np.array([0.0, 1.0, 0.0]), gamma)
        alpha /= np.linalg.norm(alpha)
        beta = np.cross(gamma, alpha)
        y = np.concatenate([v, w, alpha, beta, gamma, [0.0, 0.0, 0.0]])
        dy = reference.rhs(name, np.array(p), y)[0]
        vdot, wdot, gdot = dy[0:3], dy[3:6], dy[12:15]

        def frame_rate(k, gamma=gamma, gdot=gdot):
            h = 1e-6
            return (_frame(gamma + h * gdot, phi)[k] - _frame(gamma - h * gdot, phi)[k]) / (2 * h)

        rdot = -body["R"] * gdot
        vp, vpdot = v + np.cross(w, r), vdot + np.cross(wdot, r) + np.cross(w, rdot)
        want = {
            search.WT: wdot @ tau + w @ frame_rate(0),
            search.WN: wdot @ n + w @ frame_rate(1),
            search.W3: wdot[2],
            search.U: vpdot @ e + vp @ frame_rate(2),
        }
        point = {search.Q: q, search.WT: wt, search.WN: wn, search.W3: w3, search.U: u}
        for x, value in want.items():
            got = _float(red, red.rates[x], point)
            assert got == pytest.approx(value, rel=RATE_TOL, abs=RATE_TOL), (t, x)


def test_a_density_of_gamma3_exists_only_at_the_papers_angle():
    """Symbolically in t: the obstruction's gcd is a constant times t (for both bodies)."""
    for body in (PAPER, OTHER):
        poly = search.density_obstruction(search.as_rational_body(body))
        assert sp.Poly(poly.monic().as_expr(), PHI_T) == sp.Poly(PHI_T, PHI_T)


def test_the_ends_of_the_family_give_what_is_known_there():
    exact = search.as_rational_body(PAPER)
    paper = search.search_angle(exact, Fraction(0))
    # the paper's constraint: its measure rho(gamma3) and three linear integrals (M3, C1, C2)
    assert paper.bounds["density 0"] == 1
    assert paper.bounds["linear"] == 3
    assert set(paper.integrals) == {"energy", "jellett", "lagrange", "area"}
    companion = search.search_angle(exact, Fraction(1))
    # the companion paper's: Jellett's integral only, no density (symbolic/parallel.py)
    assert companion.integrals == ("energy", "jellett")  # no slip integral for this body
    for name in ("linear", "quadratic"):
        assert companion.closed(name), name
    assert all(companion.bounds[f"density {k}"] == 0 for k in range(3))


@pytest.mark.parametrize("t", [Fraction(1), Fraction(1, 3), Fraction(2)])
def test_the_bound_sees_the_balanced_balls_slip_integral(t):
    """a3 = 0, I3 = I1: the slip along nu is conserved under the companion constraint (found by
    symbolic/parallel.py's separate ansatz); the search finds the slip along e conserved at
    every angle, and the linear bound rises to 2 to meet it."""
    special = {**PAPER, "a3": 0.0, "I3": PAPER["I1"]}
    result = search.search_angle(search.as_rational_body(special), t, max_degree=0)
    assert "slip" in result.integrals
    assert result.bounds["linear"] == result.known["linear"] == 2
    assert result.bounds["quadratic"] == result.known["quadratic"] == 4


def test_between_the_ends_only_energy_and_jellett():
    exact = search.as_rational_body(OTHER)
    for t in (Fraction(1, 4), Fraction(3, 2)):
        result = search.search_angle(exact, t, max_degree=1)
        assert result.integrals == ("energy", "jellett")
        assert result.closed("linear") and result.closed("quadratic")
        assert result.bounds["density 0"] == result.bounds["density 1"] == 0


def test_the_command_refuses_misplaced_options(capsys):
    from rollingtop.cli import main

    for args, message in (
        (["verify", "--body", "examples/parallel.toml"], "--body is an option of --search"),
        (["verify", "--search", "--model", "oblique"], "leave out --model"),
    ):
        with pytest.raises(SystemExit) as exc:
            main(args)
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_the_command_searches_a_scenarios_body():
    import json
    import subprocess
    import sys

    run = subprocess.run(
        [sys.executable, "-m", "rollingtop", "verify", "--search", "--json"]
        + ["--body", "examples/parallel.toml"],
        capture_output=True,
        text=True,
        check=False,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    (result,) = json.loads(run.stdout)["search"]
    assert result["body"]["a3"] == "1/10" and result["obstruction"] == "2*t_phi"
    assert result["density_angles"] == [0.0]
    by_t = {a["t"]: a for a in result["angles"]}
    assert by_t["0"]["density_gamma3"] and by_t["0"]["bounds"]["linear"] == 3
    assert by_t["1/2"]["bounds"]["linear"] == by_t["1/2"]["known"]["linear"] == 1


def test_the_balanced_balls_claims_hold_only_for_the_balanced_ball():
    """verify's claims for every phi (symbolic/oblique.py): the slip along d x gamma and the
    area integral conserved when a3 = 0, I3 = I1; with the paper's body's own a3 and I3 the
    same claims fail (a rational counterexample), so the proof is not vacuous."""
    from dataclasses import replace

    from rollingtop.symbolic.claims import check, claims_for

    ball = [c for c in claims_for("oblique") if c.name.startswith("balanced ball")]
    assert len(ball) == 2
    for claim in ball:
        assert check(claim).result == "proved", claim.name
        assert check(replace(claim, params=())).result == "failed", claim.name
