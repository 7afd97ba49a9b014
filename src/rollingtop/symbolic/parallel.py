"""The companion model ``parallel``: its reduced system, its particular integrable cases and
the limit in which it is integrable by the Euler-Jacobi theorem.

Kilin and Ivanova's companion paper (Rus. J. Nonlin. Dyn. 19(4), 2023, 533-543,
doi:10.20537/nd231201) states that the model without slip *across* the axis projection
(``(v_P, tau) = 0``, free slip along ``nu``) is not integrable in general, has no invariant
measure with a smooth density, gains an additional integral in particular cases and is
integrable by the Euler-Jacobi theorem in a limit. This module finds those cases from the
equations, with the same method as :mod:`.discover` for the paper's model.

**Reduced system.** For a dynamically symmetric body the equations are invariant under
rotations about ``e3``; in the variables ``gamma3``, ``w_tau = (w, tau)``, ``w_n = (w, n)``,
``w3`` and ``v_nu = (v, nu)`` (``docs/model.md``, "Reduced variables"; ``v_nu`` the free
component) they close (:func:`reduced_system`, proved from the full equations by
:func:`claims`). With ``s = sqrt(1 - gamma3^2)``, ``k = R gamma3 + a3``,
``K = I1 + m a3^2 s^2`` and ``D = I1 I3 + m (I1 R^2 s^2 + I3 k^2)``::

    gamma3' = s w_tau
    K w_tau' = -I1 gamma3 w_n^2 / s - I3 w3 w_n + m a3^2 gamma3 s w_tau^2 - m g a3 s
    D w_n'   = -I3 m k v_nu w_n / s + I3 (I3 + m R (R + a3 gamma3)) w3 w_tau
               + (I1 I3 gamma3 + m R s^2 (I1 R gamma3 - I3 k)) w_n w_tau / s
    D w3'    = -R m (I1 v_nu w_n + I1 (R + a3 gamma3) w_n w_tau + s (I3 k - I1 R gamma3) w3 w_tau)
    v_nu'    = w_n (k w_n + R s w3) / s

It conserves the energy and Jellett's integral ``R I1 s w_n - I3 k w3``.

**Linear integrals** (:func:`discover_linear_integrals`): the ansatz
``F = A v_nu + B w_n + C w_tau + D w3`` with coefficient functions of ``gamma3`` gives, for
every body, Jellett's integral only -- unless ``a3 = 0`` and ``I3 = I1`` (the centre of mass at
the geometric centre and a spherical ellipsoid of inertia), where the contact point's slip
along ``nu``, ``u = (v_P, nu) = v_nu + (R + a3 gamma3) w_tau``, is conserved as well. That
case has three integrals on a five-dimensional phase space: its motions lie on
two-dimensional surfaces (the invariant curves of its section, ``docs/guide/chaos.md``).

**Invariant measure** (:func:`density_condition`): the divergence of the reduced field
contains the term ``-I3 m k v_nu / (s D)``, so no density depending on ``gamma3`` alone
exists unless ``I3 = 0``. In the limit ``I3 -> 0`` (all mass on the symmetry axis) the
density ``s K`` exists, and ``h0 = K w_tau^2 / 2 + I1 w_n^2 / 2 + m g a3 gamma3``
becomes a third integral (the ``(gamma3, w_tau, w_n)`` subsystem closes: the axis moves as a
heavy symmetric top's would): a measure and three integrals on five dimensions -- integrable
by the Euler-Jacobi theorem.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from rollingtop.symbolic.claims import Claim, s_sym
from rollingtop.symbolic.discover import _solve_linear_first_order
from rollingtop.symbolic.equations import SYMBOLS

__all__ = [
    "ParallelIntegrals",
    "claims",
    "density_condition",
    "discover_linear_integrals",
    "reduced_system",
]

S = SYMBOLS
#: The reduced variables (``s`` is ``sqrt(1 - gamma3^2)``, kept as a symbol).
G, WT, WN, W3, VN = sp.symbols("gamma3 w_tau w_n w3 v_nu", real=True)


def _shorthands(s: Any, g3: Any) -> tuple[Any, Any, Any]:
    R, m, a3, I1, I3 = S.R, S.m, S.a3, S.I1, S.I3
    k = R * g3 + a3
    K = I1 + m * a3**2 * s**2
    D = I1 * I3 + m * (I1 * R**2 * s**2 + I3 * k**2)
    return k, K, D


def reduced_system(s: Any = s_sym, g3: Any = G) -> dict[Any, Any]:
    """The right-hand sides of the reduced system (module docstring), keyed by the variables
    ``gamma3, w_tau, w_n, w3, v_nu`` (:data:`G`, :data:`WT`, :data:`WN`, :data:`W3`, :data:`VN`).
    ``s`` and ``g3`` may be replaced (e.g. by a rational parametrisation)."""
    R, m, g, a3, I1, I3 = S.R, S.m, S.g, S.a3, S.I1, S.I3
    k, K, D = _shorthands(s, g3)
    return {
        G: s * WT,
        WT: (-I1 * g3 * WN**2 / s - I3 * W3 * WN + m * a3**2 * g3 * s * WT**2 - m * g * a3 * s) / K,
        WN: (
            -I3 * m * k * VN * WN / s
            + I3 * (I3 + m * R * (R + a3 * g3)) * W3 * WT
            + (I1 * I3 * g3 + m * R * s**2 * (I1 * R * g3 - I3 * k)) * WN * WT / s
        )
        / D,
        W3: -R
        * m
        * (I1 * VN * WN + I1 * (R + a3 * g3) * WN * WT + s * (I3 * k - I1 * R * g3) * W3 * WT)
        / D,
        VN: WN * (k * WN + R * s * W3) / s,
    }


def _reduced_of_state() -> dict[Any, Any]:
    """The reduced variables as functions of the full state (``s`` as :data:`s_sym`)."""
    g1, g2, g3 = S.gamma
    tau = sp.Matrix([-g2, g1, 0]) / s_sym
    n = -sp.Matrix([g1, g2, 0]) / s_sym
    nu = s_sym * sp.Matrix([0, 0, 1]) + g3 * n
    return {G: g3, WT: S.w.dot(tau), WN: S.w.dot(n), W3: S.w[2], VN: S.v.dot(nu)}


def _in_state(expr: Any) -> Any:
    return sp.sympify(expr).xreplace(_reduced_of_state())


def _rational(expr: Any, q: Any) -> Any:
    """``expr`` with ``gamma3 = (1 - q^2)/(1 + q^2)``, ``s = 2 q/(1 + q^2)``: rational."""
    return expr.xreplace({G: (1 - q**2) / (1 + q**2), s_sym: 2 * q / (1 + q**2)})


def _divergence(field: dict[Any, Any], density: Any = 1) -> Any:
    """``div(density * field)`` in the variables ``gamma3, w_tau, w_n, w3, v_nu`` (``s`` a
    function of ``gamma3``: ``ds/dgamma3 = -gamma3 / s``, so the result stays rational in
    ``gamma3`` and ``s``)."""
    total = 0
    for x, f in field.items():
        total += sp.diff(density * f, x)
        if x == G:
            total += sp.diff(density * f, s_sym) * (-G / s_sym)
    return total


def density_condition() -> tuple[Any, Any]:
    """The obstruction to an invariant density ``rho(gamma3)`` and the density of the limit.

    Returns ``(obstruction, density)``: ``obstruction`` is the coefficient of ``v_nu`` in the
    divergence of the reduced field (a density of ``gamma3`` alone must make every coefficient
    but that of ``w_tau`` vanish, and nothing can cancel this one), ``density`` is
    ``rho(gamma3)`` solving ``rho' s w_tau + rho div = 0`` at ``I3 = 0``.
    """
    field = reduced_system()
    div = sp.together(_divergence(field))
    obstruction = sp.factor(sp.diff(div, VN))
    limit = {S.I3: 0}
    # rho' s w_tau + rho div = 0; div is w_tau G f(s^2): integrate in x = s^2 (dG/dx = -1/(2G))
    rate = sp.cancel(sp.together(div.xreplace(limit) / (s_sym * WT * G)))
    x = sp.Symbol("x", positive=True)
    rate = sp.cancel(rate.xreplace({s_sym: sp.sqrt(x), G: sp.sqrt(1 - x)}))
    if rate.has(sp.sqrt(1 - x)):
        raise RuntimeError(f"the divergence is not gamma3 w_tau f(s^2): {rate}")
    log_rho = sp.integrate(rate / 2, x)
    density = sp.factor(sp.simplify(sp.exp(log_rho)).xreplace({x: s_sym**2}))
    density = sp.powdenest(density, force=True)
    return obstruction, density


@dataclass(frozen=True)
class ParallelIntegrals:
    """Result of :func:`discover_linear_integrals`.

    ``generic``: the integral for every body (coefficients with a free constant);
    ``case``: the parameter values (sympy ``Eq``) where a second one exists;
    ``particular``: that integral in the reduced variables; ``conditions``: the coefficient
    equations of the ansatz (in ``q = tan(theta/2)``).
    """

    generic: sp.Expr
    case: tuple[Any, ...]
    particular: sp.Expr
    conditions: list[Any]


def _conditions(field: dict[Any, Any], q: Any, coefficients: dict[str, Any]) -> dict[Any, Any]:
    A, B, C, D = (coefficients[c] for c in "ABCD")
    F = A * VN + B * WN + C * WT + D * W3
    rates = {x: _rational(f, q) for x, f in field.items() if x != G}
    rates[q] = -(1 + q**2) * WT / 2  # q' from gamma3' = s w_tau
    dF = sp.together(sum(sp.diff(F, x) * dx for x, dx in rates.items()))
    poly = sp.Poly(sp.expand(sp.fraction(dF)[0]), VN, WN, WT, W3)
    return {mon: sp.factor(co) for mon, co in poly.terms()}


def _monomial(**powers: int) -> tuple[int, ...]:
    return tuple(powers.get(n, 0) for n in ("vn", "wn", "wt", "w3"))


def discover_linear_integrals() -> ParallelIntegrals:
    """Solve the linear ansatz ``F = A v_nu + B w_n + C w_tau + D w3`` for the reduced system.

    ``dF/dt`` is a polynomial in the velocities whose coefficients must vanish. Step by step:

    1. the ``v_nu w_tau`` coefficient is ``A'``: ``A`` is a constant ``a``;
    2. the ``w_n w3`` coefficient is algebraic in ``a`` and ``C``: it gives ``C``;
    3. the ``w_n^2`` coefficient is then ``a`` times a polynomial in ``q`` whose coefficients
       depend on the body: ``a = 0``, unless all of them vanish -- solved for the body's
       parameters, this is the particular case;
    4. with ``a = 0`` (every body) and with ``a = 1`` in the particular case, the remaining
       conditions are triangular (:func:`rollingtop.symbolic.discover._solve_linear_first_order`
       with fresh constants).
    """
    q = sp.Symbol("q", positive=True)
    field = reduced_system()
    funcs = {c: sp.Function(c)(q) for c in "ABCD"}
    a = sp.Symbol("a")
    conditions = _conditions(field, q, {**funcs, "A": a})
    # 1. A' (the v_nu w_tau coefficient) vanishes identically with A = a
    assert _monomial(vn=1, wt=1) not in conditions
    # 2. C from the w_n w3 coefficient
    C = sp.solve(conditions[_monomial(wn=1, w3=1)], funcs["C"])[0]
    # 3. the w_n^2 coefficient: a * P(q) = 0
    rest = sp.factor(sp.fraction(sp.together(conditions[_monomial(wn=2)].subs(funcs["C"], C)))[0])
    P = sp.Poly(sp.cancel(rest / a), q)
    params = [S.a3, S.I3]
    cases = sp.solve(P.coeffs(), params, dict=True)
    physical = [c for c in cases if all(v != 0 for k, v in c.items() if k == S.I3)]
    if len(physical) != 1:
        raise RuntimeError(f"unexpected particular cases {cases}")
    case = physical[0]
    generic = _triangular(field, q, {"A": 0, "C": 0}, {})
    particular = _triangular(field, q, {"A": 1, "C": C.subs(a, 1)}, case)
    return ParallelIntegrals(
        generic=generic,
        case=tuple(sp.Eq(k, v) for k, v in case.items()),
        particular=particular,
        conditions=list(conditions.values()),
    )


def _triangular(field: dict[Any, Any], q: Any, fixed: dict[str, Any], case: dict[Any, Any]) -> Any:
    """Solve the ansatz with the coefficients ``fixed`` given, in the case ``case``."""
    field = {x: f.xreplace(case) for x, f in field.items()}
    unknown = {c: sp.Function(c)(q) for c in "ABCD" if c not in fixed}
    coefficients = {c: sp.sympify(v).xreplace(case) for c, v in fixed.items()} | unknown
    pending = list(_conditions(field, q, coefficients).values())
    known: dict[Any, Any] = {}
    constants: list[Any] = []
    while pending:
        for co in list(pending):
            e = sp.fraction(sp.together(co.subs(known).doit()))[0] if known else co
            left = [f for f in unknown.values() if f not in known and e.has(f)]
            if not left:
                if sp.simplify(e) != 0:
                    raise RuntimeError(f"inconsistent condition {e}")
                pending.remove(co)
                break
            if len(left) == 1:
                f = left[0]
                constant: Any = 0
                if e.has(sp.Derivative(f, q)):
                    constant = sp.Symbol(f"C{len(constants) + 1}")
                    constants.append(constant)
                solution = _solve_linear_first_order(e, f, q, constant)
                known = {h: sp.simplify(v.subs(f, solution).doit()) for h, v in known.items()}
                known[f] = solution
                pending.remove(co)
                break
        else:
            # no condition with a single unknown left: solve an algebraic one (no derivative)
            # for one of its unknowns
            for co in pending:
                e = sp.fraction(sp.together(co.subs(known).doit()))[0] if known else co
                left = [f for f in unknown.values() if f not in known and e.has(f)]
                if not any(e.has(sp.Derivative(f, q)) for f in left):
                    known[left[-1]] = sp.simplify(sp.solve(e, left[-1])[0])
                    pending.remove(co)
                    break
            else:
                raise RuntimeError("the coefficient conditions are not triangular")
    values = {c: sp.simplify(known.get(f, f)) for c, f in unknown.items()}
    values |= {c: coefficients[c] for c in fixed}
    F = values["A"] * VN + values["B"] * WN + values["C"] * WT + values["D"] * W3
    # back to gamma3 and s: q = s / (1 + gamma3)
    back = sp.simplify(F.xreplace({q: s_sym / (1 + G)}))
    return back


def _h0() -> Any:
    _, K, _ = _shorthands(s_sym, G)
    return K * WT**2 / 2 + S.I1 * WN**2 / 2 + S.m * S.g * S.a3 * G


#: The contact point's slip along ``nu`` (conserved when ``a3 = 0``, ``I3 = I1``).
SLIP_NU = VN + (S.R + S.a3 * G) * WT


def claims() -> list[Claim]:
    """The claims :func:`rollingtop.symbolic.verify` checks for ``parallel`` beyond its
    integrals: the reduced system follows from the full equations, the slip along ``nu`` is
    conserved when ``a3 = 0, I3 = I1`` (and not otherwise: a separate test), and in the limit
    ``I3 = 0`` the reduced field has the density ``s K`` and the integral ``h0``."""
    out = []
    field = reduced_system()
    of_state = _reduced_of_state()
    for x, rhs in field.items():
        out.append(
            Claim(
                f"reduced system: {x}' follows from the full equations",
                "parallel",
                (of_state[x], _in_state(rhs)),
                "reduced",
            )
        )
    out.append(
        Claim(
            "slip along nu conserved when a3 = 0, I3 = I1",
            "parallel",
            _in_state(SLIP_NU),
            params=((S.a3, 0), (S.I3, S.I1)),
        )
    )
    q = sp.Symbol("q", positive=True)
    limit = {S.I3: 0}
    _, K, _ = _shorthands(s_sym, G)
    density = s_sym * K
    limit_field = {x: f.xreplace(limit) for x, f in field.items()}
    div = _rational(sp.together(_divergence(limit_field, density)), q)
    out.append(
        Claim("limit I3 -> 0: div(s K field) = 0 (invariant measure)", "parallel", div, "identity")
    )
    h0 = _h0()
    dh0 = sum(sp.diff(h0, x) * f for x, f in limit_field.items())
    dh0 += sp.diff(h0, s_sym) * (-G * WT)  # s' = -gamma3 w_tau
    out.append(
        Claim(
            "limit I3 -> 0: h0 = K w_tau^2/2 + I1 w_n^2/2 + m g a3 gamma3 conserved",
            "parallel",
            _rational(dh0, q),
            "identity",
        )
    )
    return out
