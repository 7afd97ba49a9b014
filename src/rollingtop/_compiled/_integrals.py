"""The first integrals of :mod:`rollingtop.dynamics.integrals`, compiled, one state at a time:
what the projection onto their level set (:mod:`rollingtop._compiled._template.invariants`)
evaluates after every accepted step.

Each is written again from its definition in :mod:`rollingtop.dynamics.integrals` for a bare
state ``y`` (shape (18,)) and the body's parameters ``p = (R, m, g, a3, I1, I2, I3, ms, Js)``;
the tests hold them to those definitions. Every one is a polynomial of degree at most two in
the velocity ``u = (v, w)`` at a fixed attitude -- the linear ones (Lagrange, Jellett, area,
``F6``, the momenta, Routh's, rubber rolling's) of degree one, the energy of degree two -- so a
central difference of step ``h`` gives their gradient in ``u`` exactly, up to round-off
(:func:`velocity_gradient`); ``slip_nu``, a norm, is the one exception: its gradient is
written out. The shell-rotor pair's integrals (with the
shell's terms) are not here: the projection refuses that model.
"""

from __future__ import annotations

import math

from rollingtop._jit import kernel
from rollingtop._types import FloatArray

__all__ = ["CODES", "LINEAR", "integral_value", "velocity_gradient"]

ENERGY, LAGRANGE, JELLETT, AREA, F6, MOMENTUM_X, MOMENTUM_Y, ROUTH, RUBBER_SPIN, SLIP_NU = range(10)
#: The code of each integral by its name in :data:`rollingtop.dynamics.integrals.INTEGRALS`.
CODES = {
    "energy": ENERGY,
    "lagrange": LAGRANGE,
    "jellett": JELLETT,
    "area": AREA,
    "F6": F6,
    "momentum_x": MOMENTUM_X,
    "momentum_y": MOMENTUM_Y,
    "routh": ROUTH,
    "rubber_spin": RUBBER_SPIN,
    "slip_nu": SLIP_NU,
}
#: Whether each integral (by code) is linear and homogeneous in the velocity ``u = (v, w)``.
LINEAR = (False, True, True, True, True, True, True, True, True, False)


@kernel
def integral_value(icode: int, p: FloatArray, y: FloatArray) -> float:
    """The integral of code ``icode`` (:data:`CODES`) at the state ``y``."""
    R, m, g, a3, I1, I2, I3 = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    v0, v1, v2, w0, w1, w2 = y[0], y[1], y[2], y[3], y[4], y[5]
    g0, g1, g2 = y[12], y[13], y[14]
    r0, r1, r2 = -R * g0, -R * g1, -R * g2 - a3  # contact point seen from the CoM
    if icode == ENERGY:
        kin = 0.5 * m * (v0 * v0 + v1 * v1 + v2 * v2)
        kin += 0.5 * (I1 * w0 * w0 + I2 * w1 * w1 + I3 * w2 * w2)
        return float(kin - m * g * (r0 * g0 + r1 * g1 + r2 * g2))
    if icode == LAGRANGE:
        return float(I3 * w2)
    if icode == JELLETT:
        return float(I1 * w0 * r0 + I2 * w1 * r1 + I3 * w2 * r2)
    if icode == AREA:
        return float(I1 * w0 * g0 + I2 * w1 * g1 + I3 * w2 * g2)
    if icode == MOMENTUM_X:
        return float(m * (v0 * y[6] + v1 * y[7] + v2 * y[8]))
    if icode == MOMENTUM_Y:
        return float(m * (v0 * y[9] + v1 * y[10] + v2 * y[11]))
    if icode == ROUTH:
        q = I1 * I3 + m * I1 * (r0 * r0 + r1 * r1) + m * I3 * r2 * r2
        return float(w2 * math.sqrt(q))
    if icode == RUBBER_SPIN:
        ig = I1 * g0 * g0 + I2 * g1 * g1 + I3 * g2 * g2
        rg = r0 * g0 + r1 * g1 + r2 * g2
        return float(w2 * math.sqrt(I3 * (I1 + I3 - ig + m * rg * rg)))
    c, s = math.cos(y[17]), math.sin(y[17])
    n0 = c * y[6] + s * y[9]  # the carried direction nu = cos(psi_nu) alpha + sin(psi_nu) beta
    n1 = c * y[7] + s * y[10]
    n2 = c * y[8] + s * y[11]
    if icode == SLIP_NU:
        p0 = v0 + w1 * r2 - w2 * r1
        p1 = v1 + w2 * r0 - w0 * r2
        p2 = v2 + w0 * r1 - w1 * r0
        size = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        return float(-size if p0 * n0 + p1 * n1 + p2 * n2 < 0.0 else size)
    # F6 (eq. 3.9) in the signed variables of the carried direction (as dynamics.integrals.F6)
    t0 = n1 * g2 - n2 * g1  # tau = nu x gamma, n = e3 x tau
    t1 = n2 * g0 - n0 * g2
    t2 = n0 * g1 - n1 * g0
    v_tau = v0 * t0 + v1 * t1 + v2 * t2
    w_n = -w0 * t1 + w1 * t0
    theta = math.atan2(n2, g2)
    return float(I1 * (v_tau - (R * g2 + a3) * w_n) - I3 * w2 * (R * n2 + a3 * theta))


@kernel
def velocity_gradient(icode: int, p: FloatArray, y: FloatArray, out: FloatArray) -> None:
    """The gradient of the integral ``icode`` in the velocity ``u = y[0:6]`` at a fixed attitude,
    into ``out[0:6]``: central differences of step ``h = max(1, max |u_k|)``, exact for the
    integrals of degree at most two in ``u`` (all but ``slip_nu``, whose gradient is written
    out). ``y`` is restored."""
    if icode == SLIP_NU:  # a signed norm |p|, p = v + w x r: grad_v = p / |p|, grad_w = r x grad_v
        R, a3 = p[0], p[3]
        r0, r1, r2 = -R * y[12], -R * y[13], -R * y[14] - a3
        p0 = y[0] + y[4] * r2 - y[5] * r1
        p1 = y[1] + y[5] * r0 - y[3] * r2
        p2 = y[2] + y[3] * r1 - y[4] * r0
        size = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        if size > 0.0:
            sign = 1.0 if integral_value(icode, p, y) >= 0.0 else -1.0
            p0, p1, p2 = sign * p0 / size, sign * p1 / size, sign * p2 / size
        out[0], out[1], out[2] = p0, p1, p2
        out[3], out[4], out[5] = r1 * p2 - r2 * p1, r2 * p0 - r0 * p2, r0 * p1 - r1 * p0
        return
    h = 1.0
    for k in range(6):
        h = max(h, abs(y[k]))
    for k in range(6):
        keep = y[k]
        y[k] = keep + h
        up = integral_value(icode, p, y)
        y[k] = keep - h
        down = integral_value(icode, p, y)
        y[k] = keep
        out[k] = (up - down) / (2.0 * h)
