"""The oblique family's invariant measure and integrals, searched by ``phi`` (issue 39).

**The reduced system.** The body is dynamically symmetric, so the equations of
:mod:`rollingtop.contact.oblique` are invariant under rotations about ``e3``, and ``phi`` turns
with them (``d`` is built from ``nu`` and ``tau``). Their invariants close: ``gamma3`` (through
``q = tan(theta / 2)``, ``gamma3 = (1 - q^2)/(1 + q^2)``, ``s = 2 q/(1 + q^2)``), ``w_tau``,
``w_n``, ``w3`` and the contact point's slip ``u = (v_P, e)`` along the free direction
``e = d x gamma = -sin(phi) nu + cos(phi) tau``. :func:`reduced_field` evaluates the
d'Alembert-Lagrange equations of :mod:`rollingtop.symbolic.equations` (the same
constraints, the same elimination of the multipliers) on the slice ``gamma = (s, 0, gamma3)``,
``w = (-w_n, w_tau, w3)``, ``v = -w x r + u e`` that meets every orbit of the rotations once, in
exact arithmetic: a polynomial of degree two in the velocities ``(w_tau, w_n, w3, u)`` with
coefficients rational in ``q`` and in ``t = tan(phi / 2)``. It is tested against the
independent NumPy equations (``tests/symbolic/test_oblique_search.py``); the integrals the
search reports are proved exact integrals of it (:func:`rate_of`), and the balanced ball's for
every ``phi`` by ``rollingtop verify`` (:mod:`rollingtop.symbolic.oblique`).

**The searches** (:func:`search`), each for every body parameter given as a rational number and
with ``t`` a symbol where it can be:

- *a density of ``gamma3`` alone*: ``div(rho f) = 0`` asks ``div f = -(log rho)'(q) q'`` with
  ``q' = -(1 + q^2) w_tau / 2``, so every coefficient of ``div f`` but that of ``w_tau`` must
  vanish. They are polynomials in ``q`` and ``t``; their common roots in ``t`` (every
  coefficient of every power of ``q`` zero) are the angles with such a density
  (:func:`density_obstruction`).
- *a density polynomial in the velocities* (of degree ``N``, its coefficients any functions of
  ``gamma3``) and *integrals linear or quadratic in the velocities* (coefficients any functions
  of ``gamma3``): an ansatz's top-degree part must annul the part of ``dF/dt`` (or
  ``L_f rho + rho div f``) of the next degree **free of ``w_tau``**: ``q'`` is proportional to
  ``w_tau``, so no derivative of a coefficient enters those monomials, and the conditions are
  linear *algebraic* equations for the coefficients over the field ``Q(q)``. Their kernel
  bounds the candidates: a kernel ``{0}`` rules the class out; a kernel spanned by the known
  integrals' parts (Jellett's ``J`` for the linear class; the energy's kinetic part and ``J^2``
  for the quadratic one) leaves only the known integrals (then ``(lambda_1 E_2 + lambda_2
  J^2)' = lambda_1' q' E_2 + lambda_2' q' J^2`` forces constant ``lambda``, and what remains is
  linear or a function of ``gamma3`` alone, which ``q' = w_tau (...)`` forces constant). A
  larger kernel is reported as such: the class is not ruled out there (``phi = 0``, where the
  paper's integrals live).

The prolonged constraints are exact rational functions of ``q``; their rank is taken in exact
rationals at the point ``q = Q0`` (:func:`solution_bound`), a lower bound on their rank over
``Q(q)``: so each bound is a proof for the rational body and angle it was computed at.
"""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cache
from typing import Any

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from rollingtop.symbolic.equations import PHI_T, SYMBOLS, constraints

__all__ = [
    "AngleResult",
    "Q",
    "U",
    "VELOCITIES",
    "W3",
    "WN",
    "WT",
    "density_obstruction",
    "reduced_field",
    "search",
]

