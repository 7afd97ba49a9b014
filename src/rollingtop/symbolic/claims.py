"""Machine-checked claims about the models: first integrals, identities, reduction, measure.

A claim is an expression that must vanish on the constraint manifold: the time derivative of a
first integral along the derived vector field (:mod:`.equations`), an identity, or the difference
between the full and the reduced equations. It is decided by

1. **exact simplification** when the expression is small enough to simplify quickly: the
   manifold is parametrised *rationally* (``gamma`` by two rational parameters with
   ``s = sqrt(1 - gamma3^2)`` itself rational, the velocity by the constraints' free components)
   and the result cancelled to a normal form -- zero is a proof. The normal form is computed
   first in sympy's field of rational functions (:func:`._exact._field_value`: each distinct
   subexpression once, reduced by the gcd as it is formed), and where an intermediate result
   grows beyond :data:`FIELD_TERMS_LIMIT` terms by ``cancel(together(...))`` on the substituted
   expression, the faster of the two on the claims where each was measured;
2. otherwise **exact evaluation at random rational points** (all parameters and variables drawn
   as rationals, arithmetic in exact rationals): nonzero anywhere disproves the claim, zero at
   every one of several independent points establishes it with the certainty of polynomial
   identity testing (a nonzero rational function vanishes on a set of measure zero).

   The evaluation walks the expression as the graph it is (:func:`._exact._rational_value`): a
   derived rate has a few hundred distinct subexpressions but, once the manifold's rational
   functions are substituted, a tree of up to 10^6 nodes, which sympy's substitution and
   arithmetic visit one by one (seconds per claim). Each distinct subexpression is evaluated
   once, in Python's exact :class:`fractions.Fraction`, with the manifold's substitutions
   evaluated first at the point. sympy has no such evaluator (``lambdify`` prints rationals as
   floats; ``xreplace`` walks the tree); an expression with a non-rational part (a square root
   of a non-square) is evaluated by sympy as before.

Each result says which method decided it.
"""

from __future__ import annotations

import importlib
import random
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from fractions import Fraction
from typing import Any

import sympy as sp

from rollingtop.contact import MODELS, get_model
from rollingtop.symbolic._exact import (
    _field_value,
    _free_parts,
    _NotRational,
    _random_rational,
    _rational_value,
    _TooLarge,
    _tree_size,
)
from rollingtop.symbolic.equations import SYMBOLS, derive

__all__ = ["Claim", "ClaimResult", "claims_for", "decide", "verify"]

#: Above this many operations the exact route is skipped for the random rational points.
EXACT_OPS_LIMIT = 4000
#: An expression (before the manifold's substitution) with a tree larger than this goes straight
#: to the random rational points: its operation count (4000 at most for the exact route) would
#: cost more than the evaluation itself (every claim's tree above it counts > 20000 operations).
EXACT_TREE_LIMIT = 20000
#: Random rational points of the fallback.
N_POINTS = 4
#: The classical integrals of a rolling top: each one a model does not claim is shown to vary.
LOST_CANDIDATES = ("lagrange", "jellett", "area")
#: Integrals with a square root, proved through their square (rational).
SQUARED = ("routh", "rubber_spin")

S = SYMBOLS
# extra symbols: s = sqrt(gamma1^2 + gamma2^2) and theta = arccos(gamma3) as variables with
# their own time derivatives (keeps every expression rational)
s_sym, theta_sym = sp.symbols("s theta", positive=True)
q, k = sp.symbols("q k", positive=True)  # rational parametrisation of gamma
j = sp.Symbol("j", real=True)  # azimuth of the fixed x axis, rationally
# free velocity components: as many symbols as the registered model with the most has
free = sp.symbols(
    f"c1:{1 + max(2, *(sum(m.free_velocity.values()) for m in MODELS.values()))}", real=True
)
#: the angular velocity's components on the manifold of a model that constrains it alone
#: (:attr:`~rollingtop.contact.Symbolic.omega`; rubber rolling: ``w`` horizontal)
spin = sp.symbols("w_a w_b", real=True)


