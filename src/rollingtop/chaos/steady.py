"""Relative equilibria on a level of a model without a reduction (issue 38, item 1).

A *relative equilibrium* (steady motion) keeps the inclination ``gamma3`` constant: every
reduced coordinate ``z = (gamma3, w_tau, w_n, w3, u)`` (:mod:`rollingtop.chaos._section_map`) is
constant along it, and ``w_tau = 0`` (``gamma3' = s w_tau``, paper eq. 3.3). It never crosses the
Poincare section, so the periodic orbits' search does not see it. It is a zero of the reduced
vector field ``F(z) = dz/dt`` with ``w_tau = 0``: ``F`` is the compiled right-hand side
(:func:`rollingtop._compiled._template.dynamics.rhs`) carried to the reduced coordinates by a
central difference of the smooth map ``y -> z`` along it. On a level (the energy and the model's
other integrals held) they are isolated points, found by Gauss-Newton on ``F(z) = 0, I(z) = I_0``
from the grid points of the section plane where ``|F|`` is least among their neighbours.

Their **eigenvalues** are those of ``DF`` (central differences, 5 x 5) but its zeros: since
``dI DF = 0`` for each integral ``I``, an eigenvector of a nonzero eigenvalue keeps every integral
(``dI v = 0``): these are the linearised motion on the level. The zeros belong to the directions
across the level and along the family of relative equilibria (at a relative equilibrium the
energy's gradient is parallel to the other integral's, its level being critical there, so the
tangent space of the level is not the kernel of both gradients); their largest modulus is
reported (``trivial``), 0 in exact arithmetic. The models with a reduction have theirs
in closed form (:func:`rollingtop.reduction.steady_motions`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import RollingTopError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.chaos._section_map import (
    SectionMap,
    on_level,
    reduced_coordinates,
    reduced_state,
)
from rollingtop.dynamics.integrals import evaluate

__all__ = ["RelativeEquilibrium", "relative_equilibria"]

#: Newton has converged when ``|F|`` and the integrals' mismatch (max norm) are below this.
STEADY_TOL = 1e-11
#: Newton's iterations at most.
STEADY_ITERATIONS = 20
#: Relative step of the central differences of ``F``'s Jacobian (``F`` is itself a difference,
#: good to ~1e-9: a larger step keeps its round-off out of the Jacobian).
JACOBIAN_STEP = 1e-4
#: Two relative equilibria closer than this (max norm of z) are one.
SAME_STEADY = 1e-7
#: Eigenvalues of ``DF`` below this fraction of the largest modulus are its trivial zeros.
ZERO_TOL = 1e-5
#: An eigenvalue with a real part below this (relative to the largest modulus) counts as
#: imaginary (a centre).
REAL_PART_TOL = 1e-6


@dataclass(frozen=True)
class RelativeEquilibrium:
    """A steady motion on a level: ``gamma3`` constant.

    Attributes
    ----------
    z : ndarray, shape (5,)
        Its reduced coordinates ``(gamma3, w_tau = 0, w_n, w3, u)``.
    state : ndarray, shape (18,)
        A state of it.
    eigenvalues : ndarray of complex, shape (d,)
        The linearised motion's on the level, ``DF``'s nonzero ones (module docstring), by
        decreasing real part.
    type : str
        ``stable`` (every real part negative), ``unstable`` (one positive), ``centre`` (all
        imaginary) or ``degenerate``.
    residual : float
        ``max |F(z)|`` there.
    trivial : float
        The largest modulus among ``DF``'s zero eigenvalues left out (module docstring).
    """

    z: FloatArray
    state: FloatArray
    eigenvalues: NDArray[np.complex128]
    type: str
    residual: float
    trivial: float = 0.0

    def to_dict(self, key: str) -> dict[str, Any]:
        """JSON-ready; ``key`` is the model's free velocity component."""
        g3, _, w_n, w3, u = (float(v) for v in self.z)
        return {
            "gamma3": g3,
            "w_n": w_n,
            "w3": w3,
            key: u,
            "eigenvalues": [[float(e.real), float(e.imag)] for e in self.eigenvalues],
            "type": self.type,
            "residual": self.residual,
            "trivial_eigenvalues_off_zero": self.trivial,
        }


class _Field:
    """The reduced vector field ``F(z)`` of a model and body."""

    def __init__(self, P: SectionMap) -> None:
        self.P = P
        self.ws = workspace()

    def __call__(self, z: FloatArray) -> FloatArray:
        body, model = self.P.body, self.P.model
        y = reduced_state(body, model, z)
        code = model.kernel_code(body, y)
        dy = np.zeros(N_STATE)
        call(for_code(code).dynamics.rhs, code, model.params(body), y, dy, self.ws)
        e = 1e-7 * max(1.0, float(np.max(np.abs(y[:15])))) / max(float(np.max(np.abs(dy))), 1e-300)
        ahead = reduced_coordinates(model, y + e * dy)
        behind = reduced_coordinates(model, y - e * dy)
        out: FloatArray = (ahead - behind) / (2 * e)
        return out

    def integrals(self, z: FloatArray) -> FloatArray:
        """The held integrals at ``z`` (shape (len(names),))."""
        P = self.P
        y = reduced_state(P.body, P.model, z)
        values = evaluate(P.body, y[None], P.names, model=P.model)
        return np.array([float(values[k][0]) for k in P.names])


def _jacobian(f: Any, z: FloatArray, cols: list[int]) -> FloatArray:
    h = JACOBIAN_STEP * np.maximum(1.0, np.abs(z))
    columns = []
    for k in cols:
        e = np.zeros_like(z)
        e[k] = h[k]
        columns.append((f(z + e) - f(z - e)) / (2 * h[k]))
    return np.array(columns).T