S = SYMBOLS
#: ``q = tan(theta / 2)`` (``gamma3 = cos(theta)``) and the velocities of the reduced system.
Q = sp.Symbol("q", positive=True)
WT, WN, W3, U = sp.symbols("w_tau w_n w3 u", real=True)
VELOCITIES = (WT, WN, W3, U)
#: The body's symbols, in the order of :attr:`rollingtop.SphericalTop.params` less ``I2``.
_BODY = ("R", "m", "g", "a3", "I1", "I3")


@dataclass(frozen=True)
class Reduced:
    """The reduced field on the slice (module docstring) in the ring ``P = Kq[velocities]``.

    ``rates``: ``P`` elements, keyed by the velocity symbols; ``q_rate``: ``q'``;
    ``energy``, ``jellett``: the two integrals every member of the family has, in ``P``;
    ``inertia``: ``(I1, I3)`` in ``P``.
    """

    ring: Any
    ground: Any
    gens: tuple[Any, ...]
    rates: dict[Any, Any]
    q_rate: Any
    energy: Any
    jellett: Any
    inertia: tuple[Any, Any]


def _ground_symbols(t: Any) -> tuple[Any, ...]:
    return (Q,) if t is not None else (Q, PHI_T)


@cache
def reduced_field(body: tuple[tuple[str, Fraction], ...], t: Fraction | None = None) -> Reduced:
    """The oblique family's reduced field for the body ``body`` (pairs ``(name, value)`` of
    ``R, m, g, a3, I1, I3``, rational) at ``t = tan(phi / 2)`` (``None``: ``t`` a symbol).

    Returns a :class:`Reduced`: its rates are polynomials of degree two in the velocities
    ``(w_tau, w_n, w3, u)`` over ``Q(q)`` (``Q(q, t)``)."""
    values_in = dict(body)
    missing = [n for n in _BODY if n not in values_in]
    if missing:
        raise ValueError(f"the body needs {', '.join(missing)}")
    ground = sp.QQ.frac_field(*_ground_symbols(t))
    P, *gens = sp.ring([str(v) for v in VELOCITIES], ground)
    wt, wn, w3, u = gens

    def num(x: Any) -> Any:
        return P(ground.convert(sp.Rational(x.numerator, x.denominator)))

    R, m, g, a3, I1, I3 = (num(Fraction(values_in[n])) for n in _BODY)
    qq = P(ground.convert(Q))
    tt = P(ground.convert(PHI_T)) if t is None else num(Fraction(t))
    one = P(1)
    half = _inv(P, ground, P(2))
    s = 2 * qq * _inv(P, ground, one + qq**2)
    g3 = (one - qq**2) * _inv(P, ground, one + qq**2)
    gamma = [s, P(0), g3]
    w = [-wn, wt, w3]
    values = {
        **dict(zip(S.gamma, gamma, strict=True)),
        **dict(zip(S.w, w, strict=True)),
        **{getattr(S, n): x for n, x in zip(_BODY, (R, m, g, a3, I1, I3), strict=True)},
        S.I2: I1,
        PHI_T: tt,
        _S: s,
    }
    frame = {k: [_to_ring(P, ground, x, values) for x in vec] for k, vec in _frame().items()}
    tau, n, e = frame["tau"], frame["n"], frame["e"]
    r = [-R * gamma[0], -R * gamma[1], -R * gamma[2] - a3]
    wxr = _cross(w, r)
    v = [-wxr[i] + u * e[i] for i in range(3)]
    values |= dict(zip(S.v, v, strict=True))
    # the d'Alembert-Lagrange equations of rollingtop.symbolic.equations.derive, at the point
    mass = [m, m, m, I1, I1, I3]
    Iw = [I1 * w[0], I1 * w[1], I3 * w[2]]
    dLdv = [m * x for x in v]
    dLdg = [2 * m * g * x for x in r[:2]] + [2 * m * g * r[2] + m * g * a3]
    F = _cross(dLdv, w) + [
        x + y + z
        for x, y, z in zip(_cross(Iw, w), _cross(dLdv, v), _cross(dLdg, gamma), strict=True)
    ]
    gdot = _cross(gamma, w)
    cons = constraints("oblique")
    state_u = (*S.v, *S.w)
    J = [[_to_ring(P, ground, sp.diff(c, x), values) for x in state_u] for c in cons]
    b = [
        sum(
            (_to_ring(P, ground, sp.diff(c, y), values) * gdot[i] for i, y in enumerate(S.gamma)),
            P(0),
        )
        for c in cons
    ]
    inv_mass = [_inv(P, ground, x) for x in mass]
    A = [
        [sum((J[i][k] * J[j][k] * inv_mass[k] for k in range(6)), P(0)) for j in range(2)]
        for i in range(2)
    ]
    rhs = [-b[i] - sum((J[i][k] * F[k] * inv_mass[k] for k in range(6)), P(0)) for i in range(2)]
    det_inv = _inv(P, ground, A[0][0] * A[1][1] - A[0][1] * A[1][0])
    lam = [
        (rhs[0] * A[1][1] - A[0][1] * rhs[1]) * det_inv,
        (A[0][0] * rhs[1] - A[1][0] * rhs[0]) * det_inv,
    ]
    udot = [(F[k] + J[0][k] * lam[0] + J[1][k] * lam[1]) * inv_mass[k] for k in range(6)]
    vdot, wdot = udot[:3], udot[3:]
    rates_frame = {k: _rate(P, ground, _frame()[k], values, gdot) for k in ("tau", "n", "e")}
    vp = [v[i] + wxr[i] for i in range(3)]
    rdot = [-R * x for x in gdot]
    vpdot = [vdot[i] + _cross(wdot, r)[i] + _cross(w, rdot)[i] for i in range(3)]
    rates = {
        WT: _dot(wdot, tau) + _dot(w, rates_frame["tau"]),
        WN: _dot(wdot, n) + _dot(w, rates_frame["n"]),
        W3: wdot[2],
        U: _dot(vpdot, e) + _dot(vp, rates_frame["e"]),
    }
    q_rate = -(one + qq**2) * wt * half
    energy = (m * _dot(v, v) + _dot(w, Iw)) * half - m * g * _dot(r, gamma)
    return Reduced(P, ground, tuple(gens), rates, q_rate, energy, _dot(Iw, r), (I1, I3))