@dataclass(frozen=True)
class Claim:
    """``expr`` must vanish on the manifold of ``model``; ``kind``: "integral" (``expr`` is the
    integral, its time derivative is tested), "identity" (``expr`` itself) or "given" (an
    already-built expression of the state and ``s``). With ``vanishes=False`` the claim is the
    opposite, that ``expr`` (its rate, for an integral) is not identically zero: an integral the
    model does not conserve, proved by exact simplification or by a rational counterexample."""

    name: str
    model: str
    expr: sp.Expr
    kind: str = "integral"
    symmetric: bool = True
    #: parameter values of a particular case, ``((symbol, value), ...)``, substituted into the
    #: expression to decide (after the time derivative)
    params: tuple[tuple[Any, Any], ...] = ()
    vanishes: bool = True


@dataclass(frozen=True)
class ClaimResult:
    name: str
    model: str
    result: str  # "proved" | "failed"
    method: str
    seconds: float

    def to_dict(self) -> dict[str, str | float]:
        return asdict(self)


def _time_derivative(expr: Any, field: dict[Any, Any]) -> Any:
    """``d expr/dt`` along ``field`` (a dict symbol -> derivative), with ``s`` and ``theta``."""
    g1, g2, g3 = S.gamma
    extended = dict(field)
    extended[s_sym] = (g1 * field[g1] + g2 * field[g2]) / s_sym
    extended[theta_sym] = -field[g3] / s_sym
    return sum(sp.diff(expr, x) * dx for x, dx in extended.items() if expr.has(x))


def _manifold(model: str) -> dict[Any, Any]:
    """Rational parametrisation of the constraint manifold: substitutions for gamma, s, v,
    alpha, beta in terms of ``q, k`` (gamma), the free components and ``w``; and for ``w`` in
    terms of :data:`spin` where the model constrains it (``Symbolic.omega``)."""
    sq = 2 * q / (1 + q**2)
    cphi, sphi = (1 - k**2) / (1 + k**2), 2 * k / (1 + k**2)
    gamma = sp.Matrix([sq * cphi, sq * sphi, (1 - q**2) / (1 + q**2)])
    e3 = sp.Matrix([0, 0, 1])
    tau = e3.cross(gamma) / sq  # unit, rational
    r = -S.R * gamma - sp.Matrix([0, 0, S.a3])
    contact = get_model(model)
    w = S.w if contact.symbolic.omega is None else contact.symbolic.omega(gamma, tau, spin)
    wxr = w.cross(r)  # with the parametrised w: xreplace does not substitute into v's value
    v = contact.symbolic.velocity(gamma, tau, wxr, free)
    nu = (e3 - gamma[2] * gamma) / sq  # unit, rational
    alpha = ((1 - j**2) * tau + 2 * j * nu) / (1 + j**2)  # generic horizontal unit vector
    beta = gamma.cross(alpha)
    subs = {s_sym: sq}
    for i in range(3):
        subs[S.gamma[i]] = gamma[i]
        subs[S.v[i]] = v[i]
        subs[S.alpha[i]] = alpha[i]
        subs[S.beta[i]] = beta[i]
        if contact.symbolic.omega is not None:
            subs[S.w[i]] = w[i]
    return subs


def _draw(rng: random.Random, x: Any) -> Any:
    """A random rational for the symbol ``x``: ``q, k`` in (0, 1), masses and inertias
    positive, anything else in [-3, 3]."""
    if x in (q, k):
        return sp.Rational(rng.randint(1, 50), rng.randint(51, 120))  # in (0, 1)
    if x in (S.m, S.I1, S.I2, S.I3, S.R) or x.is_positive:  # masses, inertias
        return sp.Rational(rng.randint(20, 200), rng.randint(20, 100))
    return _random_rational(rng)


def _on_manifold(
    expr: Any,
    model: str,
    symmetric: bool,
    params: tuple[tuple[Any, Any], ...],
    subs: dict[Any, Any],
) -> Any:
    """``expr`` with the manifold's substitutions, then the parameters', then ``I2 = I1``."""
    on = sp.sympify(expr).xreplace(subs)
    if params:  # after the manifold, whose velocities involve the parameters
        on = on.xreplace(dict(params))
    if symmetric:
        on = on.xreplace({S.I2: S.I1})
    return on