def _classify(ev: NDArray[np.complex128]) -> str:
    scale = max(float(np.max(np.abs(ev))), 1e-300)
    re = ev.real / scale
    if np.any(re > REAL_PART_TOL):
        return "unstable"
    if np.all(re < -REAL_PART_TOL):
        return "stable"
    if np.all(np.abs(re) <= REAL_PART_TOL) and np.all(np.abs(ev) > REAL_PART_TOL * scale):
        return "centre"
    return "degenerate"


def relative_equilibria(
    P: SectionMap, target: FloatArray, g3s: FloatArray, wns: FloatArray
) -> list[RelativeEquilibrium]:
    """The relative equilibria on the level ``target`` of ``P``'s integrals (a level of the
    energy and one integral linear in the velocities), seeded from the grid ``g3s`` x ``wns``
    of the section plane (each point on each sheet of the level)."""
    if len(P.names) != 2 or "energy" not in P.names:
        return []
    F = _Field(P)
    cells = []
    for i, g3 in enumerate(g3s):
        for j, w_n in enumerate(wns):
            for sheet, x in enumerate(on_level(P, target, float(g3), float(w_n))):
                z = np.array([x[0], 0.0, x[1], x[2], x[3]])
                try:
                    size = float(np.max(np.abs(F(z)[1:])))
                except RollingTopError:
                    continue
                cells.append(((i, j, sheet), z, size))
    by_cell = {c[0]: c[2] for c in cells}
    found: list[RelativeEquilibrium] = []
    for (i, j, sheet), z0, size in cells:
        around = [
            by_cell.get((i + a, j + b, sheet), np.inf)
            for a in (-1, 0, 1)
            for b in (-1, 0, 1)
            if a or b
        ]
        if not size <= min(around):
            continue
        solved = _newton(F, z0, target)
        if solved is None or any(np.max(np.abs(e.z - solved)) < SAME_STEADY for e in found):
            continue
        found.append(_equilibrium(F, solved))
    found.sort(key=lambda e: float(e.z[0]))
    return found


def _newton(F: _Field, z0: FloatArray, target: FloatArray) -> FloatArray | None:
    free = [0, 2, 3, 4]  # w_tau stays 0

    def residual(z: FloatArray) -> FloatArray:
        return np.concatenate([F(z)[1:], F.integrals(z) - target])

    z = z0.copy()
    for _ in range(STEADY_ITERATIONS):
        try:
            res = residual(z)
            if np.max(np.abs(res)) < STEADY_TOL:
                return z
            J = _jacobian(residual, z, free)
        except RollingTopError:
            return None
        if not (np.all(np.isfinite(res)) and np.all(np.isfinite(J))):
            return None
        z[free] += np.linalg.lstsq(J, -res, rcond=1e-12)[0]
        if not abs(z[0]) < 1.0:
            return None
    return None


def _equilibrium(F: _Field, z: FloatArray) -> RelativeEquilibrium:
    A = _jacobian(F, z, list(range(5)))
    every = np.linalg.eigvals(A).astype(np.complex128)
    scale = max(float(np.max(np.abs(every))), 1e-300)
    zero = np.abs(every) <= ZERO_TOL * scale
    ev = every[~zero]
    ev = ev[np.lexsort((ev.imag, -ev.real))]
    return RelativeEquilibrium(
        z=z.copy(),
        state=reduced_state(F.P.body, F.P.model, z),
        eigenvalues=ev,
        type=_classify(ev),
        residual=float(np.max(np.abs(F(z)))),
        trivial=float(np.max(np.abs(every[zero]))) if zero.any() else 0.0,
    )


#: A steady motion of a reduced model lies on the level when its ``U`` is the level's ``h`` to
#: this (relative to ``max(1, |h|)``).
ON_LEVEL_RTOL = 1e-9
#: The reduction's names of the steady motions' types.
_TYPES = {"center": "centre", "saddle": "unstable", "degenerate": "degenerate"}


def reduced_relative_equilibria(
    P: SectionMap, state: FloatArray
) -> list[RelativeEquilibrium] | None:
    """The relative equilibria on the level of ``state`` of a model with a reduction, from its
    closed-form steady motions (:func:`rollingtop.reduction.steady_motions`: those whose ``U``
    is the level's ``h``), with the eigenvalues of the full equations linearised there;
    ``None`` for a model without one."""
    from rollingtop.reduction.models import REDUCTIONS, reduction_of
    from rollingtop.reduction.steady import steady_motions

    body, model = P.body, P.model
    if model.name not in REDUCTIONS or not body.symmetric:
        return None
    reduction = reduction_of(model.name)
    level = reduction.level_of_state(body, state)
    h = float(reduction.reduced_energy(body, state))
    out = []
    for m in steady_motions(level):
        if abs(m.U - h) > ON_LEVEL_RTOL * max(1.0, abs(h)) or not abs(m.gamma3) < 1.0:
            continue
        z = np.array([m.gamma3, 0.0, m.w_n, m.spin, m.v_tau])
        every = np.array([complex(re, im) for re, im in m.eigenvalues], dtype=np.complex128)
        scale = max(float(np.max(np.abs(every))), 1e-300) if every.size else 1.0
        ev = every[np.abs(every) > ZERO_TOL * scale]  # the integrals' zeros, as above
        out.append(
            RelativeEquilibrium(
                z=z,
                state=reduced_state(body, model, z),
                eigenvalues=ev,
                type=_TYPES.get(m.type, m.type),
                residual=0.0,
            )
        )
    return out
