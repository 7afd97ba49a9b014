"""Closed forms of the constrained equations for the contact row ``(vp, gamma) = 0`` and, if
present, one more contact row ``(vp, n) = 0`` (the smooth and meridian models): the same
equations as the general path (:func:`rollingtop._compiled._template.dynamics.rhs_rows`),
written out in scalars (a 1x1 or 2x2 solve), several times faster. The tests hold them to the
general path."""

from __future__ import annotations

from rollingtop._jit import inline
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact._rows import contact_arm_rate, free_forces, row_bias


@inline
def rhs_contact(
    p: FloatArray,
    y: FloatArray,
    dy: FloatArray,
    ws: Workspace,
    two: bool,
    n1: float,
    n2: float,
    n3: float,
    nd1: float,
    nd2: float,
    nd3: float,
) -> int:
    """The accelerations for the normal row ``(vp, gamma) = 0`` plus, if ``two``, the row
    ``(vp, n) = 0`` with ``n' = nd``; fills ``dy[0:6]`` and, for the reaction, the force
    directions ``ws[2]`` and multipliers ``ws[4]``. Returns the number of rows."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    gd1 = g2 * w3 - g3 * w2
    gd2 = g3 * w1 - g1 * w3
    gd3 = g1 * w2 - g2 * w1
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    im, i1, i2, i3 = 1.0 / p[1], 1.0 / p[4], 1.0 / p[5], 1.0 / p[6]
    f1, f2, f3, f4, f5, f6 = free_forces(p, y)
    # row 1: d = gamma: J = (gamma, r x gamma), bias = (gamma', v) + (r' x gamma + r x gamma', w)
    a1, a2, a3_ = r2 * g3 - r3 * g2, r3 * g1 - r1 * g3, r1 * g2 - r2 * g1
    bias1 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, g1, g2, g3, gd1, gd2, gd3)
    A11 = (g1 * g1 + g2 * g2 + g3 * g3) * im + a1 * a1 * i1 + a2 * a2 * i2 + a3_ * a3_ * i3
    c1 = -bias1 - (g1 * f1 + g2 * f2 + g3 * f3) * im - (a1 * f4 * i1 + a2 * f5 * i2 + a3_ * f6 * i3)
    l2 = 0.0
    b1 = b2 = b3 = 0.0
    if two:
        b1, b2, b3 = r2 * n3 - r3 * n2, r3 * n1 - r1 * n3, r1 * n2 - r2 * n1
        bias2 = row_bias(y, r1, r2, r3, rd1, rd2, rd3, n1, n2, n3, nd1, nd2, nd3)
        A12 = (g1 * n1 + g2 * n2 + g3 * n3) * im + a1 * b1 * i1 + a2 * b2 * i2 + a3_ * b3 * i3
        A22 = (n1 * n1 + n2 * n2 + n3 * n3) * im + b1 * b1 * i1 + b2 * b2 * i2 + b3 * b3 * i3
        c2 = (
            -bias2
            - (n1 * f1 + n2 * f2 + n3 * f3) * im
            - (b1 * f4 * i1 + b2 * f5 * i2 + b3 * f6 * i3)
        )
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
def project_contact(
    p: FloatArray, y: FloatArray, two: bool, n1: float, n2: float, n3: float
) -> None:
    """The velocity projection (:func:`rollingtop._compiled._template.dynamics.project`) for the
    normal row and, if ``two``, the row along ``n`` (the rows of :func:`rhs_contact`; a 1x1 or 2x2
    solve)."""
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
