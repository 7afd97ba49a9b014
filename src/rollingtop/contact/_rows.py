"""Compiled helpers shared by the contact models' constraint kernels.

A constraint row is a linear condition ``J . u = 0`` on the generalised velocity
``u = (v, w)``. Its reaction is ``lambda * J`` (ideal constraint, d'Alembert-Lagrange), and the
time derivative of the condition along the motion adds the *bias* ``dJ/dt . u`` to the
acceleration equation (``docs/model.md``, "Dynamics").
"""

from __future__ import annotations

import math

from rollingtop._jit import inline
from rollingtop._types import Float6, FloatArray


@inline
def row_bias(
    y: FloatArray,
    r1: float,
    r2: float,
    r3: float,
    rd1: float,
    rd2: float,
    rd3: float,
    d1: float,
    d2: float,
    d3: float,
    dd1: float,
    dd2: float,
    dd3: float,
) -> float:
    """``J' u = (d', v) + (r' x d + r x d', w)`` of the contact row along ``d``."""
    q1 = rd2 * d3 - rd3 * d2 + r2 * dd3 - r3 * dd2
    q2 = rd3 * d1 - rd1 * d3 + r3 * dd1 - r1 * dd3
    q3 = rd1 * d2 - rd2 * d1 + r1 * dd2 - r2 * dd1
    bias: float = dd1 * y[0] + dd2 * y[1] + dd3 * y[2] + q1 * y[3] + q2 * y[4] + q3 * y[5]
    return bias


@inline
def contact_arm_rate(p: FloatArray, y: FloatArray) -> Float6:
    """Contact arm ``r = -R gamma - a`` and its rate ``r' = -R gamma'``, ``gamma' = gamma x w``
    (paper eq. 2.1), as six scalars."""
    R, a3 = p[0], p[3]
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    return (
        -R * g1,
        -R * g2,
        -R * g3 - a3,
        -R * (g2 * w3 - g3 * w2),
        -R * (g3 * w1 - g1 * w3),
        -R * (g1 * w2 - g2 * w1),
    )


@inline
def contact_row(
    p: FloatArray,
    y: FloatArray,
    k: int,
    d1: float,
    d2: float,
    d3: float,
    dd1: float,
    dd2: float,
    dd3: float,
    J: FloatArray,
    bias: FloatArray,
    dirs: FloatArray,
) -> None:
    """Write row ``k`` for the no-slip condition ``(vp, d) = 0`` of the contact point.

    ``vp = v + w x r`` with ``r = -R gamma - a``, so ``J = (d, r x d)``; the reaction is the
    force ``lambda d`` applied at the contact point. ``(dd1, dd2, dd3)`` is ``d'`` along the
    motion; ``r' = -R gamma'`` and ``gamma' = gamma x w`` (paper eq. 2.1).
    """
    r1, r2, r3, rd1, rd2, rd3 = contact_arm_rate(p, y)
    J[k, 0] = d1
    J[k, 1] = d2
    J[k, 2] = d3
    J[k, 3] = r2 * d3 - r3 * d2
    J[k, 4] = r3 * d1 - r1 * d3
    J[k, 5] = r1 * d2 - r2 * d1
    bias[k] = row_bias(y, r1, r2, r3, rd1, rd2, rd3, d1, d2, d3, dd1, dd2, dd3)
    dirs[k, 0] = d1
    dirs[k, 1] = d2
    dirs[k, 2] = d3


@inline
def normal_row(
    p: FloatArray, y: FloatArray, k: int, J: FloatArray, bias: FloatArray, dirs: FloatArray
) -> None:
    """Row ``k`` for the contact condition ``f1 = (vp, gamma) = 0`` (paper eq. 2.4)."""
    w1, w2, w3 = y[3], y[4], y[5]
    g1, g2, g3 = y[12], y[13], y[14]
    contact_row(
        p,
        y,
        k,
        g1,
        g2,
        g3,
        g2 * w3 - g3 * w2,
        g3 * w1 - g1 * w3,
        g1 * w2 - g2 * w1,
        J,
        bias,
        dirs,
    )


@inline
def free_forces(p: FloatArray, y: FloatArray) -> Float6:
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
def sync_azimuth(y: FloatArray, period: float) -> None:
    """Set ``psi_nu = y[17]`` to the axis azimuth ``psi = atan2(beta3, alpha3)``, the value
    nearest to the present one modulo ``period`` (``2 pi``: continuous; ``pi``: keeping the side
    of a pole, see :mod:`rollingtop.contact.meridian`)."""
    psi = math.atan2(y[11], y[8])
    y[17] = psi + period * round((y[17] - psi) / period)


@inline
def sync_direction(y: FloatArray, variant: int) -> None:
    """``psi_nu`` follows the axis azimuth (:func:`sync_azimuth`, modulo ``2 pi``) wherever it is
    defined (``s > 1e-12``): the default of a model that carries no direction."""
    if math.sqrt(y[8] * y[8] + y[11] * y[11]) > 1e-12:
        sync_azimuth(y, 2.0 * math.pi)


@inline
def direction_rate(p: FloatArray, y: FloatArray, variant: int) -> float:
    """``psi_nu'`` of a model that carries no direction: 0 (``psi_nu`` is re-synchronised with
    the axis azimuth after every step)."""
    return 0.0