def _evaluate_fast(
    expr: Any,
    symmetric: bool,
    params: tuple[tuple[Any, Any], ...],
    subs: dict[Any, Any],
    rng: random.Random,
) -> tuple[bool, str]:
    """The random rational points by :func:`_rational_value`: the same substitutions as
    :func:`_on_manifold`, in the same order, made on the point's values instead of the
    expression (raises :class:`_NotRational` where a value need not be rational)."""
    expr, subs, symbols = _free_parts(expr, symmetric, params, subs)
    done = 0
    for _ in range(50 * N_POINTS):  # a point at a pole of the rational function is drawn again
        point = {x: _draw(rng, x) for x in symbols}
        if S.I2 in point and not symmetric:  # keep the triangle inequality and I1 != I2
            point[S.I3] = min(point[S.I3], point[S.I1] + point[S.I2])
        values = {x: Fraction(int(v.p), int(v.q)) for x, v in point.items()}
        try:
            if symmetric:
                values[S.I2] = values[S.I1]
            for a, b in params:
                values[a] = _rational_value(sp.sympify(b), values)
            images = {x: _rational_value(image, values) for x, image in subs.items()}
            values.update(images)
            val = _rational_value(expr, values)
        except ZeroDivisionError:
            continue
        if val != 0:
            return False, (
                f"exact evaluation: nonzero ({float(val):.6g}) at a random rational point"
            )
        done += 1
        if done == N_POINTS:
            return True, f"exact evaluation at {N_POINTS} random rational points"
    raise _NotRational("every point drawn is a pole")


def decide(
    expr: Any,
    model: str,
    symmetric: bool = True,
    seed: int = 1,
    params: tuple[tuple[Any, Any], ...] = (),
) -> tuple[bool, str]:
    """Does ``expr`` (a function of the state, ``s``, ``theta`` and the parameters) vanish on
    the manifold of ``model`` (with the parameter values ``params``, if any)? Returns
    ``(holds, method)``."""
    subs = _manifold(model)
    on = None
    if _tree_size(sp.sympify(expr), EXACT_TREE_LIMIT) <= EXACT_TREE_LIMIT:
        on = _on_manifold(expr, model, symmetric, params, subs)
        if sp.count_ops(on, visual=False) <= EXACT_OPS_LIMIT:
            try:
                return _field_value(expr, symmetric, params, subs) == 0, "exact simplification"
            except (_NotRational, _TooLarge):
                normal = sp.cancel(sp.together(on))
                return normal == 0, "exact simplification"
    rng = random.Random(seed)
    try:
        return _evaluate_fast(expr, symmetric, params, subs, rng)
    except _NotRational:
        pass
    if on is None:
        on = _on_manifold(expr, model, symmetric, params, subs)
    rng = random.Random(seed)
    symbols = sorted(on.free_symbols, key=lambda x: x.name)
    for _ in range(N_POINTS):
        values: dict[Any, Any] = {x: _draw(rng, x) for x in symbols}
        if not symmetric:  # keep the triangle inequality and I1 != I2
            values[S.I3] = min(values[S.I3], values[S.I1] + values.get(S.I2, values[S.I1]))
        val = on.xreplace(values)
        val = sp.nsimplify(val) if val.has(sp.Float) else sp.simplify(val)
        if val != 0:
            return False, f"exact evaluation: nonzero ({sp.N(val, 6)}) at a random rational point"
    return True, f"exact evaluation at {N_POINTS} random rational points"