def _inv(P: Any, ground: Any, x: Any) -> Any:
    """``1 / x`` for ``x`` free of the velocities (an element of the ground field)."""
    if x == 0 or len(x.terms()) != 1 or any(x.LM):
        raise ValueError("division by zero or by a velocity-dependent expression")
    return P(ground.quo(ground.one, x.LC))


def _to_ring(P: Any, ground: Any, expr: Any, values: Mapping[Any, Any]) -> Any:
    """The sympy expression ``expr`` as an element of ``P``, its symbols replaced by
    ``values`` (elements of ``P``); negative powers only of velocity-free subexpressions."""
    memo: dict[Any, Any] = {}

    def value(e: Any) -> Any:
        found = memo.get(e)
        if found is not None:
            return found
        if e.is_Symbol:
            out = values[e]
        elif e.is_Rational:
            out = P(ground.convert(e))
        elif e.is_Add or e.is_Mul:
            out = value(e.args[0])
            for a in e.args[1:]:
                out = out + value(a) if e.is_Add else out * value(a)
        elif e.is_Pow and e.exp.is_Integer:
            base = value(e.base)
            k = int(e.exp)
            out = base**k if k >= 0 else _inv(P, ground, base) ** (-k)
        else:
            raise ValueError(f"not rational: {e}")
        memo[e] = out
        return out

    depth = sys.getrecursionlimit()
    sys.setrecursionlimit(max(depth, 20000))
    try:
        return value(sp.sympify(expr))
    finally:
        sys.setrecursionlimit(depth)


#: ``s = sqrt(gamma1^2 + gamma2^2)`` as a symbol of the frame's expressions.
_S = sp.Symbol("s_frame", positive=True)


