"""Discovery of linear first integrals of the reduced meridian system (paper Sec. 3.2).

Ansatz ``F = A(gamma3) v_tau + B(gamma3) w_n + C(gamma3) w_tau + D(gamma3) w3``. Along the
reduced system (3.3) with ``w3' = 0``, ``dF/dt`` is a polynomial in the velocities
``(v_tau, w_n, w_tau, w3)`` (and a velocity-free gravity term) whose coefficients are linear in
``A, B, C, D`` and their derivatives: each must vanish. The algebraic conditions fix some
coefficient functions, the rest is a linear system of ODEs in ``gamma3`` solved by sympy. The
paper's ``F6`` comes out, together with the area and Lagrange integrals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from rollingtop.symbolic.equations import SYMBOLS

__all__ = ["discover_linear_integrals", "LinearIntegrals"]

S = SYMBOLS


@dataclass(frozen=True)
class LinearIntegrals:
    """General solution of the ansatz: coefficient functions with free constants."""

    q: sp.Symbol  # q = tan(theta/2), gamma3 = (1 - q^2)/(1 + q^2)
    coefficients: dict[str, Any]  # "A", "B", "C", "D" -> expression in q and the constants
    constants: tuple[Any, ...]  # the free constants
    conditions: list[Any]  # the coefficient equations that were solved
    integral: sp.Expr  # F in the reduced variables

    def basis(self) -> dict[Any, Any]:
        """One integral per free constant (that constant 1, the others 0)."""
        out = {}
        for c in self.constants:
            values = {x: (1 if x == c else 0) for x in self.constants}
            out[c] = sp.simplify(self.integral.subs(values))
        return out


def _solve_linear_first_order(eq: Any, f: Any, x: Any, constant: Any) -> Any:
    """Solve ``eq = 0``, linear in ``f(x)`` and ``f'(x)``, by the integrating factor."""
    d = sp.Derivative(f, x)
    e = sp.expand(eq.doit())
    a = e.coeff(d)
    rest = sp.expand(e - a * d)
    b = rest.coeff(f)
    c = sp.simplify(rest - b * f)
    if a == 0:  # algebraic
        return sp.simplify(-c / b)
    P, Q = sp.simplify(b / a), sp.simplify(-c / a)
    mu = sp.simplify(sp.exp(sp.integrate(P, x, conds="none")))
    integral = sp.integrate(sp.simplify(mu * Q), x, conds="none")
    return sp.simplify((integral + constant) / mu)


def discover_linear_integrals() -> LinearIntegrals:
    """Solve the ansatz for the meridian model's reduced system (symmetric body).

    In the rational parameter ``q = tan(theta / 2)`` (``gamma3 = (1 - q^2)/(1 + q^2)``,
    ``s = 2 q/(1 + q^2)``, ``q > 0``) every coefficient condition is rational, so sympy
    integrates without branches of ``sqrt(1 - gamma3^2)``. The conditions are linear and, once
    the algebraic ones are used, triangular: each new one involves a single new unknown
    function, solved by its integrating factor with a fresh constant ``C1, C2, ...``. The
    coefficient functions are returned in ``q`` (``arctan(q) = arccos(gamma3)/2``).
    """
    x = sp.Symbol("q", positive=True)
    vt, wn, wt, w3 = sp.symbols("v_tau w_n w_tau w3", real=True)
    R, m, g, a3, I1, I3 = S.R, S.m, S.g, S.a3, S.I1, S.I3
    A, B, C, D = (sp.Function(n)(x) for n in "ABCD")
    G = (1 - x**2) / (1 + x**2)
    s = 2 * x / (1 + x**2)
    M3 = I3 * w3
    rho = I1 + m * (a3**2 + R**2 + 2 * a3 * R * G)
    k = R + a3 * G
    field = {  # reduced system (3.3); q' = gamma3' / (d gamma3/dq) = -(1 + q^2) w_tau / 2
        x: -(1 + x**2) * wt / 2,
        vt: wt * wn * k / s,
        wn: wt * (M3 / I1 + G * wn / s),
        wt: -(m * a3 * s * (g + R * wt**2) + M3 * wn + I1 * G * wn**2 / s + m * vt * wn * k / s)
        / rho,
        w3: 0,
    }
    F = A * vt + B * wn + C * wt + D * w3
    dF = sp.together(sum(sp.diff(F, v) * dv for v, dv in field.items()))
    numerator, _ = sp.fraction(dF)
    poly = sp.Poly(sp.expand(numerator), vt, wn, wt, w3)
    conditions = [sp.factor(co) for co in poly.coeffs()]
    unknowns = [A, B, C, D]
    known: dict[Any, Any] = {}
    constants: list[Any] = []
    pending = list(conditions)
    while pending:
        progress = False
        for co in list(pending):
            e = sp.together(co.subs(known).doit()) if known else co
            e = sp.fraction(e)[0]
            left = [f for f in unknowns if f not in known and e.has(f)]
            if not left:
                if sp.simplify(e) != 0:
                    raise RuntimeError(f"inconsistent condition {e}")
                pending.remove(co)
                progress = True
            elif len(left) == 1:
                f = left[0]
                constant: Any = 0
                if e.has(sp.Derivative(f, x)):
                    constant = sp.Symbol(f"C{len(constants) + 1}")
                    constants.append(constant)
                known[f] = _solve_linear_first_order(e, f, x, constant)
                pending.remove(co)
                progress = True
                break
        if not progress:
            raise RuntimeError("the coefficient conditions are not triangular")
    result = {
        name: sp.simplify(known.get(f, sp.Integer(0)))
        for name, f in zip("ABCD", unknowns, strict=True)
    }
    integral = result["A"] * vt + result["B"] * wn + result["C"] * wt + result["D"] * w3
    return LinearIntegrals(x, result, tuple(constants), conditions, integral)