def _integrals() -> dict[str, Any]:
    I = sp.diag(S.I1, S.I2, S.I3)
    Iw = I * S.w
    r = -S.R * S.gamma - sp.Matrix([0, 0, S.a3])
    g1, g2, g3 = S.gamma
    v_tau = (-g2 * S.v[0] + g1 * S.v[1]) / s_sym
    w_n = -(g1 * S.w[0] + g2 * S.w[1]) / s_sym
    M3 = S.I3 * S.w[2]
    F6 = S.I1 * (v_tau - (S.R * g3 + S.a3) * w_n) - M3 * (S.R * s_sym + S.a3 * theta_sym)
    Q = S.I1 * S.I3 + S.m * S.I1 * (r[0] ** 2 + r[1] ** 2) + S.m * S.I3 * r[2] ** 2
    return {
        "energy": S.m * S.v.dot(S.v) / 2 + S.w.dot(Iw) / 2 - S.m * S.g * r.dot(S.gamma),
        "lagrange": M3,
        "jellett": Iw.dot(r),
        "area": Iw.dot(S.gamma),
        "F6": F6,
        "routh^2": S.w[2] ** 2 * Q,  # Routh's integral w3 sqrt(Q), squared: rational
        # rubber rolling's w3 sqrt(I3 J), J = (I nu, nu) + m (r, gamma)^2 with the axis's
        # horizontal projection nu: (I nu, nu) = I1 + I3 - (I gamma, gamma); squared
        "rubber_spin^2": S.w[2] ** 2
        * S.I3
        * (S.I1 + S.I3 - S.gamma.dot(I * S.gamma) + S.m * r.dot(S.gamma) ** 2),
        "momentum_x": S.m * S.v.dot(S.alpha),
        "momentum_y": S.m * S.v.dot(S.beta),
    }


def _reduced_claims() -> dict[str, tuple[Any, Any]]:
    """The reduced system (3.3) follows from the full one: d/dt of (gamma3, v_tau, w_n, w_tau)
    along the full field minus the right-hand sides of (3.3)."""
    g1, g2, g3 = S.gamma
    s = s_sym
    v_tau = (-g2 * S.v[0] + g1 * S.v[1]) / s
    w_tau = (-g2 * S.w[0] + g1 * S.w[1]) / s
    w_n = -(g1 * S.w[0] + g2 * S.w[1]) / s
    M3 = S.I3 * S.w[2]
    rho = S.I1 + S.m * (S.a3**2 + S.R**2 + 2 * S.a3 * S.R * g3)
    k_ = S.R + S.a3 * g3
    rhs = {
        "gamma3": (g3, s * w_tau),
        "v_tau": (v_tau, w_tau * w_n * k_ / s),
        "w_n": (w_n, w_tau * (M3 / S.I1 + g3 * w_n / s)),
        "w_tau": (
            w_tau,
            -(
                S.m * S.a3 * s * (S.g + S.R * w_tau**2)
                + M3 * w_n
                + S.I1 * g3 * w_n**2 / s
                + S.m * v_tau * w_n * k_ / s
            )
            / rho,
        ),
    }
    return rhs


def invariant_measure_claim() -> tuple[bool, str]:
    """div(rho * field) of the reduced system (3.3) vanishes identically (exact)."""
    G, vt, wn, wt, M3 = sp.symbols("gamma3 v_tau w_n w_tau M3", real=True)
    R, m, g, a3, I1 = S.R, S.m, S.g, S.a3, S.I1
    s = sp.sqrt(1 - G**2)
    rho = I1 + m * (a3**2 + R**2 + 2 * a3 * R * G)
    k_ = R + a3 * G
    field = [
        s * wt,
        wt * wn * k_ / s,
        wt * (M3 / I1 + G * wn / s),
        -(m * a3 * s * (g + R * wt**2) + M3 * wn + I1 * G * wn**2 / s + m * vt * wn * k_ / s) / rho,
    ]
    div = sum(sp.diff(rho * f, x) for f, x in zip(field, (G, vt, wn, wt), strict=True))
    # gamma3 = (1 - q^2)/(1 + q^2) makes s = 2q/(1 + q^2) rational (q > 0)
    div = div.subs(G, (1 - q**2) / (1 + q**2))
    return sp.cancel(sp.together(sp.powdenest(sp.simplify(div), force=True))) == 0, (
        "exact simplification"
    )


