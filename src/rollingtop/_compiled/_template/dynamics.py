"""Compiled constrained dynamics of one contact model (``docs/model.md``, "Dynamics").

With ``u = (v, w)`` and the diagonal mass matrix ``M = diag(m, m, m, I1, I2, I3)``, the free
motion is (paper eq. 2.7 with gravity written out)

    M u' = f + J^T lambda,    f = (m v x w - m g gamma,  I w x w),

and the constraint rows ``J u = 0`` of the contact model, differentiated along the motion, give
``J u' = -bias``. Eliminating ``u'`` leaves the small symmetric positive-definite system

    (J M^-1 J^T) lambda = -bias - J M^-1 f

(at most 4x4). The general path (:func:`rhs_rows`) fills the model's rows and solves it by a
small Cholesky factorisation: no allocation, no LAPACK call; it serves any model and is what a
new model needs. A model may also have the same equations written out in closed form, several
times faster (its module's ``accel`` and ``project_velocity``, reached through this model's
compiled dispatch, ``_dispatch``); then the general path is compiled only when called (the
tests hold each closed form to it).
Kinematics: ``alpha' = alpha x w``, ``beta' = beta x w``, ``gamma' = gamma x w``,
``X' = (v, alpha)``, ``Y' = (v, beta)`` (eq. 2.1).

All functions take bare arrays (state ``y`` of :mod:`rollingtop._layout`, parameters
``p`` of :attr:`rollingtop.SphericalTop.params`, the kernel code ``code`` of one of this model's
kernels) and preallocated work arrays ``ws = (J, bias, dirs, A, lam)`` of shapes
``(4, 6), (4,), (4, 3), (4, 4), (4,)`` (:func:`rollingtop._compiled._kernel.new_workspace`).
The kernels called at every stage allocate nothing and are compiled without reference counting
(:func:`rollingtop._jit.kernel`).
"""

from __future__ import annotations

import numpy as np

from rollingtop._compiled._kernel import frame_rates, new_workspace, reaction, solve_spd
from rollingtop._compiled._template import _dispatch
from rollingtop._compiled._template._dispatch import CLOSED_ACCEL, CLOSED_PROJECTION
from rollingtop._compiled._template._dispatch import rows as constraint_rows
from rollingtop._jit import compiled, inline, kernel
from rollingtop._layout import MAX_ROWS, N_STATE
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact._rows import free_forces

__all__ = [
    "constraint_rows",
    "contact_forces",
    "diagnostics",
    "project",
    "project_velocity_rows",
    "rhs",
    "rhs_inline",
    "rhs_rows",
]


@inline
def _kinematics(code: int, p: FloatArray, y: FloatArray, dy: FloatArray) -> None:
    frame_rates(y, dy)  # shared by every model (slots 6..16)
    dy[17] = _dispatch.direction_rate(code, p, y)  # the model's own slot


