"""Dense output of a DOP853 step and the zeros located on it, for one contact model.

The 7th-order continuous extension of the step (Hairer, Norsett & Wanner, *Solving ODEs I*,
Sec. II.10; the coefficients of :mod:`rollingtop._compiled._dop853_tableau`), built from the
step's own stages (:func:`prepare_dense`; evaluated by the shared
:func:`rollingtop._compiled._dop853_dense.dense_eval`), and the bisections on it that locate the
first loss of contact and the zeros of an event function. Called by the stepper's loop
(:func:`.stepper.run_rows`); compiled without reference counting like it
(:func:`rollingtop._jit.kernel`). The dense output, the loss of contact and the dip search are
called at one site of the loop and compiled into it (:func:`rollingtop._jit.spliced`): as
functions of their own they were optimised and emitted twice, alone and in the loop.
"""

from __future__ import annotations

import math

from rollingtop._compiled._dop853 import (
    EV_CODE,
    EV_DIRECTION,
    EV_PREV_G,
    EV_PREV_T,
    G_OLD,
    N_EVENTS,
    NFEV,
    dip_predicted,
)
from rollingtop._compiled._dop853_dense import dense_eval
from rollingtop._compiled._dop853_stages import dense_stage
from rollingtop._compiled._dop853_tableau import D
from rollingtop._compiled._kernel import reaction
from rollingtop._compiled._template.dynamics import project, rhs
from rollingtop._compiled._template.events import event_value
from rollingtop._jit import kernel, spliced
from rollingtop._types import FloatArray, IntArray, Workspace


@spliced
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
        dense_stage(K, s, y, h, ytmp)
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


@spliced
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


#: Interior points of a step where the normal force is sampled when a dip is predicted, and the
#: golden-section iterations that then refine its minimum.
DIP_SAMPLES = 8
DIP_REFINE = 40
_GOLDEN = 0.3819660112501051


@kernel
def normal_at(
    code: int,
    p: FloatArray,
    Fd: FloatArray,
    y: FloatArray,
    x: float,
    ytmp: FloatArray,
    dy: FloatArray,
    ws: Workspace,
) -> tuple[float, float]:
    """The contact force ``(N, |F_t|)`` at the fraction ``x`` of the step, on the dense output
    (projected onto the constraints, as the samples are)."""
    dense_eval(Fd, y, x, ytmp)
    project(code, p, ytmp, ws)
    nc = rhs(code, p, ytmp, dy, ws)
    return reaction(nc, ytmp, ws)


@spliced
def dip_minimum(
    code: int,
    p: FloatArray,
    Fd: FloatArray,
    y: FloatArray,
    t: float,
    h: float,
    ytmp: FloatArray,
    dy: FloatArray,
    ws: Workspace,
    found: FloatArray,
) -> int:
    """The normal force's minimum inside the step ``[t, t + h]`` on the dense output: sampled at
    :data:`DIP_SAMPLES` - 1 interior points, the best one refined by golden sections. Writes
    ``found = (t_min, N_min, t_lost)`` (``t_lost``: where the force first turns negative, by
    bisection between the last positive sample and the first negative one; NaN if it does not)
    and returns the right-hand sides evaluated. Each evaluation is also handed to the
    friction-ratio tracking by the caller through ``found[3:5]`` (the largest ``|F_t| / N``
    and its time)."""
    best_x, best_n = 0.0, math.inf
    found[2] = math.nan
    found[3], found[4] = 0.0, math.nan
    x_pos = 0.0
    evals = 0
    for j in range(1, DIP_SAMPLES):
        x = j / DIP_SAMPLES
        n_x, tf = normal_at(code, p, Fd, y, x, ytmp, dy, ws)
        evals += 1
        if n_x > 0.0 and tf / n_x > found[3]:
            found[3], found[4] = tf / n_x, t + x * h
        if n_x < best_n:
            best_x, best_n = x, n_x
        if n_x < 0.0 and math.isnan(found[2]):
            lo, hi = x_pos, x
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                n_mid, _ = normal_at(code, p, Fd, y, mid, ytmp, dy, ws)
                if n_mid >= 0.0:
                    lo = mid
                else:
                    hi = mid
            evals += 60
            found[2] = t + 0.5 * (lo + hi) * h
        if n_x >= 0.0 and math.isnan(found[2]):
            x_pos = x
    a = max(0.0, best_x - 1.0 / DIP_SAMPLES)
    b = min(1.0, best_x + 1.0 / DIP_SAMPLES)
    c = a + _GOLDEN * (b - a)
    d = b - _GOLDEN * (b - a)
    fc, _ = normal_at(code, p, Fd, y, c, ytmp, dy, ws)
    fd, _ = normal_at(code, p, Fd, y, d, ytmp, dy, ws)
    for _ in range(DIP_REFINE):
        if fc < fd:
            b, d, fd = d, c, fc
            c = a + _GOLDEN * (b - a)
            fc, _ = normal_at(code, p, Fd, y, c, ytmp, dy, ws)
        else:
            a, c, fc = c, d, fd
            d = b - _GOLDEN * (b - a)
            fd, _ = normal_at(code, p, Fd, y, d, ytmp, dy, ws)
    evals += DIP_REFINE + 2
    x_min, n_min = (c, fc) if fc < fd else (d, fd)
    if n_min > best_n:
        x_min, n_min = best_x, best_n
    found[0], found[1] = t + x_min * h, n_min
    return evals


