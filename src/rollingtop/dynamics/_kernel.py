"""Compiled constrained dynamics shared by every contact model (``docs/model.md``, "Dynamics").

With ``u = (v, w)`` and the diagonal mass matrix ``M = diag(m, m, m, I1, I2, I3)``, the free
motion is (paper eq. 2.7 with gravity written out)

    M u' = f + J^T lambda,    f = (m v x w - m g gamma,  I w x w),

and the constraint rows ``J u = 0`` of the contact model, differentiated along the motion, give
``J u' = -bias``. Eliminating ``u'`` leaves the small symmetric positive-definite system

    (J M^-1 J^T) lambda = -bias - J M^-1 f

(at most 4x4). The general path (:func:`rhs_rows`) fills the model's rows and solves it by a
small Cholesky factorisation: no allocation, no LAPACK call; it serves any model and is what a
new model needs. Every present model also has the same equations written out in closed form,
several times faster: smooth and meridian (with its pole variants) in :func:`_rhs_contact` (a
1x1 or 2x2 solve in scalars), rough in :func:`_rhs_rough` (3x3); the tests hold each closed
form, and the closed-form projections, to the general path.
Kinematics: ``alpha' = alpha x w``, ``beta' = beta x w``, ``gamma' = gamma x w``,
``X' = (v, alpha)``, ``Y' = (v, beta)`` (eq. 2.1).

All functions take bare arrays (state ``y`` of :mod:`._layout`, parameters
``p = (R, m, g, a3, I1, I2, I3)``) and preallocated work arrays ``ws = (J, bias, dirs, A, lam)``
of shapes ``(4, 6), (4,), (4, 3), (4, 4), (4,)``.

The kernels called at every stage allocate nothing and are compiled with ``_nrt=False`` (numba's
flag, used the same way in numba's own string kernels): with numba's reference counting on,
every call increments and decrements each array argument's count atomically, which cost more
than the arithmetic -- the whole stepper ran about twice as slow (``benchmarks/``). Such a
function must not allocate or return arrays; the test suite compiles each of them.
"""

import math

import numpy as np

from rollingtop._jit import compiled, inline, kernel
from rollingtop.contact import meridian, rough, smooth
from rollingtop.contact._rows import contact_arm_rate, row_bias
from rollingtop.dynamics._layout import MAX_ROWS, N_STATE


@compiled()
def new_workspace():
    """Work arrays ``(J, bias, dirs, A, lam)`` for one thread of the kernels (callable from
    Python and from compiled code)."""
    return (
        np.zeros((MAX_ROWS, 6)),
        np.zeros(MAX_ROWS),
        np.zeros((MAX_ROWS, 3)),
        np.zeros((MAX_ROWS, MAX_ROWS)),
        np.zeros(MAX_ROWS),
    )


@kernel
def constraint_rows(code, p, y, J, bias, dirs):
    """Fill the contact model's rows ``J``, their ``bias = J' u`` and force directions ``dirs``.

    Returns the number of rows. ``code`` selects the model (``rollingtop.contact.*.CODE``).
    """
    if code == meridian.CODE:
        return meridian.rows(p, y, J, bias, dirs)
    elif code == smooth.CODE:
        return smooth.rows(p, y, J, bias, dirs)
    elif code == rough.CODE:
        return rough.rows(p, y, J, bias, dirs)
    elif code == meridian.SOUTH_CODE:
        return meridian.rows_pole(p, y, J, bias, dirs, False)
    elif code == meridian.NORTH_CODE:
        return meridian.rows_pole(p, y, J, bias, dirs, True)
    return -1


@inline
def _solve_spd(n, A, x):
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


@inline
def _free_forces(p, y):
    """The free forces ``f = (m v x w - m g gamma, (I w) x w)`` as six scalars."""
    m, g, I1, I2, I3 = p[1], p[2], p[4], p[5], p[6]
    v1, v2, v3 = y[0], y[1], y[2]
    w1, w2, w3 = y[3], y[4], y[5]
    return (
        m * (v2 * w3 - v3 * w2) - m * g * y[12],
        m * (v3 * w1 - v1 * w3) - m * g * y[13],
        m * (v1 * w2 - v2 * w1) - m * g * y[14],
        (I2 - I3) * w2 * w3,
        (I3 - I1) * w3 * w1,
        (I1 - I2) * w1 * w2,
    )