@inline
def rhs_inline(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """Right-hand side ``dy = y'`` of the constrained equations; returns the number of rows.

    After the call ``ws[4][:nrows]`` holds the multipliers ``lambda`` and ``ws[2]`` the force
    directions, from which :func:`rollingtop._compiled._kernel.reaction` forms the contact force.
    The model's closed form where it has one, else the general path (:func:`rhs_rows`). Inlined into
    the stepper's stage loop (:func:`.stepper.run_rows`): a call there passes the workspace's five
    arrays field by field, twelve times a step, which cost 15 % of the paper's model's time against
    the C limit (``benchmarks/c_limit.py``); elsewhere :func:`rhs` calls it.
    """
    if CLOSED_ACCEL:
        # the kinematics first: a model whose last slot is a velocity of its own (shell-rotor)
        # sets its rate with the accelerations
        _kinematics(code, p, y, dy)
        return _dispatch.accel(code, p, y, dy, ws)
    return rhs_rows(code, p, y, dy, ws)


@kernel
def rhs(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """:func:`rhs_inline` as a function of its own (every caller but the stage loop)."""
    return rhs_inline(code, p, y, dy, ws)


@kernel
def rhs_rows(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """:func:`rhs` by the general path: the model's rows from :func:`constraint_rows` and the
    small SPD system solved by Cholesky. Every model has it; the tests hold the closed forms of
    :func:`rhs` to it."""
    J, bias, dirs, A, lam = ws
    nc = constraint_rows(code, p, y, J, bias, dirs)
    m, I1, I2, I3 = p[1], p[4], p[5], p[6]
    f = free_forces(p, y)
    minv = (1.0 / m, 1.0 / m, 1.0 / m, 1.0 / I1, 1.0 / I2, 1.0 / I3)
    for i in range(nc):
        s = -bias[i]
        for k in range(6):
            s -= J[i, k] * minv[k] * f[k]
        lam[i] = s
        for j in range(i + 1):
            a = 0.0
            for k in range(6):
                a += J[i, k] * J[j, k] * minv[k]
            A[i, j] = a
    solve_spd(nc, A, lam)
    for k in range(6):
        s = f[k]
        for i in range(nc):
            s += J[i, k] * lam[i]
        dy[k] = minv[k] * s
    _kinematics(code, p, y, dy)
    return nc


#: Largest Newton-Schulz steps of the frame in one :func:`project`.
FRAME_ITERATIONS = 6
#: ``max |Q Q^T - 1|`` from which one Newton-Schulz step reaches round-off (``1.5 e^2``).
FRAME_ONE_STEP = 1e-8


@kernel
def project(code: int, p: FloatArray, y: FloatArray, ws: Workspace) -> None:
    """Project ``y`` in place onto the constraint manifold.

    The frame ``Q = [alpha; beta; gamma]`` goes to its nearest orthogonal matrix by
    Newton-Schulz steps ``Q <- (3 Q - Q Q^T Q) / 2`` (quadratic convergence: a step from an
    error ``e`` leaves about ``1.5 e^2``) until a step starts within :data:`FRAME_ONE_STEP`:
    one step after an accepted step at a tight tolerance, a few at a loose one (one step left
    3e-3 at ``rtol = 1e-2``); ``psi_nu`` is
    re-synchronised with the axis azimuth (see :mod:`rollingtop.contact.meridian`). The
    velocity ``u`` then goes to the nearest point, in the kinetic-energy metric, of ``J u = 0``:
    ``u <- u - M^-1 J^T (J M^-1 J^T)^-1 J u``.

    The steps stay written here, not in a shared helper: compiled apart, LLVM fuses their
    multiply-adds otherwise, and the C limit (``benchmarks/c_limit/dop853.c``) mirrors these.
    """
    for _ in range(FRAME_ITERATIONS):
        # Q Q^T (rows alpha, beta, gamma at offsets 6, 9, 12)
        G00 = y[6] * y[6] + y[7] * y[7] + y[8] * y[8]
        G11 = y[9] * y[9] + y[10] * y[10] + y[11] * y[11]
        G22 = y[12] * y[12] + y[13] * y[13] + y[14] * y[14]
        G01 = y[6] * y[9] + y[7] * y[10] + y[8] * y[11]
        G02 = y[6] * y[12] + y[7] * y[13] + y[8] * y[14]
        G12 = y[9] * y[12] + y[10] * y[13] + y[11] * y[14]
        for c in range(3):
            a, b, g = y[6 + c], y[9 + c], y[12 + c]
            y[6 + c] = 1.5 * a - 0.5 * (G00 * a + G01 * b + G02 * g)
            y[9 + c] = 1.5 * b - 0.5 * (G01 * a + G11 * b + G12 * g)
            y[12 + c] = 1.5 * g - 0.5 * (G02 * a + G12 * b + G22 * g)
        error = max(abs(G00 - 1.0), abs(G11 - 1.0), abs(G22 - 1.0), abs(G01), abs(G02), abs(G12))
        if error <= FRAME_ONE_STEP:  # the step left about error^2: round-off
            break
    _dispatch.sync_direction(code, y)
    if CLOSED_PROJECTION:
        _dispatch.project_velocity(code, p, y)
    else:
        project_velocity_rows(code, p, y, ws)


@kernel
def project_velocity_rows(code: int, p: FloatArray, y: FloatArray, ws: Workspace) -> None:
    """The velocity part of :func:`project` by the general path (rows and a Cholesky solve);
    the tests hold the closed forms to it."""
    J, bias, dirs, A, lam = ws
    nc = constraint_rows(code, p, y, J, bias, dirs)
    m, I1, I2, I3 = p[1], p[4], p[5], p[6]
    minv = (1.0 / m, 1.0 / m, 1.0 / m, 1.0 / I1, 1.0 / I2, 1.0 / I3)
    for i in range(nc):
        s = 0.0
        for k in range(6):
            s += J[i, k] * y[k]
        lam[i] = s
        for j in range(i + 1):
            a = 0.0
            for k in range(6):
                a += J[i, k] * J[j, k] * minv[k]
            A[i, j] = a
    solve_spd(nc, A, lam)
    for k in range(6):
        s = 0.0
        for i in range(nc):
            s += J[i, k] * lam[i]
        y[k] -= minv[k] * s


@compiled()
def diagnostics(code: int, p: FloatArray, Y: FloatArray, out: FloatArray) -> None:
    """Per-sample reactions and constraint errors.

    Parameters
    ----------
    Y : ndarray, shape (n, 18)
        States.
    out : ndarray, shape (n, 4 + 4)
        Filled with: normal force, tangential force, max ``|J_k u|`` over the rows,
        max ``|Q Q^T - 1|``, then each row's residual ``J_k u`` (zero-padded to 4).
    """
    ws = new_workspace()
    dy = np.empty(N_STATE)
    for n in range(Y.shape[0]):
        y = Y[n]
        nc = rhs(code, p, y, dy, ws)
        N, T = reaction(nc, y, ws)
        out[n, 0] = N
        out[n, 1] = T
        J = ws[0]
        constraint_rows(code, p, y, J, ws[1], ws[2])  # the closed-form rhs leaves J unset
        worst = 0.0
        for i in range(MAX_ROWS):
            r = 0.0
            if i < nc:
                for k in range(6):
                    r += J[i, k] * y[k]
            out[n, 4 + i] = r
            worst = max(worst, abs(r))
        out[n, 2] = worst
        err = 0.0
        for i in range(3):
            for j in range(3):
                s = 0.0
                for c in range(3):
                    s += y[6 + 3 * i + c] * y[6 + 3 * j + c]
                if i == j:
                    s -= 1.0
                err = max(err, abs(s))
        out[n, 3] = err


@compiled()
def contact_forces(code: int, p: FloatArray, Y: FloatArray, out: FloatArray) -> None:
    """The normal and tangential contact forces of each state of ``Y`` (shape (n, 18)) into
    ``out`` (shape (n, 2)): the right-hand side and the reaction alone, without the constraint
    rows that :func:`diagnostics` also evaluates (what a portrait's shading and the friction a
    motion needs use; far less to compile)."""
    ws = new_workspace()
    dy = np.empty(N_STATE)
    for n in range(Y.shape[0]):
        nc = rhs(code, p, Y[n], dy, ws)
        out[n, 0], out[n, 1] = reaction(nc, Y[n], ws)