@kernel
def event_root(
    ev_code: int,
    code: int,
    Fd: FloatArray,
    y: FloatArray,
    lo: float,
    hi: float,
    ytmp: FloatArray,
) -> float:
    """Fraction ``x`` in ``[lo, hi]`` of the step where the event function changes sign (once),
    by bisection on the dense output (60 halvings: to the resolution of the interpolant)."""
    dense_eval(Fd, y, lo, ytmp)
    g_lo = event_value(ev_code, code, ytmp)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        dense_eval(Fd, y, mid, ytmp)
        g = event_value(ev_code, code, ytmp)
        if (g > 0.0) == (g_lo > 0.0) and g != 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@kernel
def event_turn(
    ev_code: int, code: int, Fd: FloatArray, y: FloatArray, sign: float, ytmp: FloatArray
) -> float:
    """Inside a step whose ends have the event function's sign ``sign``, the fraction ``x``
    where it comes closest to zero on the dense output, or a point past zero: sampled at
    :data:`DIP_SAMPLES` - 1 interior points (any of the other sign is returned at once), the
    best refined by golden sections. The caller reads the sign there."""
    best_x, best = 0.0, math.inf
    for j in range(1, DIP_SAMPLES):
        x = j / DIP_SAMPLES
        dense_eval(Fd, y, x, ytmp)
        v = sign * event_value(ev_code, code, ytmp)
        if v <= 0.0:
            return x
        if v < best:
            best_x, best = x, v
    a = max(0.0, best_x - 1.0 / DIP_SAMPLES)
    b = min(1.0, best_x + 1.0 / DIP_SAMPLES)
    c = a + _GOLDEN * (b - a)
    d = b - _GOLDEN * (b - a)
    dense_eval(Fd, y, c, ytmp)
    fc = sign * event_value(ev_code, code, ytmp)
    dense_eval(Fd, y, d, ytmp)
    fd = sign * event_value(ev_code, code, ytmp)
    for _ in range(DIP_REFINE):
        if fc <= 0.0:
            return c
        if fd <= 0.0:
            return d
        if fc < fd:
            b, d, fd = d, c, fc
            c = a + _GOLDEN * (b - a)
            dense_eval(Fd, y, c, ytmp)
            fc = sign * event_value(ev_code, code, ytmp)
        else:
            a, c, fc = c, d, fd
            d = b - _GOLDEN * (b - a)
            dense_eval(Fd, y, d, ytmp)
            fd = sign * event_value(ev_code, code, ytmp)
    return c if fc < fd else d