@inline
def _rhs_contact(p, y, dy, ws, two, n1, n2, n3, nd1, nd2, nd3):
    """Closed form of :func:`rhs` for the normal row ``(vp, gamma) = 0`` plus, if ``two``, the
    row ``(vp, n) = 0`` with ``n' = nd`` (meridian models): the same equations as the general
    path, written out in scalars (a 1x1 or 2x2 solve), several times faster."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    gd1 = g2 * w3 - g3 * w2
    gd2 = g3 * w1 - g1 * w3
    gd3 = g1 * w2 - g2 * w1
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = _free_forces(p, y)
    # row 1: d = gamma: J = (gamma, r x gamma), bias = (gamma', v) + (r' x gamma + r x gamma', w)
    a1, a2, a3_ = r2 * g3 - r3 * g2, r3 * g1 - r1 * g3, r1 * g2 - r2 * g1
    bias1 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, g1, g2, g3, gd1, gd2, gd3)
    A11 = (g1 * g1 + g2 * g2 + g3 * g3) * im + a1 * a1 * i1 + a2 * a2 * i2 + a3_ * a3_ * i3
    c1 = -bias1 - (g1 * f1 + g2 * f2 + g3 * f3) * im - (a1 * f4 * i1 + a2 * f5 * i2
                                                        + a3_ * f6 * i3)  # fmt: skip
    l2 = 0.0
    b1 = b2 = b3 = 0.0
    if two:
        b1, b2, b3 = r2 * n3 - r3 * n2, r3 * n1 - r1 * n3, r1 * n2 - r2 * n1
        bias2 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, n1, n2, n3, nd1, nd2, nd3)
        A12 = (g1 * n1 + g2 * n2 + g3 * n3) * im + a1 * b1 * i1 + a2 * b2 * i2 + a3_ * b3 * i3
        A22 = (n1 * n1 + n2 * n2 + n3 * n3) * im + b1 * b1 * i1 + b2 * b2 * i2 + b3 * b3 * i3
        c2 = -bias2 - (n1 * f1 + n2 * f2 + n3 * f3) * im - (b1 * f4 * i1 + b2 * f5 * i2
                                                            + b3 * f6 * i3)  # fmt: skip
        det = A11 * A22 - A12 * A12
        l1 = (c1 * A22 - c2 * A12) / det
        l2 = (A11 * c2 - A12 * c1) / det
    else:
        l1 = c1 / A11
    dy[0] = (f1 + l1 * g1 + l2 * n1) * im
    dy[1] = (f2 + l1 * g2 + l2 * n2) * im
    dy[2] = (f3 + l1 * g3 + l2 * n3) * im
    dy[3] = (f4 + l1 * a1 + l2 * b1) * i1
    dy[4] = (f5 + l1 * a2 + l2 * b2) * i2
    dy[5] = (f6 + l1 * a3_ + l2 * b3) * i3
    # what reaction() needs: force directions and multipliers
    dirs, lam = ws[2], ws[4]
    dirs[0, 0], dirs[0, 1], dirs[0, 2] = g1, g2, g3
    dirs[1, 0], dirs[1, 1], dirs[1, 2] = n1, n2, n3
    lam[0], lam[1] = l1, l2
    return 2 if two else 1


@inline
def _rough_matrix(p, r1, r2, r3):
    """``A = J M^-1 J^T`` of the rough model's rows ``J_k = (e_k, r x e_k)`` (lower triangle):
    ``A = 1/m + sum_j (r x e_k)_j (r x e_l)_j / I_j`` with ``r x e1 = (0, r3, -r2)``,
    ``r x e2 = (-r3, 0, r1)``, ``r x e3 = (r2, -r1, 0)``."""
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    A11 = im + r3 * r3 * i2 + r2 * r2 * i3
    A22 = im + r3 * r3 * i1 + r1 * r1 * i3
    A33 = im + r2 * r2 * i1 + r1 * r1 * i2
    A21 = -r1 * r2 * i3
    A31 = -r1 * r3 * i2
    A32 = -r2 * r3 * i1
    return A11, A21, A22, A31, A32, A33


@inline
def _solve3(A11, A21, A22, A31, A32, A33, b1, b2, b3):
    """``A^-1 b`` for a 3x3 SPD ``A`` (lower triangle) by Cholesky, in scalars."""
    L11 = math.sqrt(A11)
    L21 = A21 / L11
    L31 = A31 / L11
    L22 = math.sqrt(A22 - L21 * L21)
    L32 = (A32 - L31 * L21) / L22
    L33 = math.sqrt(A33 - L31 * L31 - L32 * L32)
    z1 = b1 / L11
    z2 = (b2 - L21 * z1) / L22
    z3 = (b3 - L31 * z1 - L32 * z2) / L33
    x3 = z3 / L33
    x2 = (z2 - L32 * x3) / L22
    x1 = (z1 - L21 * x2 - L31 * x3) / L11
    return x1, x2, x3


@inline
def _rhs_rough(p, y, dy, ws):
    """Closed form of :func:`rhs` for the rough model (rows ``(vp, e_k) = 0``, see
    :mod:`rollingtop.contact.rough`): with ``J u = vp = v + w x r`` the multipliers are the
    contact force ``lambda`` itself, ``A lambda = -w x r' - f_v / m - (I^-1 f_w) x r`` (the
    bias of row ``k`` is ``(r' x e_k, w) = (w x r')_k``), then ``m v' = f_v + lambda`` and
    ``I w' = f_w + r x lambda``."""
    w1, w2, w3 = y[3], y[4], y[5]
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = _free_forces(p, y)
    q1, q2, q3 = f4 * i1, f5 * i2, f6 * i3  # I^-1 f_w
    c1 = -(w2 * rd3 - w3 * rd2) - f1 * im - (q2 * r3 - q3 * r2)
    c2 = -(w3 * rd1 - w1 * rd3) - f2 * im - (q3 * r1 - q1 * r3)
    c3 = -(w1 * rd2 - w2 * rd1) - f3 * im - (q1 * r2 - q2 * r1)
    A11, A21, A22, A31, A32, A33 = _rough_matrix(p, r1, r2, r3)
    l1, l2, l3 = _solve3(A11, A21, A22, A31, A32, A33, c1, c2, c3)
    dy[0] = (f1 + l1) * im
    dy[1] = (f2 + l2) * im
    dy[2] = (f3 + l3) * im
    dy[3] = (f4 + r2 * l3 - r3 * l2) * i1
    dy[4] = (f5 + r3 * l1 - r1 * l3) * i2
    dy[5] = (f6 + r1 * l2 - r2 * l1) * i3
    # what reaction() needs: the force directions are the body axes
    dirs, lam = ws[2], ws[4]
    for k in range(3):
        for c in range(3):
            dirs[k, c] = 1.0 if k == c else 0.0
    lam[0], lam[1], lam[2] = l1, l2, l3
    return 3


