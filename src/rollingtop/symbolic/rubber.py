"""The rubber model's reduction, proved (:mod:`rollingtop.reduction.rubber`).

Rolling without slipping or spinning keeps the angular velocity horizontal,
``w = w_tau tau + Omega nu`` with ``nu = (e3 - gamma3 gamma) / s``. The claims:

1. **the linear ODE**: along the full equations, ``Omega' = A(gamma3) gamma3' Omega`` with
   ``A = gamma3 / s^2 - J' / (2 J)``, ``J = (I nu, nu) + m (r, gamma)^2``: so
   ``d Omega / d gamma3 = A Omega``, and an integral ``f(gamma3) Omega`` needs ``f' = -A f``;
2. **its solution** ``f = s sqrt(J)``: ``d log f / d gamma3 + A = 0`` (exact);
3. **the level's energy**: ``J Omega^2 = w3^2 J / s^2``, the kinetic energy's part besides
   ``rho w_tau^2 / 2`` (``T - rho w_tau^2/2 - J Omega^2/2 = 0`` on the manifold).

The integral itself, ``rubber_spin = w3 sqrt(I3 J) = sqrt(I3) f Omega`` (``w3 = s Omega``), is
proved conserved through its square with the model's other integrals
(:func:`rollingtop.symbolic.claims.claims_for`).
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from rollingtop.symbolic.claims import Claim, s_sym
from rollingtop.symbolic.equations import SYMBOLS as S

__all__ = ["claims", "ode_coefficient"]


def _J(g3: Any) -> Any:
    """``J = I1 gamma3^2 + I3 s^2 + m (R + a3 gamma3)^2`` (symmetric body)."""
    return S.I1 * g3**2 + S.I3 * (1 - g3**2) + S.m * (S.R + S.a3 * g3) ** 2


def ode_coefficient(g3: Any) -> Any:
    """``A(gamma3) = gamma3 / (1 - gamma3^2) - J'(gamma3) / (2 J)`` of ``dOmega/dgamma3 = A
    Omega``."""
    J = _J(g3)
    return g3 / (1 - g3**2) - sp.diff(J, g3) / (2 * J)


def claims() -> list[Claim]:
    """The claims :func:`rollingtop.symbolic.verify` checks for ``rubber`` beyond its
    integrals (module docstring)."""
    g1, g2, g3 = S.gamma
    w = S.w
    omega = (w[2] - g3 * w.dot(S.gamma)) / s_sym  # (w, nu)
    g3_dot = g1 * w[1] - g2 * w[0]  # (gamma x w)_3
    A = ode_coefficient(g3).xreplace({1 - g3**2: s_sym**2})
    out = [
        Claim(
            "linear ODE: Omega' = A(gamma3) gamma3' Omega follows from the full equations",
            "rubber",
            (omega, A * g3_dot * omega),
            "reduced",
        ),
    ]
    x = sp.Symbol("x", real=True)
    f = sp.sqrt(1 - x**2) * sp.sqrt(_J(x))
    residual = sp.cancel(sp.together(sp.diff(f, x) / f + ode_coefficient(x)))
    out.append(Claim("its solution f = s sqrt(J): f' = -A f", "rubber", residual, "identity"))
    I = sp.diag(S.I1, S.I1, S.I3)
    r = -S.R * S.gamma - sp.Matrix([0, 0, S.a3])
    v = r.cross(w)
    T = (w.dot(I * w) + S.m * v.dot(v)) / 2
    w_tau = (-g2 * w[0] + g1 * w[1]) / s_sym
    rho = S.I1 + S.m * (S.a3**2 + S.R**2 + 2 * S.a3 * S.R * g3)
    split = T - rho * w_tau**2 / 2 - _J(g3) * omega**2 / 2
    out.append(
        Claim(
            "kinetic energy = rho w_tau^2/2 + J Omega^2/2 (the potential U)",
            "rubber",
            split,
            "identity",
        )
    )
    return out
