"""Equations of motion derived with sympy from the Lagrangian and a contact model's constraints.

Quasi-velocities ``u = (v, w)`` (body frame) and the vertical ``gamma`` as advected parameter.
From ``L = m (v, v)/2 + (w, I w)/2 + m g (r, gamma)``, ``r = -R gamma - a`` (paper Sec. 2), the
d'Alembert-Lagrange (Poincare) equations with ideal constraint reactions are

    d/dt dL/dv = dL/dv x w                               + sum_k lambda_k dc_k/dv
    d/dt dL/dw = dL/dw x w + dL/dv x v + dL/dgamma x gamma + sum_k lambda_k dc_k/dw
    gamma' = gamma x w,

where ``c_k(u, gamma) = (vp, d_k)`` are the model's constraints, linear in ``u``
(``vp = v + w x r``), and those on the angular velocity alone, ``c = (w, d)`` (rubber rolling's
``(w, gamma) = 0``: its reaction ``lambda dc/dw = lambda gamma`` is a torque).
The multipliers are eliminated with the differentiated constraints
``dc_k/du . u' + dc_k/dgamma . gamma' = 0``: ``lambda = (J M^-1 J^T)^-1 (-b - J M^-1 F)`` with
``J = dc/du``, ``b = dc/dgamma . gamma'`` and ``M`` the kinetic Hessian. The meridian constraint
uses the unnormalised direction ``e3 - gamma3 gamma`` (it spans the same condition away from the
pole and keeps the expressions rational).

Here gravity enters through the potential's dependence on ``gamma`` (the CoM height is
``-(r, gamma)``), i.e. as the torque ``m g gamma x a`` about the CoM, whereas the compiled kernel
applies the force ``-m g gamma`` at the CoM: the two differ by a force along the normal at the
contact point, which the normal multiplier absorbs -- the accelerations agree (tests).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

import sympy as sp

from rollingtop._types import FloatArray
from rollingtop.contact import get_model

__all__ = ["PHI_T", "Symbols", "SYMBOLS", "derive", "Derivation"]


@dataclass(frozen=True)
class Symbols:
    """The sympy symbols of the body, the state and the fixed frame."""

    R: sp.Symbol
    m: sp.Symbol
    g: sp.Symbol
    a3: sp.Symbol
    I1: sp.Symbol
    I2: sp.Symbol
    I3: sp.Symbol
    v: sp.Matrix
    w: sp.Matrix
    gamma: sp.Matrix
    alpha: sp.Matrix
    beta: sp.Matrix

    @property
    def params(self) -> tuple[Any, ...]:
        """``(R, m, g, a3, I1, I2, I3)``, the order of :attr:`rollingtop.SphericalTop.params`."""
        return (self.R, self.m, self.g, self.a3, self.I1, self.I2, self.I3)

    @property
    def state(self) -> tuple[Any, ...]:
        """``(v, w, alpha, beta, gamma)`` as a flat tuple of 15 symbols."""
        return (*self.v, *self.w, *self.alpha, *self.beta, *self.gamma)


def _make_symbols() -> Symbols:
    R, m, a3_ = sp.symbols("R m a3", real=True)
    g = sp.Symbol("g", nonnegative=True)
    I1, I2, I3 = sp.symbols("I1 I2 I3", positive=True)

    def vec(name: str) -> Any:
        return sp.Matrix(sp.symbols(f"{name}1:4", real=True))

    return Symbols(
        R, m, g, a3_, I1, I2, I3, vec("v"), vec("w"), vec("gamma"), vec("alpha"), vec("beta")
    )


SYMBOLS = _make_symbols()
#: ``t = tan(phi / 2)``: the oblique model's constraint angle as a rational parameter
#: (``cos(phi) = (1 - t^2) / (1 + t^2)``, ``sin(phi) = 2 t / (1 + t^2)``;
#: :mod:`rollingtop.contact.oblique`), a symbol of every derivation that model's directions
#: enter.
PHI_T = sp.Symbol("t_phi", real=True)


def _cross(a: Any, b: Any) -> Any:
    return sp.Matrix(a).cross(sp.Matrix(b))


def constraints(model: str, S: Symbols = SYMBOLS) -> list[Any]:
    """The model's constraints ``c_k(u, gamma) = (vp, d_k)``, then those on the angular velocity
    alone, ``(w, d) = 0`` (:attr:`~rollingtop.contact.ContactModel.spin_directions`, rubber
    rolling's ``(w, gamma) = 0``); all linear in ``u``."""
    r = -S.R * S.gamma - sp.Matrix([0, 0, S.a3])
    vp = S.v + _cross(S.w, r)
    m = get_model(model)
    out = [sp.expand(vp.dot(d)) for d in m.symbolic.directions(sp, S.gamma)]
    if m.spin_directions is not None:
        out += [sp.expand(S.w.dot(d)) for d in m.spin_directions(S.gamma).values()]
    return out


@dataclass(frozen=True)
class Derivation:
    """Result of :func:`derive`: the accelerations and the full vector field."""

    model: str
    symmetric: bool
    udot: sp.Matrix  # (6,) accelerations (v', w')
    field: dict[Any, Any]  # symbol -> time derivative, for v, w, alpha, beta, gamma
    constraints: list[Any]
    lagrangian: sp.Expr


@cache
def derive(model: str, symmetric: bool = True) -> Derivation:
    """Derive the constrained equations of ``model`` (a name of
    :data:`rollingtop.contact.MODELS`).

    With ``symmetric`` the body has ``I2 = I1``.
    """
    S = SYMBOLS
    I2 = S.I1 if symmetric else S.I2
    Iw = sp.Matrix([S.I1 * S.w[0], I2 * S.w[1], S.I3 * S.w[2]])
    r = -S.R * S.gamma - sp.Matrix([0, 0, S.a3])
    L = S.m * S.v.dot(S.v) / 2 + S.w.dot(Iw) / 2 + S.m * S.g * r.dot(S.gamma)
    u = list(S.v) + list(S.w)
    dLdv = sp.Matrix([sp.diff(L, x) for x in S.v])
    dLdw = sp.Matrix([sp.diff(L, x) for x in S.w])
    dLdg = sp.Matrix([sp.diff(L, x) for x in S.gamma])
    M = sp.Matrix(6, 6, lambda i, j: sp.diff(L, u[i], u[j]))
    F = sp.Matrix.vstack(
        _cross(dLdv, S.w), _cross(dLdw, S.w) + _cross(dLdv, S.v) + _cross(dLdg, S.gamma)
    )
    gdot = _cross(S.gamma, S.w)
    cons = constraints(model)
    J = sp.Matrix([[sp.diff(c, x) for x in u] for c in cons])
    b = sp.Matrix(
        [
            sum(sp.diff(J[k, :].dot(sp.Matrix(u)), S.gamma[i]) * gdot[i] for i in range(3))
            for k in range(len(cons))
        ]
    )
    Minv = sp.diag(*[1 / M[i, i] for i in range(6)])
    A = J * Minv * J.T
    rhs = -b - J * Minv * F
    lam = A.LUsolve(rhs)
    udot = Minv * (F + J.T * lam)
    field = {}
    for i in range(3):
        field[S.v[i]] = udot[i]
        field[S.w[i]] = udot[3 + i]
    for e in (S.alpha, S.beta, S.gamma):
        ed = _cross(e, S.w)
        for i in range(3):
            field[e[i]] = ed[i]
    return Derivation(model, symmetric, udot, field, cons, L)


def rhs_function(
    model: str, symmetric: bool = True
) -> Callable[[FloatArray, FloatArray], list[float]]:
    """A NumPy function ``f(params, y) -> y'[:15]`` of the derived field (``y`` in the kernel's
    layout ``(v, w, alpha, beta, gamma, ...)``), for comparison with the compiled kernel. The
    oblique model's angle is read from its slot of ``params`` (13 entries; 0 where absent)."""
    S = SYMBOLS
    d = derive(model, symmetric)
    exprs = [d.field[x] for x in S.state]
    f = sp.lambdify([S.params, S.state, PHI_T], exprs, "numpy")
    # the oblique model's angle: its default plus its slot of ``params`` (the offset)
    own = {r.name: r.default for r in get_model(model).parameters}
    angle = own.get("angle", 0.0)

    def rhs(params: FloatArray, y: FloatArray) -> list[float]:
        t = math.tan((angle + (params[12] if len(params) > 12 else 0.0)) / 2)
        values: list[float] = f(tuple(params[:7]), tuple(y[:15]), t)  # the body's own
        return values

    return rhs