def _frame() -> dict[str, Any]:
    """``tau, n, nu, e, d`` as sympy vectors of ``gamma`` (and :data:`_S`, ``t``)."""
    from rollingtop.contact.oblique import _cos_sin

    g1, g2, g3 = S.gamma
    e3 = sp.Matrix([0, 0, 1])
    c, sn = _cos_sin(sp)
    tau = e3.cross(S.gamma) / _S
    n = -sp.Matrix([g1, g2, 0]) / _S
    nu = (e3 - g3 * S.gamma) / _S
    return {"tau": tau, "n": n, "nu": nu, "e": -sn * nu + c * tau, "d": c * nu + sn * tau}


def _rate(P: Any, ground: Any, vec: Any, values: Mapping[Any, Any], gdot: list[Any]) -> list[Any]:
    """The time derivative of a frame vector of ``gamma`` along ``gamma' = gdot``."""
    out = []
    for comp in vec:
        total = P(0)
        for i, y in enumerate(S.gamma):
            dx = sp.diff(comp, y)
            if i < 2:  # through s = sqrt(gamma1^2 + gamma2^2)
                dx += sp.diff(comp, _S) * y / _S
            if dx != 0:
                total += _to_ring(P, ground, dx, values) * gdot[i]
        out.append(total)
    return out


def _cross(a: Sequence[Any], b: Sequence[Any]) -> list[Any]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: Sequence[Any], b: Sequence[Any]) -> Any:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _part(p: Any, degree: int) -> Any:
    """The homogeneous part of degree ``degree`` of ``p`` (in the velocities)."""
    return p.ring.from_dict({mon: c for mon, c in p.terms() if sum(mon) == degree})


def _divergence(red: Reduced) -> Any:
    """``div f`` in the coordinates ``(q, w_tau, w_n, w3, u)``: ``d q'/dq = -q w_tau`` plus the
    velocity rates' own derivatives."""
    P = red.ring
    qq = P(red.ground.convert(Q))
    total = -qq * red.gens[0]
    for i, x in enumerate(VELOCITIES):
        total += red.rates[x].diff(red.gens[i])
    return total


def _wtau_free(p: Any) -> dict[tuple[int, ...], Any]:
    """The coefficients of ``p``'s monomials free of ``w_tau`` (the first velocity)."""
    return {mon: c for mon, c in p.terms() if mon[0] == 0}


def _monomials(degree: int) -> list[tuple[int, ...]]:
    return [
        mon
        for mon in itertools.product(range(degree + 1), repeat=len(VELOCITIES))
        if sum(mon) == degree
    ]


def _monomial(red: Reduced, mon: tuple[int, ...]) -> Any:
    out = red.ring(1)
    for x, k in zip(red.gens, mon, strict=True):
        out *= x**k
    return out


#: The point where the prolonged constraints' rank is evaluated (module docstring): any
#: rational point gives a valid bound; this one is not special for any body (``q = 1`` is the
#: horizontal axis).
Q0 = Fraction(7, 5)


def _value_at(K: Any, e: Any, q0: Fraction) -> Any:
    """The ground-field element ``e`` at ``q = q0`` (a rational of :data:`sympy.QQ`)."""
    if len(K.symbols) != 1:
        raise ValueError("the rank bound needs a rational angle t (the ground field Q(q))")
    x = sp.QQ(q0.numerator, q0.denominator)
    num = e.numer.evaluate(e.numer.ring.gens[0], x)
    den = e.denom.evaluate(e.denom.ring.gens[0], x)
    num = num if isinstance(num, type(x)) else num.LC if num else sp.QQ(0)
    den = den if isinstance(den, type(x)) else den.LC
    if den == 0:
        raise ZeroDivisionError(f"the rank point q = {q0} is a pole")
    return num / den


