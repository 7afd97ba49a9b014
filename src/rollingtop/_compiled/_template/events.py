"""Compiled event functions of one contact model: scalar functions of the state whose zeros the
stepper locates (the codes: :mod:`rollingtop._compiled._events`).

``W_TAU``: ``s * w_tau = (w, e3 x gamma) = gamma1 w2 - gamma2 w1``, zero exactly when
``w_tau = 0`` (for ``s > 0``): the turning points of ``gamma3`` (paper eq. 3.3,
``gamma3' = s w_tau``). In the meridian model's pole cases ``s`` vanishes at a pole passage
while ``w_tau`` does not, so under a kernel that carries its direction the event function is
``w_tau = (w, nu x gamma)`` with the carried direction ``nu`` (continuous through the pole).
"""

from __future__ import annotations

import math

from rollingtop._compiled._events import W_TAU
from rollingtop._compiled._template import _dispatch
from rollingtop._jit import kernel
from rollingtop._types import FloatArray


@kernel
def event_value(code: int, model_code: int, y: FloatArray) -> float:
    """Value of event function ``code`` at state ``y`` under kernel ``model_code``."""
    if code == W_TAU:
        if _dispatch.carries_direction(model_code):
            c, s = math.cos(y[17]), math.sin(y[17])
            n1 = c * y[6] + s * y[9]
            n2 = c * y[7] + s * y[10]
            n3 = c * y[8] + s * y[11]
            g1, g2, g3 = y[12], y[13], y[14]
            w_tau: float = (
                y[3] * (n2 * g3 - n3 * g2) + y[4] * (n3 * g1 - n1 * g3) + y[5] * (n1 * g2 - n2 * g1)
            )
            return w_tau
        s_w_tau: float = y[12] * y[4] - y[13] * y[3]
        return s_w_tau
    return 1.0
