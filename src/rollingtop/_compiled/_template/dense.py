"""Dense output of a DOP853 step and the zeros located on it, for one contact model.

The 7th-order continuous extension of the step (Hairer, Norsett & Wanner, *Solving ODEs I*,
Sec. II.10; the coefficients of :mod:`rollingtop._compiled._dop853_tableau`), built from the
step's own stages (:func:`prepare_dense`; evaluated by the shared
:func:`rollingtop._compiled._dop853_dense.dense_eval`), and the bisections on it that locate the
first loss of contact and the zeros of an event function. Called by the stepper
(:func:`.stepper.run`); compiled without reference counting like it
(:func:`rollingtop._jit.kernel`).
"""

from __future__ import annotations

from rollingtop._compiled._dop853_dense import dense_eval
from rollingtop._compiled._dop853_stages import stage
from rollingtop._compiled._dop853_tableau import D
from rollingtop._compiled._kernel import reaction
from rollingtop._compiled._template.dynamics import project, rhs
from rollingtop._compiled._template.events import event_value
from rollingtop._jit import kernel
from rollingtop._types import FloatArray, Workspace


@kernel
def prepare_dense(
    code: int,
    p: FloatArray,
    K: FloatArray,
    y: FloatArray,
    ynew: FloatArray,
    h: float,
    ytmp: FloatArray,
    Fd: FloatArray,
    ws: Workspace,
) -> None:
    """Extra stages 14-16 and the coefficients ``Fd`` of the 7th-order interpolant on a step."""
    n = y.shape[0]
    for s in range(13, 16):
        stage(K, s, y, h, ytmp)
        rhs(code, p, ytmp, K[s], ws)
    for i in range(n):
        dlt = ynew[i] - y[i]
        Fd[0, i] = dlt
        Fd[1, i] = h * K[0, i] - dlt
        Fd[2, i] = 2.0 * dlt - h * (K[12, i] + K[0, i])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += D[r, j] * K[j, i]
            Fd[3 + r, i] = h * acc


@kernel
def normal_root(
    code: int,
    p: FloatArray,
    Fd: FloatArray,
    y: FloatArray,
    t: float,
    h: float,
    ytmp: FloatArray,
    dy: FloatArray,
    ws: Workspace,
) -> float:
    """Time in ``[t, t + h]`` where the normal force crosses zero, by bisection on the dense
    output (the force is positive at ``x = 0`` and negative at ``x = 1``); 60 halvings.
    ``ytmp`` and ``dy`` are scratch."""
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        dense_eval(Fd, y, mid, ytmp)
        project(code, p, ytmp, ws)
        nc = rhs(code, p, ytmp, dy, ws)
        N, _ = reaction(nc, ytmp, ws)
        if N >= 0.0:
            lo = mid
        else:
            hi = mid
    return t + 0.5 * (lo + hi) * h


@kernel
def event_root(
    ev_code: int,
    code: int,
    Fd: FloatArray,
    y: FloatArray,
    t: float,
    h: float,
    ytmp: FloatArray,
) -> float:
    """Fraction ``x`` in ``[0, 1]`` of the step ``[t, t + h]`` where the event function changes
    sign, by bisection on the dense output (60 halvings: to the resolution of the
    interpolant)."""
    dense_eval(Fd, y, 0.0, ytmp)
    g_lo = event_value(ev_code, code, ytmp)
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        dense_eval(Fd, y, mid, ytmp)
        g = event_value(ev_code, code, ytmp)
        if (g > 0.0) == (g_lo > 0.0) and g != 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