def solution_bound(
    red: Reduced, forms: Sequence[Any], images: Sequence[Any], q0: Fraction = Q0
) -> int:
    """An upper bound on the dimension (over the constants) of the top-degree solutions
    ``c(q)`` of ``sum_j (c_j' q' forms[j] + c_j images[j]) = 0``.

    ``forms[j]`` is the ansatz's ``j``-th velocity monomial, ``images[j]`` the top-degree part of
    what it contributes with its coefficient frozen (``L_f`` of it, plus ``div f`` times it for
    a density). The monomial ``w_tau forms[j]`` carries ``c_j'`` (``q' = -(1 + q^2) w_tau / 2``):
    those rows give the first-order system ``c' = M c``, the others the constraints
    ``G_0 c = 0``, and a solution satisfies every prolongation ``G_{k+1} = G_k' + G_k M``. The
    dimension is at most ``n`` minus the rank of the stacked ``G_0 .. G_k`` over ``Q(q)``, and
    that rank is at least the rank at the point ``q = q0`` (exact, in rationals). The bound is
    returned once the rank stops growing or nothing is left.
    """
    K = red.ground
    n = len(forms)
    wt = red.gens[0]
    ode_rows = {(wt * f).LM: j for j, f in enumerate(forms)}
    monomials = sorted({m for col in images for m, _ in col.terms()} | set(ode_rows))
    table = [dict(col.terms()) for col in images]
    factor = K.convert(sp.Integer(2)) / K.convert(1 + Q**2)
    M = [[K.zero] * n for _ in range(n)]
    G: list[list[Any]] = []
    for mon in monomials:
        row = [table[j].get(mon, K.zero) for j in range(n)]
        if mon in ode_rows:
            M[ode_rows[mon]] = [factor * x for x in row]
        elif any(x != 0 for x in row):
            G.append(row)
    x = K.field.gens[0]
    stack: list[list[Any]] = []
    rank = 0
    for _ in range(n + 1):
        stack += [[_value_at(K, e, q0) for e in row] for row in G]
        new_rank = DomainMatrix(stack, (len(stack), n), sp.QQ).rank() if stack else 0
        if new_rank == n or (new_rank == rank and stack and _ > 0):
            rank = new_rank
            break
        rank = new_rank
        G = [
            [row[i].diff(x) + sum((row[k] * M[k][i] for k in range(n)), K.zero) for i in range(n)]
            for row in G
        ]
    return n - rank


def _velocity_monomials(red: Reduced, degree: int) -> list[Any]:
    return [_monomial(red, mon) for mon in _monomials(degree)]


def integral_bound(red: Reduced, degree: int) -> int:
    """Top-degree solutions of the integral ansatz homogeneous of ``degree`` in the velocities
    (coefficients functions of ``gamma3``): :func:`solution_dimension` with
    ``images = d(form)/dt`` (frozen coefficients), degree ``degree + 1``."""
    forms = _velocity_monomials(red, degree)
    r2 = [_part(red.rates[x], 2) for x in VELOCITIES]
    images = [sum((f.diff(x) * r2[k] for k, x in enumerate(red.gens)), red.ring(0)) for f in forms]
    return solution_bound(red, forms, images)


def density_bound(red: Reduced, degree: int) -> int:
    """Top-degree solutions of the density ansatz of ``degree`` in the velocities:
    ``images = L_f(form) + form div f`` (degree ``degree + 1``)."""
    forms = _velocity_monomials(red, degree)
    r2 = [_part(red.rates[x], 2) for x in VELOCITIES]
    div1 = _part(_divergence(red), 1)
    images = [
        f * div1 + sum((f.diff(x) * r2[k] for k, x in enumerate(red.gens)), red.ring(0))
        for f in forms
    ]
    return solution_bound(red, forms, images)


def _q_derivative(red: Reduced, p: Any) -> Any:
    """``dp/dq`` for ``p`` in ``P`` (the coefficients' derivative)."""
    x = red.ground.field.gens[0]
    return red.ring.from_dict({mon: c.diff(x) for mon, c in p.terms()})


def rate_of(red: Reduced, p: Any) -> Any:
    """``dp/dt`` along the reduced field, exactly (``p`` in ``P``)."""
    total = _q_derivative(red, p) * red.q_rate
    for k, x in enumerate(red.gens):
        total += p.diff(x) * red.rates[VELOCITIES[k]]
    return total