def _model_claims(model: str) -> list[Claim]:
    """The claims of the model's own symbolic module (``Symbolic.claims``)."""
    extra = get_model(model).symbolic.claims
    if extra is None:
        return []
    module, function = extra.split(":")
    claims: list[Claim] = getattr(importlib.import_module(module), function)()
    return claims


def claims_for(model: str) -> list[Claim]:
    """The claims checked for ``model``: its integrals and identities from the derived
    equations (:func:`.equations.derive`), then its own module's; a model whose kinetic energy
    is not the body's alone (``ContactModel.own_inertia``) has only its own."""
    if get_model(model).own_inertia:
        return _model_claims(model)
    F = _integrals()
    out = []
    # the integrals the model claims (those with a square root through their square)
    names = [n + "^2" if n in SQUARED else n for n in get_model(model).integrals_symmetric]
    for name in names:
        label = (
            f"{name[:-2]} integral conserved (its square)"
            if name.endswith("^2")
            else f"{name} integral conserved"
        )
        out.append(Claim(label, model, F[name]))
    out.append(
        Claim(
            "energy integral conserved, general body (I1 != I2)",
            model,
            F["energy"],
            symmetric=False,
        )
    )
    # the classical integrals the model loses: shown to vary (a nonzero rate)
    for name in LOST_CANDIDATES:
        if name not in get_model(model).integrals_symmetric:
            out.append(Claim(f"{name} integral not conserved", model, F[name], vanishes=False))
    from rollingtop.reduction.models import closed_form_diagram

    if closed_form_diagram(model):
        out.append(
            Claim(
                "identity jellett + a3 lagrange + R area = 0",
                model,
                F["jellett"] + S.a3 * F["lagrange"] + S.R * F["area"],
                "identity",
            )
        )
        for var, (expr, rhs) in _reduced_claims().items():
            out.append(
                Claim(
                    f"reduced system (3.3): {var}' follows from the full equations",
                    model,
                    (expr, rhs),
                    "reduced",
                )
            )
    out.extend(_model_claims(model))
    return out


def check(claim: Claim, seed: int = 1) -> ClaimResult:
    """Decide one claim."""
    start = time.perf_counter()
    d = derive(claim.model, claim.symmetric)
    if claim.kind == "integral":
        expr = _time_derivative(claim.expr, d.field)
    elif claim.kind == "reduced":
        lhs, rhs = claim.expr
        expr = _time_derivative(lhs, d.field) - rhs
    else:
        expr = claim.expr
    holds, method = decide(expr, claim.model, claim.symmetric, seed=seed, params=claim.params)
    proved = holds == claim.vanishes
    return ClaimResult(
        claim.name,
        claim.model,
        "proved" if proved else "failed",
        method,
        time.perf_counter() - start,
    )


def verify(
    models: Sequence[str] = tuple(MODELS),
    progress: Callable[[int, int], None] | None = None,
) -> list[ClaimResult]:
    """Check every claim of ``models`` (and the invariant measure of the reduced system with a
    model that has a reduction).

    Parameters
    ----------
    models : sequence of str
        Registered model names (default: all).
    progress : callable, optional
        ``progress(done, total)`` after each claim decided (``total``: the claims of all
        ``models``).

    Returns
    -------
    list of ClaimResult
        In order: each model's claims (:func:`claims_for`), then its invariant measure.
    """
    from rollingtop.reduction.models import closed_form_diagram

    plan = [(model, claims_for(model), closed_form_diagram(model)) for model in models]
    total = sum(len(claims) + measure for _, claims, measure in plan)
    results: list[ClaimResult] = []

    def decided(result: ClaimResult) -> None:
        results.append(result)
        if progress is not None:
            progress(len(results), total)

    for model, claims, measure in plan:
        for claim in claims:
            decided(check(claim))
        if measure:
            start = time.perf_counter()
            holds, method = invariant_measure_claim()
            decided(
                ClaimResult(
                    "invariant measure rho(gamma3) of the reduced system",
                    model,
                    "proved" if holds else "failed",
                    method,
                    time.perf_counter() - start,
                )
            )
    return results