@inline
def _kinematics(code, p, y, dy):
    w1, w2, w3 = y[3], y[4], y[5]
    for base in (6, 9, 12):
        e1, e2, e3 = y[base], y[base + 1], y[base + 2]
        dy[base] = e2 * w3 - e3 * w2
        dy[base + 1] = e3 * w1 - e1 * w3
        dy[base + 2] = e1 * w2 - e2 * w1
    dy[15] = y[0] * y[6] + y[1] * y[7] + y[2] * y[8]
    dy[16] = y[0] * y[9] + y[1] * y[10] + y[2] * y[11]
    if code == meridian.SOUTH_CODE or code == meridian.NORTH_CODE:
        dy[17] = meridian.psi_nu_rate(p, y, code == meridian.NORTH_CODE)
    else:
        dy[17] = 0.0


@kernel
def rhs(code, p, y, dy, ws):
    """Right-hand side ``dy = y'`` of the constrained equations; returns the number of rows.

    After the call ``ws[4][:nrows]`` holds the multipliers ``lambda`` and ``ws[2]`` the force
    directions, from which :func:`reaction` forms the contact force.
    """
    # closed forms of every model (the general path, rhs_rows, serves any model and is what a
    # new model needs; a closed form is an optional speed-up)
    if code == smooth.CODE:
        nc = _rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        _kinematics(code, p, y, dy)
        return nc
    if code == meridian.CODE or code == meridian.SOUTH_CODE or code == meridian.NORTH_CODE:
        n1, n2, n3, nd1, nd2, nd3 = meridian.nu_of(p, y, code)
        nc = _rhs_contact(p, y, dy, ws, True, n1, n2, n3, nd1, nd2, nd3)
        _kinematics(code, p, y, dy)
        return nc
    if code == rough.CODE:
        nc = _rhs_rough(p, y, dy, ws)
        _kinematics(code, p, y, dy)
        return nc
    return rhs_rows(code, p, y, dy, ws)


