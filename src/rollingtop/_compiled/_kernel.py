"""The model-independent pieces of the compiled dynamics: work arrays, the contact force, the
small Cholesky solve of the general path, the frame's kinematics.

Everything that depends on a contact model -- the right-hand side, the projection, the
diagnostics -- is compiled per model (:mod:`rollingtop._compiled`, from the template
:mod:`rollingtop._compiled._template.dynamics`, where the equations are written out); these
helpers are shared by every model and cached once (a model's compile pays only for what is its
own: the frame's rates, written in the template before, cost each compiled package about
0.15 s of typing and lowering).
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._jit import compiled, inline, kernel
from rollingtop._layout import MAX_ROWS
from rollingtop._types import FloatArray, Workspace

__all__ = [
    "frame_rates",
    "new_workspace",
    "reaction",
    "solve_spd",
    "workspace",
]


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


@inline
def frame_rates(y: FloatArray, dy: FloatArray) -> None:
    """The kinematics of every model (eq. 2.1) into ``dy``: ``alpha' = alpha x w``,
    ``beta' = beta x w``, ``gamma' = gamma x w`` (slots 6..14), ``X' = (v, alpha)``,
    ``Y' = (v, beta)`` (15, 16); slot 17 is the model's (shape ``(18,)`` each)."""
    w1, w2, w3 = y[3], y[4], y[5]
    for base in (6, 9, 12):
        e1, e2, e3 = y[base], y[base + 1], y[base + 2]
        dy[base] = e2 * w3 - e3 * w2
        dy[base + 1] = e3 * w1 - e1 * w3
        dy[base + 2] = e1 * w2 - e2 * w1
    dy[15] = y[0] * y[6] + y[1] * y[7] + y[2] * y[8]
    dy[16] = y[0] * y[9] + y[1] * y[10] + y[2] * y[11]
