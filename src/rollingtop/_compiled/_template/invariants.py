"""Projection of a state onto the level set of the model's first integrals, after an accepted
step (``project_integrals`` of :func:`rollingtop.simulate`; issue 26).

**What moves.** Only the velocity ``u = (v, w)``: the attitude, the position and the carried
direction stay as the step left them (the constraint projection has already made the frame
orthonormal). Every claimed integral is of degree at most two in ``u`` at a fixed attitude
(:mod:`rollingtop._compiled._integrals`), so the correction is a small linear problem plus,
for the energy, a quadratic equation, solved to round-off in one pass.

**The metric** is the body's kinetic energy, ``|du|^2_M = m |dv|^2 + (I dw, dw)``: the
correction is the velocity change of least kinetic energy, the impulse-like change that
respects the body's mass and inertia, and the result does not depend on the units of length or
time (a Euclidean metric on ``(v, w)`` would weigh metres against radians). It is the metric of
the constraint projection too (:func:`.dynamics.project`).

**The construction.** The rows of the velocity constraints ``J u = 0`` and the gradients of the
linear integrals are made orthonormal in the dual metric ``M^-1`` (modified Gram-Schmidt); a row
that lies in the span of the earlier ones to round-off (dependent integrals, as the area and
Lagrange's integrals on the vertical) is dropped. The minimum-norm ``du`` that zeroes the
constraint residuals and the linear integrals' deviations from their initial values is then
``M^-1 sum_k beta_k q_k``. The energy (and ``slip_nu``) is corrected along the direction of its
gradient orthogonal to those rows, so the linear integrals and the constraints are not touched:
along ``d = M^-1 g_perp`` the energy is ``E + q (l + l^2 / 2)`` with ``q = (g_perp, M^-1
g_perp)``, and ``l`` solves that quadratic exactly. Where no such direction exists -- at a
turning point of ``gamma3`` of an integrable model, where the other integrals fix every velocity
component but ``w_tau = 0`` -- the energy is left for the next steps (counted in
``counts[PROJ_DEFERRED]`` of the stepper); its error there is one step's.

``F6`` carries ``-M3 a3 theta``, with the signed ``theta`` of the carried direction: its value
jumps by ``2 pi M3 a3`` where ``atan2`` wraps (a passage of the north pole in a pole case), so
its deviation is taken modulo that.
"""

from __future__ import annotations

import math

from rollingtop._compiled._integrals import ENERGY, F6, LINEAR, integral_value, velocity_gradient
from rollingtop._compiled._template._dispatch import rows as constraint_rows
from rollingtop._jit import kernel
from rollingtop._types import FloatArray, IntArray, Workspace

__all__ = ["project_integrals"]

#: A row whose part orthogonal to the earlier rows is below this fraction of its size (in the
#: dual metric) is dependent on them: dropped.
DEPENDENT = 1e-9
#: A correction of the velocity beyond this fraction of its size is not a round-off correction:
#: the energy is then left for the next steps (near a turning point).
MAX_CHANGE = 1e-6
#: Newton iterations of the nonlinear integrals (the energy is solved exactly in the first).
NEWTON_ITERATIONS = 4
#: Rows of the work array ``pw`` (:func:`project_integrals`): orthonormal rows, their
#: right-hand sides, a gradient and the correction.
WORK_ROWS = 16


@kernel
def _orthogonalise(pw: FloatArray, n_rows: int, row: int, minv: FloatArray) -> float:
    """Make ``pw[row, 0:6]`` orthogonal (dual metric ``diag(minv)``) to the orthonormal rows
    ``pw[0:n_rows, 0:6]``, updating its right-hand side ``pw[row, 6]`` alike; returns the squared
    size of what is left relative to the row's own (1 for a row orthogonal to the others)."""
    size0 = 0.0
    for k in range(6):
        size0 += pw[row, k] * pw[row, k] * minv[k]
    if not size0 > 0.0:
        return 0.0
    for j in range(n_rows):
        a = 0.0
        for k in range(6):
            a += pw[row, k] * pw[j, k] * minv[k]
        for k in range(7):
            pw[row, k] -= a * pw[j, k]
    size = 0.0
    for k in range(6):
        size += pw[row, k] * pw[row, k] * minv[k]
    return size / size0


