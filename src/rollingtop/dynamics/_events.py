"""Compiled event functions: scalar functions of the state whose zeros the stepper locates.

``W_TAU``: ``s * w_tau = (w, e3 x gamma) = gamma1 w2 - gamma2 w1``, zero exactly when
``w_tau = 0`` (for ``s > 0``): the turning points of ``gamma3`` (paper eq. 3.3,
``gamma3' = s w_tau``).
"""

from numba import njit

NONE = 0
W_TAU = 1

#: Names accepted by :func:`rollingtop.simulate` (``events=...``).
EVENTS = {"w_tau": W_TAU}


@njit(cache=True, error_model="numpy")
def event_value(code, y):
    """Value of event function ``code`` at state ``y``."""
    if code == W_TAU:
        return y[12] * y[4] - y[13] * y[3]
    return 1.0
