"""Exact arithmetic on sympy expressions as graphs, for :mod:`rollingtop.symbolic.claims`.

Each distinct subexpression is visited once: its size (:func:`_tree_size`), its free symbols
(:func:`_symbols`), its value at a rational point in Python's :class:`fractions.Fraction`
(:func:`_rational_value`) and its normal form in sympy's field of rational functions
(:func:`_field_value`). Written here because sympy walks an expression as a tree (its
``xreplace``, ``free_symbols`` and ``lambdify`` visit a shared subexpression once per
occurrence, up to 10^6 nodes on a derived rate) and ``lambdify`` prints rationals as floats.
"""

from __future__ import annotations

import math
import random
import sys
from fractions import Fraction
from typing import Any

import sympy as sp

from rollingtop.symbolic.equations import SYMBOLS as S

#: The field route of the exact simplification gives up above this many terms in a numerator
#: or denominator (the smooth model's momentum rates reach 610-667 and take 12-15 s there, 5-7 s
#: by ``cancel``; every other claim stays below 130 and takes at most 0.8 s there, up to 9 s by
#: ``cancel``: measured on the claims of every model).
FIELD_TERMS_LIMIT = 160


def _random_rational(rng: random.Random, lo: int = -3, hi: int = 3) -> Any:
    return sp.Rational(Fraction(rng.randint(lo * 97, hi * 97), rng.randint(1, 97)))


class _NotRational(Exception):
    """A subexpression whose value at a rational point need not be rational."""


def _tree_size(expr: Any, limit: int) -> int:
    """Nodes of ``expr``'s tree, counted up to ``limit + 1``."""
    n = 0
    for _ in sp.preorder_traversal(expr):
        n += 1
        if n > limit:
            break
    return n


def _symbols(expr: Any) -> set[Any]:
    """``expr.free_symbols``, each distinct subexpression visited once (sympy's property walks
    the tree: seconds for the shell-rotor pair's rates, whose few hundred subexpressions repeat
    10^6 times)."""
    seen: set[int] = set()
    out: set[Any] = set()
    stack = [expr]
    while stack:
        e = stack.pop()
        if id(e) in seen:
            continue
        seen.add(id(e))
        if e.is_Symbol:
            out.add(e)
        else:
            stack.extend(e.args)
    return out


def _free_parts(
    expr: Any, symmetric: bool, params: tuple[tuple[Any, Any], ...], subs: dict[Any, Any]
) -> tuple[Any, dict[Any, Any], list[Any]]:
    """``expr`` sympified, the manifold's substitutions it needs, and the symbols left free once
    they, the parameters' and ``I2 = I1`` (if ``symmetric``) are made, sorted by name."""
    expr = sp.sympify(expr)
    present = _symbols(expr)
    subs = {x: image for x, image in subs.items() if x in present}
    replaced = set(subs) | {a for a, _ in params} | ({S.I2} if symmetric else set())
    base = set(present)
    for image in (*subs.values(), *(sp.sympify(b) for _, b in params)):
        base |= _symbols(image)
    return expr, subs, sorted(base - replaced, key=lambda x: x.name)


class _TooLarge(Exception):
    """An intermediate rational function beyond :data:`FIELD_TERMS_LIMIT` terms."""


def _field_value(
    expr: Any, symmetric: bool, params: tuple[tuple[Any, Any], ...], subs: dict[Any, Any]
) -> Any:
    """``expr`` on the manifold as an element of sympy's sparse field of rational functions
    (:func:`sympy.polys.fields.field` over QQ): the substitutions of :func:`_on_manifold` made
    on the field's values, each distinct subexpression once. Zero is the zero element, so the
    claim is decided exactly. Raises :class:`_NotRational` for a node outside the field and
    :class:`_TooLarge` (module docstring)."""
    from sympy.polys.fields import field

    expr, subs, symbols = _free_parts(expr, symmetric, params, subs)
    if not symbols:
        return sp.cancel(expr)
    K, *gens = field(symbols, sp.QQ)
    values: dict[Any, Any] = dict(zip(symbols, gens, strict=True))

    def value_of(e: Any) -> Any:
        memo: dict[Any, Any] = {}

        def value(e: Any) -> Any:
            found = memo.get(e)
            if found is not None:
                return found
            if e.is_Symbol:
                out = values[e]
            elif e.is_Rational:
                out = K(sp.QQ(int(e.p), int(e.q)))
            elif e.is_Add or e.is_Mul:
                out = value(e.args[0])
                for a in e.args[1:]:
                    out = out + value(a) if e.is_Add else out * value(a)
            elif e.is_Pow and e.exp.is_Integer:
                out = value(e.base) ** int(e.exp)
            else:
                raise _NotRational(str(e))
            if len(out.numer) > FIELD_TERMS_LIMIT or len(out.denom) > FIELD_TERMS_LIMIT:
                raise _TooLarge
            memo[e] = out
            return out

        return value(sp.sympify(e))

    if symmetric and S.I1 in values:
        values[S.I2] = values[S.I1]
    for a, b in params:
        values[a] = value_of(b)
    values.update({x: value_of(image) for x, image in subs.items()})
    depth = sys.getrecursionlimit()
    sys.setrecursionlimit(max(depth, 20000))
    try:
        return value_of(expr)
    finally:
        sys.setrecursionlimit(depth)


def _rational_value(expr: Any, values: dict[Any, Fraction]) -> Fraction:
    """``expr`` at the point ``values`` (symbol -> Fraction), exactly, each distinct subexpression
    once (module docstring). Raises :class:`_NotRational` for a node other than a symbol, a
    rational number, a sum, a product or an integer power (a root that is not exact), and
    ``ZeroDivisionError`` at a pole of the rational function."""
    memo: dict[Any, Fraction] = {}

    def value(e: Any) -> Fraction:
        found = memo.get(e)
        if found is not None:
            return found
        if e.is_Symbol:
            out = values[e]
        elif e.is_Rational:
            out = Fraction(int(e.p), int(e.q))
        elif e.is_Add:
            out = sum((value(a) for a in e.args), Fraction(0))
        elif e.is_Mul:
            out = Fraction(1)
            for a in e.args:
                out *= value(a)
        elif e.is_Pow and e.exp.is_Integer:
            out = value(e.base) ** int(e.exp)
        elif e.is_Pow and e.exp == sp.S.Half:  # exact only for squares of rationals
            base = value(e.base)
            if base < 0:
                raise _NotRational(str(e))
            num, den = math.isqrt(base.numerator), math.isqrt(base.denominator)
            if num * num != base.numerator or den * den != base.denominator:
                raise _NotRational(str(e))
            out = Fraction(num, den)
        else:
            raise _NotRational(str(e))
        memo[e] = out
        return out

    depth = sys.getrecursionlimit()
    sys.setrecursionlimit(max(depth, 20000))  # a deep sum of products recurses once per level
    try:
        return value(expr)
    finally:
        sys.setrecursionlimit(depth)