@kernel
def project_integrals(
    code: int,
    p: FloatArray,
    y: FloatArray,
    icodes: IntArray,
    targets: FloatArray,
    pw: FloatArray,
    ws: Workspace,
) -> int:
    """Move the velocity of ``y`` (in place) onto the level set ``I_k(y) = targets[k]`` of the
    integrals ``icodes`` and the velocity constraints, in the kinetic-energy metric (module
    docstring). ``pw`` is a work array of shape ``(WORK_ROWS, 8)``.

    Returns the number of passes made (>= 1: the linear part, solved exactly, then each pass
    that moved a nonlinear integral), or ``-1`` when the corrected state is not finite;
    ``pw[WORK_ROWS - 1, 7]`` is 1 when a nonlinear integral was left for the next steps.
    """
    J, bias, dirs = ws[0], ws[1], ws[2]
    m, I1, I2, I3, a3 = p[1], p[4], p[5], p[6], p[3]
    minv = pw[WORK_ROWS - 1, 0:6]
    minv[0] = minv[1] = minv[2] = 1.0 / m
    minv[3], minv[4], minv[5] = 1.0 / I1, 1.0 / I2, 1.0 / I3
    n_int = icodes.shape[0]
    # ---- the constraints and the linear integrals: one exact minimum-norm correction ----------
    nc = constraint_rows(code, p, y, J, bias, dirs)
    n_rows = 0
    for i in range(nc + n_int):
        if n_rows >= WORK_ROWS - 3:
            break
        if i < nc:
            res = 0.0
            for k in range(6):
                pw[n_rows, k] = J[i, k]
                res += J[i, k] * y[k]
        else:
            ic = icodes[i - nc]
            if not LINEAR[ic]:
                continue
            velocity_gradient(ic, p, y, pw[n_rows])
            res = integral_value(ic, p, y) - targets[i - nc]
            if ic == F6:
                period = 2.0 * math.pi * abs(a3 * I3 * y[5])
                if period > 0.0:
                    res -= period * math.floor(res / period + 0.5)
        pw[n_rows, 6] = -res
        if _orthogonalise(pw, n_rows, n_rows, minv) > DEPENDENT * DEPENDENT:
            size = 0.0
            for k in range(6):
                size += pw[n_rows, k] * pw[n_rows, k] * minv[k]
            size = math.sqrt(size)
            for k in range(7):
                pw[n_rows, k] /= size
            n_rows += 1
    for k in range(6):
        s = 0.0
        for j in range(n_rows):
            s += pw[j, 6] * pw[j, k]
        y[k] += minv[k] * s
    # ---- the nonlinear integrals (energy, slip_nu), along directions the rows leave free ---
    grad = pw[WORK_ROWS - 2]
    passes = 1
    pw[WORK_ROWS - 1, 7] = 0.0
    for _ in range(NEWTON_ITERATIONS):
        moved = False
        for i in range(n_int):
            ic = icodes[i]
            if LINEAR[ic]:
                continue
            res = integral_value(ic, p, y) - targets[i]
            scale = abs(targets[i]) + 1e-300
            if abs(res) <= 4e-16 * scale:
                continue
            velocity_gradient(ic, p, y, grad)
            for k in range(6):
                pw[n_rows, k] = grad[k]
            pw[n_rows, 6] = 0.0
            if _orthogonalise(pw, n_rows, n_rows, minv) <= DEPENDENT * DEPENDENT:
                pw[WORK_ROWS - 1, 7] = 1.0
                continue
            q = 0.0
            usize = 0.0
            for k in range(6):
                q += pw[n_rows, k] * pw[n_rows, k] * minv[k]
                usize += y[k] * y[k] / minv[k]
            if ic == ENERGY:  # the energy, quadratic along d: E + q (l + l^2 / 2) = target
                disc = 1.0 - 2.0 * res / q
                if not disc >= 0.0:
                    pw[WORK_ROWS - 1, 7] = 1.0
                    continue
                lam = -2.0 * res / q / (1.0 + math.sqrt(disc))
            else:  # Newton
                lam = -res / q
            if lam * lam * q > MAX_CHANGE * MAX_CHANGE * usize:
                pw[WORK_ROWS - 1, 7] = 1.0
                continue
            for k in range(6):
                y[k] += lam * minv[k] * pw[n_rows, k]
            moved = True
        if not moved:
            break
        passes += 1
    for k in range(6):
        if not math.isfinite(y[k]):
            return -1
    return passes