def classical(red: Reduced) -> dict[str, Any]:
    """The classical integrals that are exact integrals of this reduced field (checked by
    :func:`rate_of`), by name: ``energy``, ``jellett`` (every angle), ``lagrange`` (``w3``),
    ``area`` (``(I w, gamma)``) and ``slip`` (``u``) where they hold."""
    P, K = red.ring, red.ground
    _, wn, w3, u = red.gens
    qq = P(K.convert(Q))
    s = 2 * qq * _inv(P, K, P(1) + qq**2)
    g3 = (P(1) - qq**2) * _inv(P, K, P(1) + qq**2)
    I1, I3 = red.inertia
    candidates = {
        "energy": red.energy,
        "jellett": red.jellett,
        "lagrange": w3,
        # (I w, gamma) = I1 (w1 gamma1 + w2 gamma2) + I3 w3 gamma3 on the slice
        "area": -I1 * s * wn + I3 * g3 * w3,
        # the contact point's slip along e (the companion model's particular integral when
        # a3 = 0, I3 = I1: rollingtop.symbolic.parallel)
        "slip": u,
    }
    return {name: p for name, p in candidates.items() if rate_of(red, p) == 0}


def _rank_at(red: Reduced, polys: Sequence[Any], q0: Fraction = Q0) -> int:
    """The rank over the constants of ``polys`` is at least that of their coefficient vectors at
    ``q = q0`` (the number a lower bound needs)."""
    monomials = sorted({m for p in polys for m, _ in p.terms()})
    if not polys or not monomials:
        return 0
    K = red.ground
    rows = [[_value_at(K, dict(p.terms()).get(m, K.zero), q0) for m in monomials] for p in polys]
    return int(DomainMatrix(rows, (len(rows), len(monomials)), sp.QQ).rank())


#: The default angles of :func:`search`, as ``t = tan(phi / 2)``: both ends (0 and 1) and
#: rational points between them and beyond, twelve distinct constraints (``phi`` and
#: ``phi + pi``, i.e. ``t`` and ``-1/t``, are one: ``t`` in ``(-1, 1]`` covers the family).
DEFAULT_T = tuple(
    Fraction(x)
    for x in ("0", "1/8", "1/4", "1/3", "1/2", "2/3", "3/4", "1", "-1/4", "-1/2", "-2/3", "-7/8")
)
#: The highest degree in the velocities of the density ansatz searched by default.
DENSITY_DEGREE = 2


@dataclass(frozen=True)
class AngleResult:
    """What :func:`search` found at one angle.

    ``bounds[name]``: an upper bound on the dimension (over the constants) of the top-degree
    parts of the ansatz ``name`` (``"linear"``, ``"quadratic"``, ``"density N"``);
    ``known[name]``: the dimension the classical integrals (``integrals``, proved exact
    integrals of the reduced field at this angle) account for. Where the two agree the class
    holds nothing else; a density bound 0 rules that density out.
    """

    t: Fraction
    integrals: tuple[str, ...]
    bounds: dict[str, int]
    known: dict[str, int]

    @property
    def angle(self) -> float:
        """``phi`` in radians, in ``(-pi, pi)``."""
        return 2 * math.atan(self.t)

    #: Whether a density of ``gamma3`` alone exists: every coefficient of ``div f`` but that of
    #: ``w_tau`` vanishes identically (then ``div f = w_tau F(q)`` and ``rho`` is
    #: ``exp(2 int F / (1 + q^2) dq)``), decided exactly.
    density: bool = False

    def closed(self, name: str) -> bool:
        """Whether the class ``name`` holds only what the classical integrals account for."""
        return self.bounds[name] == self.known[name]

    def to_dict(self) -> dict[str, Any]:
        return {
            "t": str(self.t),
            "angle": self.angle,
            "integrals": list(self.integrals),
            "density_gamma3": self.density,
            "bounds": dict(self.bounds),
            "known": dict(self.known),
        }


