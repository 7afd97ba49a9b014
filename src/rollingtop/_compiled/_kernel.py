"""The model-independent pieces of the compiled dynamics: work arrays, the contact force, and
the small Cholesky solve of the general path.

Everything that depends on a contact model -- the right-hand side, the projection, the
diagnostics -- is compiled per model (:mod:`rollingtop._compiled`, from the template
:mod:`rollingtop._compiled._template.dynamics`, where the equations are written out); these
helpers are shared by every model and cached once.
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._jit import compiled, inline, kernel
from rollingtop._layout import MAX_ROWS
from rollingtop._types import FloatArray, Workspace

__all__ = ["new_workspace", "reaction", "solve_spd", "workspace"]


def workspace() -> Workspace:
    """Work arrays ``(J, bias, dirs, A, lam)`` for one thread of the kernels, made by NumPy:
    for Python callers, which so compile nothing (the arrays' types are those of
    :func:`new_workspace`'s)."""
    return (
        np.zeros((MAX_ROWS, 6)),
        np.zeros(MAX_ROWS),
        np.zeros((MAX_ROWS, 3)),
        np.zeros((MAX_ROWS, MAX_ROWS)),
        np.zeros(MAX_ROWS),
    )


#: :func:`workspace` compiled, for compiled callers (the diagnostics, the chaos batches).
new_workspace = compiled()(workspace)


@inline
def solve_spd(n: int, A: FloatArray, x: FloatArray) -> None:
    """Solve ``A z = x`` in place (``x <- z``) for SPD ``A`` given by its lower triangle."""
    for j in range(n):
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        d = math.sqrt(d)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(n):
        s = x[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= A[k, i] * x[k]
        x[i] = s / A[i, i]


@kernel
def reaction(nc: int, y: FloatArray, ws: Workspace) -> tuple[float, float]:
    """Normal force ``N = (F, gamma)`` and tangential force ``|F - N gamma|`` after the last
    right-hand side (:func:`rollingtop._compiled._template.dynamics.rhs`).

    ``F = sum_k lambda_k d_k`` is the constraint force at the contact point (body frame).
    """
    dirs, lam = ws[2], ws[4]
    F1 = F2 = F3 = 0.0
    for i in range(nc):
        F1 += lam[i] * dirs[i, 0]
        F2 += lam[i] * dirs[i, 1]
        F3 += lam[i] * dirs[i, 2]
    g1, g2, g3 = y[12], y[13], y[14]
    N = F1 * g1 + F2 * g2 + F3 * g3
    t1, t2, t3 = F1 - N * g1, F2 - N * g2, F3 - N * g3
    return N, math.sqrt(t1 * t1 + t2 * t2 + t3 * t3)
