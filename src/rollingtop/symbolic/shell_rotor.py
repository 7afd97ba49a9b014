"""The ``shell-rotor`` pair (:mod:`rollingtop.contact.shell_rotor`): its equations derived
with sympy from the Lagrangian, and the claims :func:`rollingtop.symbolic.verify` checks for
it.

**Derivation** (:func:`derive_pair`), independent of the compiled kernel's formulation (which
solves the constraints for ``v`` and projects onto the independent velocities ``(w, delta)``):
the pair's Lagrangian, with ``v_O = v - w x (a3 e3)`` the shell centre's velocity and
``Omega = w + delta e3`` the shell's angular velocity (body frame = the rotor's),

    L = m v^2/2 + (w, I w)/2 + ms |v_O|^2/2 + Js |Omega|^2/2 - m g (R + a3 gamma3)

(the shell's centre stays at height ``R``: its weight does no work), the quasi-velocities
``u = (v, w, delta)``, the shell's three no-slip conditions (body frame)

    c = v - a3 w x e3 - R Omega x gamma = 0,

and Poincare's equations with the reaction ``lambda`` of ``c`` (``delta`` is the rate of an
angle that ``L`` does not contain)

    d/dt dL/dv     = dL/dv x w                                  + J_v^T lambda
    d/dt dL/dw     = dL/dw x w + dL/dv x v + dL/dgamma x gamma  + J_w^T lambda
    d/dt dL/ddelta =                                              J_delta^T lambda,
    gamma' = gamma x w,

i.e. ``M u' = F + J^T lambda`` with the constant, non-diagonal kinetic Hessian ``M`` and
``J = dc/du``. The multipliers are eliminated as in :func:`.equations.derive`, with the full
inverse of ``M``: ``lambda = (J M^-1 J^T)^-1 (-b - J M^-1 F)``, ``b = (dc/dgamma) gamma'``.

**Manifold.** :func:`rollingtop.symbolic.claims.check` derives the *body's* equations
(``derive('shell-rotor')`` is the rotor alone under the meridian rows, not the pair) and
parametrises the model's manifold by its ``Symbolic.velocity`` (the meridian one, free
``v_tau``; the pair's ``delta`` is not in it). The pair's claims are therefore built here,
already on the pair's manifold (:func:`on_manifold`: ``gamma`` rational in the ``q, k`` of
:mod:`.claims`, ``v`` from ``(w, delta)`` by ``c = 0``, ``delta`` free), as ``"identity"``
claims: ``check`` finds nothing left to substitute and decides them as they are.

**Claims** (:func:`claims`), for a symmetric rotor unless said otherwise:

- the pair's energy ``(u, dL/du) - L`` is conserved (also for ``I1 != I2``);
- the rotor's axial spin ``w3`` is conserved (Lagrange's ``I3 w3``);
- the limit ``ms = Js = 0`` is the meridian model (the paper's "it is easy to show"). There
  ``M`` is singular (``delta`` carries no kinetic energy of its own): :func:`derive_pair`'s
  accelerations contain ``1/Js`` and cannot be evaluated at the limit, but the pair's
  *equations* can. The meridian model's ``(v', w')`` (:func:`.equations.derive`), with
  ``lambda`` from the ``v`` rows (``J_v = 1``) and ``delta'`` the rate of the rotor's slip
  ``(vp, e3 x gamma) / (R s^2)`` (:func:`meridian_limit`), satisfy the other Poincare rows and
  the differentiated constraints at ``ms = Js = 0`` (claims with those ``params``), and the
  pair's linear system for ``(u', lambda)`` is regular: its determinant is
  ``I3 rho_pair(gamma3) N(gamma3)`` (:func:`rho_pair`, :func:`spin_weight`), at the limit
  ``I1 I3 m R^2 s^2 rho(gamma3)``, so that solution is the only one;
- a Jellett integral of the pair (:func:`jellett_pair`): ``(K_G, r_G)``, the angular momentum
  about the pair's centre of mass ``G`` against the contact point seen from ``G``
  (``K_G = I w + Js Omega + mu a3^2 (w1, w2, 0)``, ``mu = m ms/(m + ms)``,
  ``r_G = -R gamma - m a3/(m + ms) e3``). The rotor's own form ``(I w + Js Omega, r)`` is
  conserved only at ``ms = 0`` (or ``a3 = 0``);
- the pair's ``F6`` (:func:`f6_pair`): ``Omega3`` obeys, with ``w3`` constant,
  ``N Omega3' = -(N'/2 Omega3 + R I3 ((m + ms) R gamma3 + m a3) w3) gamma3'`` with

      N(gamma3) = Js rho_pair(gamma3) + R^2 s^2 ((m + ms) I1 + m ms a3^2)
                = alpha + beta gamma3 - kappa gamma3^2,

  so ``Omega3 sqrt(N) + R I3 w3 Phi(gamma3)`` is conserved, ``Phi' = ((m + ms) R gamma3 +
  m a3) / sqrt(N)``: ``Phi = -(p/kappa) sqrt(N) - (m a3 + p beta/(2 kappa)) / sqrt(kappa)
  arccos((2 kappa gamma3 - beta) / sqrt(beta^2 + 4 alpha kappa))``, ``p = (m + ms) R``. At
  ``ms = Js = 0`` it is ``sqrt(m/I1)`` times the paper's ``F6`` (``R s Omega3 = v_tau -
  (R gamma3 + a3) w_n`` there). The claim is its rate times ``sqrt(N)`` (rational), given
  ``w3' = 0``.

With ``E``, ``w3``, ``(K_G, r_G)`` and this ``F6`` the pair has as many integrals as the
meridian model.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import sympy as sp

from rollingtop.symbolic.claims import Claim, k, q
from rollingtop.symbolic.equations import SYMBOLS, derive

__all__ = [
    "DELTA",
    "JS",
    "MS",
    "PairDerivation",
    "claims",
    "derive_pair",
    "f6_pair",
    "f6_pair_rate",
    "jellett_pair",
    "linear_system",
    "meridian_limit",
    "on_manifold",
    "pair_constraints",
    "rate",
    "rho_pair",
    "spin_weight",
]

S = SYMBOLS
MODEL = "shell-rotor"
#: The shell's mass and moment of inertia about a diameter (``p[7]``, ``p[8]``).
MS, JS = sp.symbols("ms Js", positive=True)
#: The shell's spin relative to the rotor, ``delta = Omega3 - w3`` (the state's ``y[17]``).
DELTA = sp.Symbol("delta", real=True)
E3 = sp.Matrix([0, 0, 1])


@dataclass(frozen=True)
class PairDerivation:
    """Result of :func:`derive_pair`.

    ``udot``: ``(v', w', delta')`` (7 rows) as functions of ``(v, w, gamma, delta)`` and the
    parameters; ``field``: symbol -> time derivative for ``v, w, delta, gamma``; the pieces of
    ``M u' = F + J^T lambda``, ``J u' + b = 0``: ``mass`` (7x7), ``forces`` (7), ``jacobian``
    (3x7) and ``bias`` (3); ``constraints``: ``c`` (3); ``energy``: ``(u, dL/du) - L``.
    """

    symmetric: bool
    udot: sp.Matrix
    field: dict[Any, Any]
    lagrangian: sp.Expr
    energy: sp.Expr
    constraints: sp.Matrix
    mass: sp.Matrix
    forces: sp.Matrix
    jacobian: sp.Matrix
    bias: sp.Matrix

    @property
    def velocities(self) -> list[Any]:
        """The quasi-velocities ``u = (v, w, delta)``."""
        return [*S.v, *S.w, DELTA]


def _lagrangian(symmetric: bool) -> Any:
    I2 = S.I1 if symmetric else S.I2
    Iw = sp.Matrix([S.I1 * S.w[0], I2 * S.w[1], S.I3 * S.w[2]])
    v_O = S.v - S.w.cross(S.a3 * E3)
    Omega = S.w + DELTA * E3
    kinetic = (S.m * S.v.dot(S.v) + S.w.dot(Iw) + MS * v_O.dot(v_O) + JS * Omega.dot(Omega)) / 2
    return kinetic - S.m * S.g * (S.R + S.a3 * S.gamma[2])


def pair_constraints() -> sp.Matrix:
    """The shell's no-slip conditions ``c = v - a3 w x e3 - R (w + delta e3) x gamma``."""
    return S.v - S.a3 * S.w.cross(E3) - S.R * (S.w + DELTA * E3).cross(S.gamma)


@cache
def derive_pair(symmetric: bool = True) -> PairDerivation:
    """Derive the pair's equations (module docstring); with ``symmetric`` the rotor has
    ``I2 = I1``."""
    L = _lagrangian(symmetric)
    u = [*S.v, *S.w, DELTA]

    def grad(xs: Any) -> Any:
        return sp.Matrix([sp.diff(L, x) for x in xs])

    dLdv, dLdw, dLdg = grad(S.v), grad(S.w), grad(S.gamma)
    M = sp.Matrix(7, 7, lambda i, j: sp.diff(L, u[i], u[j]))
    F = sp.Matrix.vstack(
        dLdv.cross(S.w),
        dLdw.cross(S.w) + dLdv.cross(S.v) + dLdg.cross(S.gamma),
        sp.Matrix([0]),
    )
    c = pair_constraints()
    J = c.jacobian(u)
    gdot = S.gamma.cross(S.w)
    b = (J * sp.Matrix(u)).jacobian(S.gamma) * gdot
    Minv = M.inv()
    lam = (J * Minv * J.T).LUsolve(-b - J * Minv * F)
    udot = Minv * (F + J.T * lam)
    field = {x: udot[i] for i, x in enumerate(u)}
    field |= {S.gamma[i]: gdot[i] for i in range(3)}
    energy = sum(x * sp.diff(L, x) for x in u) - L
    return PairDerivation(symmetric, udot, field, L, sp.expand(energy), c, M, F, J, b)


def on_manifold(expr: Any) -> Any:
    """``expr`` (of ``v, w, gamma, delta``) on the pair's manifold: ``gamma`` rational in the
    parameters ``q, k`` of :mod:`.claims` (``s = 2 q/(1 + q^2)``), ``v`` from ``(w, delta)``
    by ``c = 0``."""
    sq = 2 * q / (1 + q**2)
    gamma = sp.Matrix(
        [sq * (1 - k**2) / (1 + k**2), sq * 2 * k / (1 + k**2), (1 - q**2) / (1 + q**2)]
    )
    v = S.a3 * S.w.cross(E3) + S.R * (S.w + DELTA * E3).cross(gamma)
    subs = {S.gamma[i]: gamma[i] for i in range(3)} | {S.v[i]: v[i] for i in range(3)}
    return sp.sympify(expr).xreplace(subs)


def rate(expr: Any, field: dict[Any, Any]) -> Any:
    """``d expr/dt`` along ``field`` (symbol -> time derivative)."""
    return sum(sp.diff(expr, x) * dx for x, dx in field.items() if expr.has(x))


def _slip_delta() -> Any:
    """``delta`` of a rotor state: its contact point's slip across the axis projection,
    ``(vp, e3 x gamma) / (R s^2)`` (:func:`rollingtop.contact.shell_rotor.relative_spin`)."""
    r = -S.R * S.gamma - S.a3 * E3
    vp = S.v + S.w.cross(r)
    return vp.dot(E3.cross(S.gamma)) / (S.R * (S.gamma[0] ** 2 + S.gamma[1] ** 2))


def meridian_limit(symmetric: bool = True) -> sp.Matrix:
    """The meridian model's ``(v', w')`` (:func:`.equations.derive`) with
    ``delta' = d/dt (vp, e3 x gamma) / (R s^2)`` along its field: the candidate for the pair's
    ``u'`` at ``ms = Js = 0`` (7 rows)."""
    field = derive("meridian", symmetric).field
    delta_dot = rate(_slip_delta(), {x: field[x] for x in (*S.v, *S.w, *S.gamma)})
    return sp.Matrix([*(field[x] for x in (*S.v, *S.w)), delta_dot])


def _limit_residuals(symmetric: bool) -> tuple[sp.Matrix, sp.Matrix]:
    """The pair's Poincare rows for ``w`` and ``delta`` and its differentiated constraints at
    :func:`meridian_limit`'s ``u'``, the multipliers taken from the ``v`` rows
    (``J_v = 1``: ``lambda = (M u' - F)_v``); zero at ``ms = Js = 0`` if the meridian model is the
    pair's limit."""
    d = derive_pair(symmetric)
    udot = meridian_limit(symmetric)
    unbalanced = d.mass * udot - d.forces
    lam = unbalanced[0:3, 0]
    poincare = (unbalanced - d.jacobian.T * lam)[3:7, 0]
    return poincare, d.jacobian * udot + d.bias


def _squares(rows: Any) -> Any:
    """``sum(row^2)``: zero at a real point iff every row is."""
    return sum(x**2 for x in rows)


def linear_system(symmetric: bool = True) -> sp.Matrix:
    """The pair's linear system for ``(u', lambda)``, ``[[M, -J^T], [J, 0]]`` (10x10)."""
    d = derive_pair(symmetric)
    return sp.Matrix.vstack(
        sp.Matrix.hstack(d.mass, -d.jacobian.T), sp.Matrix.hstack(d.jacobian, sp.zeros(3, 3))
    )


def rho_pair(gamma3: Any = S.gamma[2]) -> Any:
    """``I1 + Js + ms R^2 + m |r|^2``: the pair's ``rho(gamma3)`` (the paper's at
    ``ms = Js = 0``)."""
    R, m, a3 = S.R, S.m, S.a3
    return S.I1 + JS + MS * R**2 + m * (R**2 + 2 * R * a3 * gamma3 + a3**2)


def spin_weight(gamma3: Any = S.gamma[2]) -> Any:
    """``N(gamma3) = Js (I1 + Js + ms R^2 + m |r|^2) + R^2 s^2 ((m + ms) I1 + m ms a3^2)``
    (module docstring; ``R^2 s^2 m I1`` at ``ms = Js = 0``)."""
    K = (S.m + MS) * S.I1 + S.m * MS * S.a3**2
    return JS * rho_pair(gamma3) + S.R**2 * (1 - gamma3**2) * K


def jellett_pair() -> Any:
    """``(K_G, r_G)``: the pair's angular momentum about its centre of mass ``G`` against the
    contact point seen from ``G`` (``(I w, r)``, the paper's ``F4``, at ``ms = 0``)."""
    I = sp.diag(S.I1, S.I1, S.I3)
    O = -S.a3 * E3  # the shell's centre, from the rotor's centre of mass C
    G = MS * O / (S.m + MS)
    v_O = S.v - S.w.cross(S.a3 * E3)
    K_G = I * S.w + JS * (S.w + DELTA * E3) + S.m * (-G).cross(S.v) + MS * (O - G).cross(v_O)
    r_G = -S.R * S.gamma - S.a3 * E3 - G
    return K_G.dot(r_G)


def f6_pair() -> Any:
    """The pair's ``F6``, ``Omega3 sqrt(N) + R I3 w3 Phi(gamma3)`` (module docstring; with
    ``arccos``: for numerical use, the claim is :func:`f6_pair_rate`)."""
    g3 = S.gamma[2]
    N = sp.expand(spin_weight())
    alpha, beta, kappa = N.coeff(g3, 0), N.coeff(g3, 1), -N.coeff(g3, 2)
    p = (S.m + MS) * S.R
    arc = sp.acos((2 * kappa * g3 - beta) / sp.sqrt(beta**2 + 4 * alpha * kappa))
    Phi = -p / kappa * sp.sqrt(N) - (S.m * S.a3 + p * beta / (2 * kappa)) / sp.sqrt(kappa) * arc
    return (S.w[2] + DELTA) * sp.sqrt(N) + S.R * S.I3 * S.w[2] * Phi


def f6_pair_rate(d: PairDerivation) -> Any:
    """``sqrt(N) d/dt (Omega3 sqrt(N)) + R I3 w3 ((m + ms) R gamma3 + m a3) gamma3'`` along
    ``d``'s field: zero if ``Omega3 sqrt(N) + R I3 w3 Phi(gamma3)`` (module docstring) is
    conserved while ``w3`` is."""
    g3 = S.gamma[2]
    N = spin_weight()
    spin = S.w[2] + DELTA  # Omega3
    g3dot = d.field[g3]
    arm = (S.m + MS) * S.R * g3 + S.m * S.a3
    return (
        N * rate(spin, d.field)
        + sp.diff(N, g3) * spin * g3dot / 2
        + S.R * S.I3 * S.w[2] * arm * g3dot
    )


def claims() -> list[Claim]:
    """The pair's claims (module docstring), built on its manifold (:func:`on_manifold`) as
    ``"identity"`` claims for :func:`rollingtop.symbolic.claims.check`."""
    d, general = derive_pair(True), derive_pair(False)
    poincare, differentiated = _limit_residuals(True)
    limit = ((MS, 0), (JS, 0))
    system = linear_system(True).det(method="berkowitz")  # division-free
    return [
        Claim(
            "pair energy conserved (rotor + shell: ms v_O^2/2 + Js |Omega|^2/2 included)",
            MODEL,
            on_manifold(rate(d.energy, d.field)),
            "identity",
        ),
        Claim(
            "pair energy conserved, general rotor (I1 != I2)",
            MODEL,
            on_manifold(rate(general.energy, general.field)),
            "identity",
            symmetric=False,
        ),
        Claim(
            "rotor's axial spin w3 conserved (Lagrange's I3 w3)",
            MODEL,
            on_manifold(d.field[S.w[2]]),
            "identity",
        ),
        Claim(
            "ms = Js = 0: meridian (v', w') solve the pair's Poincare rows for w, delta",
            MODEL,
            on_manifold(_squares(poincare)),
            "identity",
            params=limit,
        ),
        Claim(
            "ms = Js = 0: meridian (v', w') keep the pair's no-slip conditions",
            MODEL,
            on_manifold(_squares(differentiated)),
            "identity",
            params=limit,
        ),
        Claim(
            "pair's system for (u', lambda) regular: det = I3 rho_pair N "
            "(I1 I3 m R^2 s^2 rho at ms = Js = 0)",
            MODEL,
            on_manifold(system - S.I3 * rho_pair() * spin_weight()),
            "identity",
        ),
        Claim(
            "pair Jellett integral (K_G, r_G) conserved (G: the pair's centre of mass)",
            MODEL,
            on_manifold(rate(jellett_pair(), d.field)),
            "identity",
        ),
        Claim(
            "pair F6 integral Omega3 sqrt(N) + R I3 w3 Phi(gamma3) conserved",
            MODEL,
            on_manifold(f6_pair_rate(d)),
            "identity",
        ),
    ]
