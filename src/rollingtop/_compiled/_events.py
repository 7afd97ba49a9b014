"""Event functions: scalar functions of the state whose zeros the stepper locates.

The codes, shared by every model; each model's compiled event function is
:func:`rollingtop._compiled._template.events.event_value` (compiled per model).

``W_TAU``: ``s * w_tau = (w, e3 x gamma) = gamma1 w2 - gamma2 w1``, zero exactly when
``w_tau = 0``: the turning points of ``gamma3`` (paper eq. 3.3, ``gamma3' = s w_tau``).
"""

from __future__ import annotations

NONE = 0
W_TAU = 1

#: Names accepted by :func:`rollingtop.simulate` (``events=...``).
EVENTS = {"w_tau": W_TAU}