@kernel
def _record_event(
    ev_code: int,
    code: int,
    p: FloatArray,
    Fd: FloatArray,
    y: FloatArray,
    t: float,
    h: float,
    lo: float,
    hi: float,
    counts: IntArray,
    ev_t: FloatArray,
    ev_y: FloatArray,
    ytmp: FloatArray,
    ws: Workspace,
) -> None:
    """Locate the zero in ``[lo, hi]`` of the step and record its time and projected state
    (only counted once the capacity is full)."""
    m = counts[N_EVENTS]
    if m < ev_t.shape[0]:
        x = event_root(ev_code, code, Fd, y, lo, hi, ytmp)
        ev_t[m] = t + x * h
        dense_eval(Fd, y, x, ev_y[m])
        project(code, p, ev_y[m], ws)
    counts[N_EVENTS] += 1


@kernel
def step_events(
    code: int,
    p: FloatArray,
    K: FloatArray,
    Fd: FloatArray,
    y: FloatArray,
    ynew: FloatArray,
    t: float,
    h: float,
    y_acc: FloatArray,
    ctrl: FloatArray,
    counts: IntArray,
    ev_spec: IntArray,
    ev_t: FloatArray,
    ev_y: FloatArray,
    ytmp: FloatArray,
    ws: Workspace,
    dense_ready: bool,
) -> bool:
    """The zeros of the event function inside the accepted step ``[t, t + h]`` from ``y``
    (``y_acc``: the accepted, projected new state), in the direction asked, recorded in time
    order. A sign change between the ends is one zero. Ends of one sign hide two zeros where
    the function turns back inside the step: the parabola through its values at the last three
    step ends (:func:`.dip_predicted`) says when a turn lies inside, and the dense output then
    finds how close to zero it comes (:func:`event_turn`) and, past it, both zeros. Returns
    whether the dense output is built. Limits: one pair per step; none in the step right after
    a crossing (the parabola through values of both signs predicts no turn back); a turn that
    touches zero exactly is no crossing (a step that ends on zero is one)."""
    ev_code, direction = ev_spec[EV_CODE], ev_spec[EV_DIRECTION]
    g_new = event_value(ev_code, code, y_acc)
    g_old = ctrl[G_OLD]
    crossed = (g_old < 0.0 and g_new >= 0.0) or (g_old > 0.0 and g_new <= 0.0)
    sign = 1.0 if g_old > 0.0 else -1.0
    if crossed:
        rising = g_new > g_old
        if direction == 0 or (direction > 0) == rising:
            if not dense_ready:
                prepare_dense(code, p, K, y, ynew, h, ytmp, Fd, ws)
                counts[NFEV] += 3
                dense_ready = True
            _record_event(ev_code, code, p, Fd, y, t, h, 0.0, 1.0, counts, ev_t, ev_y, ytmp, ws)
    elif g_old != 0.0 and dip_predicted(
        ctrl[EV_PREV_T], sign * ctrl[EV_PREV_G], t, sign * g_old, t + h, sign * g_new
    ):
        if not dense_ready:
            prepare_dense(code, p, K, y, ynew, h, ytmp, Fd, ws)
            counts[NFEV] += 3
            dense_ready = True
        x = event_turn(ev_code, code, Fd, y, sign, ytmp)
        dense_eval(Fd, y, x, ytmp)
        if sign * event_value(ev_code, code, ytmp) < 0.0:  # two zeros: away, then back
            if direction == 0 or (direction > 0) == (sign < 0.0):
                _record_event(ev_code, code, p, Fd, y, t, h, 0.0, x, counts, ev_t, ev_y, ytmp, ws)
            if direction == 0 or (direction > 0) == (sign > 0.0):
                _record_event(ev_code, code, p, Fd, y, t, h, x, 1.0, counts, ev_t, ev_y, ytmp, ws)
    ctrl[EV_PREV_T], ctrl[EV_PREV_G] = t, g_old
    ctrl[G_OLD] = g_new
    return dense_ready