@kernel
def rhs_rows(code, p, y, dy, ws):
    """:func:`rhs` by the general path: the model's rows from :func:`constraint_rows` and the
    small SPD system solved by Cholesky. Every model has it; the tests hold the closed forms of
    :func:`rhs` to it."""
    J, bias, dirs, A, lam = ws
    nc = constraint_rows(code, p, y, J, bias, dirs)
    m, I1, I2, I3 = p[1], p[4], p[5], p[6]
    f = _free_forces(p, y)
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
    _solve_spd(nc, A, lam)
    for k in range(6):
        s = f[k]
        for i in range(nc):
            s += J[i, k] * lam[i]
        dy[k] = minv[k] * s
    _kinematics(code, p, y, dy)
    return nc


@kernel
def reaction(nc, y, ws):
    """Normal force ``N = (F, gamma)`` and tangential force ``|F - N gamma|`` (last :func:`rhs`).

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
def _sync_psi_nu(code, y):
    """Set ``psi_nu`` to the axis azimuth ``atan2(beta3, alpha3)``: the nearest value modulo
    ``2 pi`` (continuous), or modulo ``pi`` in a pole case (keeping the side of the pole), where
    only away from the pole (``s > RESYNC_S``)."""
    s = math.sqrt(y[8] * y[8] + y[11] * y[11])
    pole = code == meridian.SOUTH_CODE or code == meridian.NORTH_CODE
    if not pole and s <= 1e-12:
        return
    if pole and s <= meridian.RESYNC_S:
        # Near the pole only where the axis moves across its meridian rather than towards the
        # pole (meridian.RESYNC_ANGLE): there the geometric direction is well defined although
        # s is small (a sleeping top's precession), while along a passage it would carry the
        # numerical miss distance of the pole.
        if s <= meridian.RESYNC_S_MIN:
            return
        w1, w2 = y[3], y[4]
        da = y[6] * w2 - y[7] * w1  # alpha3' (alpha' = alpha x w): the tilt's rate
        db = y[9] * w2 - y[10] * w1  # beta3'
        across = abs(y[8] * db - y[11] * da)
        if across <= meridian.RESYNC_ANGLE * s * math.sqrt(da * da + db * db):
            return
    period = math.pi if pole else 2.0 * math.pi
    psi = math.atan2(y[11], y[8])
    y[17] = psi + period * round((y[17] - psi) / period)


@inline
def _project_contact(p, y, two, n1, n2, n3):
    """Closed form of the velocity projection of :func:`project` for the normal row and, if
    ``two``, the row along ``n`` (the rows of :func:`_rhs_contact`; a 1x1 or 2x2 solve)."""
    R, m, a3, I1, I2, I3 = p[0], p[1], p[3], p[4], p[5], p[6]
    im, i1, i2, i3 = 1.0 / m, 1.0 / I1, 1.0 / I2, 1.0 / I3
    v1, v2, v3, w1, w2, w3 = y[0], y[1], y[2], y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3 = -R * g1, -R * g2, -R * g3 - a3
    a1, a2, a3_ = r2 * g3 - r3 * g2, r3 * g1 - r1 * g3, r1 * g2 - r2 * g1
    c1 = g1 * v1 + g2 * v2 + g3 * v3 + a1 * w1 + a2 * w2 + a3_ * w3
    A11 = (g1 * g1 + g2 * g2 + g3 * g3) * im + a1 * a1 * i1 + a2 * a2 * i2 + a3_ * a3_ * i3
    l2 = 0.0
    b1 = b2 = b3 = 0.0
    if two:
        b1, b2, b3 = r2 * n3 - r3 * n2, r3 * n1 - r1 * n3, r1 * n2 - r2 * n1
        c2 = n1 * v1 + n2 * v2 + n3 * v3 + b1 * w1 + b2 * w2 + b3 * w3
        A12 = (g1 * n1 + g2 * n2 + g3 * n3) * im + a1 * b1 * i1 + a2 * b2 * i2 + a3_ * b3 * i3
        A22 = (n1 * n1 + n2 * n2 + n3 * n3) * im + b1 * b1 * i1 + b2 * b2 * i2 + b3 * b3 * i3
        det = A11 * A22 - A12 * A12
        l1 = (c1 * A22 - c2 * A12) / det
        l2 = (A11 * c2 - A12 * c1) / det
    else:
        l1 = c1 / A11
    y[0] = v1 - (l1 * g1 + l2 * n1) * im
    y[1] = v2 - (l1 * g2 + l2 * n2) * im
    y[2] = v3 - (l1 * g3 + l2 * n3) * im
    y[3] = w1 - (l1 * a1 + l2 * b1) * i1
    y[4] = w2 - (l1 * a2 + l2 * b2) * i2
    y[5] = w3 - (l1 * a3_ + l2 * b3) * i3


@inline
def _project_rough(p, y):
    """Closed form of the velocity projection of :func:`project` for the rough model:
    ``lambda = A^-1 vp``, ``v <- v - lambda / m``, ``w <- w - I^-1 (r x lambda)``."""
    R, m, a3 = p[0], p[1], p[3]
    g1, g2, g3 = y[12], y[13], y[14]
    r1, r2, r3 = -R * g1, -R * g2, -R * g3 - a3
    w1, w2, w3 = y[3], y[4], y[5]
    c1 = y[0] + w2 * r3 - w3 * r2
    c2 = y[1] + w3 * r1 - w1 * r3
    c3 = y[2] + w1 * r2 - w2 * r1
    A11, A21, A22, A31, A32, A33 = _rough_matrix(p, r1, r2, r3)
    l1, l2, l3 = _solve3(A11, A21, A22, A31, A32, A33, c1, c2, c3)
    y[0] -= l1 / m
    y[1] -= l2 / m
    y[2] -= l3 / m
    y[3] -= (r2 * l3 - r3 * l2) / p[4]
    y[4] -= (r3 * l1 - r1 * l3) / p[5]
    y[5] -= (r1 * l2 - r2 * l1) / p[6]


@kernel
def project(code, p, y, ws):
    """Project ``y`` in place onto the constraint manifold.

    The frame ``Q = [alpha; beta; gamma]`` goes to its nearest orthogonal matrix by one
    Newton-Schulz step ``Q <- (3 Q - Q Q^T Q) / 2`` (quadratic convergence; the error after an
    accepted step is at truncation level); ``psi_nu`` is re-synchronised with the axis azimuth
    (see :mod:`rollingtop.contact.meridian`). The velocity ``u`` then goes to the nearest point,
    in the kinetic-energy metric, of ``J u = 0``: ``u <- u - M^-1 J^T (J M^-1 J^T)^-1 J u``.
    """
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
    _sync_psi_nu(code, y)
    if code == smooth.CODE:
        _project_contact(p, y, False, 0.0, 0.0, 0.0)
        return
    if code == meridian.CODE or code == meridian.SOUTH_CODE or code == meridian.NORTH_CODE:
        n1, n2, n3, _, _, _ = meridian.nu_of(p, y, code)
        _project_contact(p, y, True, n1, n2, n3)
        return
    if code == rough.CODE:
        _project_rough(p, y)
        return
    project_velocity_rows(code, p, y, ws)


@kernel
def project_velocity_rows(code, p, y, ws):
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
    _solve_spd(nc, A, lam)
    for k in range(6):
        s = 0.0
        for i in range(nc):
            s += J[i, k] * lam[i]
        y[k] -= minv[k] * s


@compiled()
def diagnostics(code, p, Y, out):
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