def search_angle(
    body: tuple[tuple[str, Fraction], ...], t: Fraction, max_degree: int = DENSITY_DEGREE
) -> AngleResult:
    """The searches of the module docstring at one rational ``t = tan(phi / 2)``."""
    red = reduced_field(body, t)
    found = classical(red)
    linear = [_part(found[n], 1) for n in ("jellett", "lagrange", "area", "slip") if n in found]
    products = [a * b for i, a in enumerate(linear) for b in linear[i:]]
    bounds = {
        "linear": integral_bound(red, 1),
        "quadratic": integral_bound(red, 2),
    }
    known = {
        "linear": _rank_at(red, linear),
        "quadratic": _rank_at(red, [*products, _part(found["energy"], 2)]),
    }
    for degree in range(max_degree + 1):
        bounds[f"density {degree}"] = density_bound(red, degree)
        known[f"density {degree}"] = 0
    density = not _wtau_free(_divergence(red))
    return AngleResult(t, tuple(found), bounds, known, density)


def density_obstruction(body: tuple[tuple[str, Fraction], ...]) -> sp.Poly:
    """The angles with a density of ``gamma3`` alone, symbolically in ``t = tan(phi / 2)``.

    Every coefficient of ``div f`` but that of ``w_tau`` must vanish identically in ``q``
    (module docstring); each is a polynomial in ``q`` whose coefficients are polynomials in
    ``t``. Returns their greatest common divisor, a polynomial in ``t``: its real roots are the
    only angles where such a density can exist (and it does where the remaining coefficient is
    ``w_tau`` times a function of ``q``, which :func:`search_angle` checks at those angles)."""
    red = reduced_field(body, None)
    div = _divergence(red)
    gcd = None
    for _, c in _wtau_free(div).items():
        numer = sp.Poly(c.numer.as_expr(), Q, PHI_T)
        for co in sp.Poly(numer.as_expr(), Q).all_coeffs():
            poly = sp.Poly(co, PHI_T)
            gcd = poly if gcd is None else sp.gcd(gcd, poly)
    return gcd if gcd is not None else sp.Poly(0, PHI_T)


def as_rational_body(values: Mapping[str, float]) -> tuple[tuple[str, Fraction], ...]:
    """A body's parameters as exact rationals (a float's shortest decimal, so ``0.1`` is
    ``1/10``): the searches are exact for the body they print."""
    return tuple((n, Fraction(repr(float(values[n])))) for n in _BODY)


@dataclass(frozen=True)
class SearchResult:
    """:func:`search`'s answer for one body: the rational body, the obstruction polynomial in
    ``t`` and its real roots (the angles where a density of ``gamma3`` can exist), and one
    :class:`AngleResult` per angle."""

    body: tuple[tuple[str, Fraction], ...]
    obstruction: sp.Poly
    density_angles: tuple[float, ...]
    angles: list[AngleResult] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "body": {n: str(v) for n, v in self.body},
            "obstruction": str(self.obstruction.as_expr()),
            "density_angles": list(self.density_angles),
            "angles": [a.to_dict() for a in self.angles],
        }


def search(
    body: Mapping[str, float],
    ts: Sequence[Fraction] = DEFAULT_T,
    max_degree: int = DENSITY_DEGREE,
    progress: Any = None,
) -> SearchResult:
    """Search the oblique family of ``body`` (``R, m, g, a3, I1, I3``) for an invariant measure
    and integrals: symbolically in ``t`` for a density of ``gamma3`` alone, at each ``t`` of
    ``ts`` for the polynomial classes (module docstring). ``progress(k)`` is called after each
    angle."""
    exact = as_rational_body(body)
    obstruction = density_obstruction(exact)
    roots = (
        sorted(
            2 * math.atan(float(r)) for r in sp.real_roots(obstruction) if obstruction.degree() > 0
        )
        if obstruction.degree() > 0
        else []
    )
    out = []
    for k, t in enumerate(ts):
        out.append(search_angle(exact, Fraction(t), max_degree))
        if progress is not None:
            progress(k + 1)
    return SearchResult(exact, obstruction, tuple(sorted(set(roots))), out)
