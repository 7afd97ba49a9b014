"""Compiled DOP853 stepper with after-step projection, dense output and reaction monitoring.

The method is Dormand & Prince's explicit Runge-Kutta pair of order 8(5,3) with its 7th-order
continuous extension (Hairer, Norsett & Wanner, *Solving ODEs I*, Sec. II.10), with the step-size
control of Hairer's ``dop853.f`` as also used by ``scipy.integrate.DOP853``: the error norm
combines the 5th- and 3rd-order estimates, safety factor 0.9, step ratio in [0.2, 10].

Why a stepper of our own rather than CyRK's ``nbsolve_ivp`` or numbalsoda (both evaluated): after
every accepted step the state must be projected back onto the constraint manifold (orthonormal
frame, velocity on the constraints), the dense output must be built from the step's own stages,
the contact reaction must be monitored at every step, and later work needs events and one
stepper per thread in parallel ensembles. Neither library exposes an after-step hook, and
numbalsoda's LSODA/DOP853 wrappers offer no dense output or events; the method itself is short.

The stepper itself calls the contact model's right-hand side at every stage, so it is compiled
per model (:mod:`rollingtop._compiled`; written once in
:mod:`rollingtop._compiled._template.stepper`). This module holds what every model's stepper
shares: the status codes, the layout of the control arrays, the step-size constants and the
reaction tracking. The stages come from generated code (:mod:`._dop853_stages`).
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._jit import kernel
from rollingtop._types import FloatArray

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
ERROR_EXPONENT = -1.0 / 8.0

# Status codes of each row of the stepper's loop (``run_rows``: a single run's one row, an
# ensemble's trajectories): >= 0 the run may go on (or is done), < 0 it cannot reach ``t_end``.
FINISHED = 0
#: The step budget of this call is spent (the caller resumes, or reports ``max_steps``).
BUDGET_EXHAUSTED = 1
#: A trajectory stopped (or never started) on a stop request.
INTERRUPTED = 2
#: A row still advancing, inside the loop; never reported.
RUNNING = 3
#: The step size fell below ten units in the last place of ``t``, or is zero or NaN (no initial
#: step: the scaled norm of the state or its derivative overflows).
STEP_TOO_SMALL = -1
#: The state or its derivative is not finite (at an accepted step, or when ``run_rows`` is entered),
#: or ``MAX_REJECTED_IN_A_ROW`` steps in a row were rejected with a non-finite error estimate.
NOT_FINITE = -2
#: ``MAX_REJECTED_IN_A_ROW`` steps in a row were rejected by the error control.
TOO_MANY_REJECTED = -3
#: The projection onto the integrals' level set gave a non-finite state.
PROJECTION_FAILED = -4

#: Short descriptions of the status codes (the ensemble reports them per trajectory).
STATUS_NAMES = {
    FINISHED: "finished",
    BUDGET_EXHAUSTED: "max_steps reached",
    INTERRUPTED: "interrupted",
    STEP_TOO_SMALL: "step size underflow",
    NOT_FINITE: "non-finite state",
    TOO_MANY_REJECTED: "too many rejected steps in a row",
    PROJECTION_FAILED: "projection onto the integrals failed",
}

#: Rejected attempts in a row after which a run gives up. After a rejection the next attempt is
#: at most 0.9 times as long and usually far shorter (the error scales as ``h**8``), so a sound
#: step needs a handful; a hundred in a row (the step shrunk by at least ``0.9**100 ~ 3e-5``)
#: means the error control cannot meet the tolerance here (too tight, or a singular point).
MAX_REJECTED_IN_A_ROW = 100

# Indices into the float control array ``ctrl``: the event function at ``t`` (``G_OLD``) and,
# for the pairs of crossings inside one step, the one before it (``EV_PREV_G`` at ``EV_PREV_T``).
T, H_ABS, T_END, RTOL, ATOL, G_OLD, EV_PREV_T, EV_PREV_G = 0, 1, 2, 3, 4, 5, 6, 7
# Indices into the integer counter array ``counts``: the projection's passes and the steps at
# which it left a nonlinear integral (the energy at a turning point) for the next ones, then the
# right-hand sides spent on monitoring the normal force inside steps (not in ``NFEV``, which
# counts the integration's own).
NEXT_SAMPLE, STEPS, REJECTED, NFEV, N_EVENTS, PROJ_PASSES, PROJ_DEFERRED = 0, 1, 2, 3, 4, 5, 6
MONITOR_EVALS = 7
#: Length of ``counts``.
N_COUNTS = 8
# Indices into the integer specification ``ev_spec``: the event function's code and direction,
# and whether the normal force's minima inside steps are located (``dip_predicted``; a run that
# does not locate them pays one comparison a step for it).
EV_CODE, EV_DIRECTION, EV_DIPS = 0, 1, 2
#: Length of ``ev_spec``.
N_EV_SPEC = 3
# Indices into the reaction-tracking array ``track``: the normal force at the last accepted step
# and, for the dips between steps, the one before it (``PREV_NORMAL`` at ``PREV_T``).
MIN_NORMAL, T_MIN_NORMAL, T_CONTACT_LOST, MAX_RATIO, T_MAX_RATIO, LAST_NORMAL = 0, 1, 2, 3, 4, 5
PREV_T, PREV_NORMAL = 6, 7


#: Length of ``track``.
N_TRACK = 8
#: Length of ``ctrl``.
N_CTRL = 8


@kernel
def reset_track(track: FloatArray) -> None:
    """Reaction tracking from scratch, in ``track`` (shape (:data:`N_TRACK`,)): min normal force
    and when, first time it is < 0, max ratio and when, the normal force at the last accepted
    step, the time and normal force of the one before."""
    track[MIN_NORMAL] = np.inf
    track[T_MIN_NORMAL] = np.nan
    track[T_CONTACT_LOST] = np.nan
    track[MAX_RATIO] = 0.0
    track[T_MAX_RATIO] = np.nan
    track[LAST_NORMAL] = np.nan
    track[PREV_T] = np.nan
    track[PREV_NORMAL] = np.nan


@kernel
def dip_predicted(t0: float, n0: float, t1: float, n1: float, t2: float, n2: float) -> bool:
    """Whether the parabola through the normal force at the last three step ends ``t0 < t1 <
    t2`` has its minimum inside the last step ``(t1, t2)``: the force may dip there below both
    ends, which the dense output then resolves (:func:`.dense.dip_minimum`; the same test finds
    the extrema of an event function, :func:`.dense.step_events`)."""
    if not (math.isfinite(t0) and math.isfinite(n0)):
        return False
    d1 = (n1 - n0) / (t1 - t0)
    d2 = (n2 - n1) / (t2 - t1)
    a = (d2 - d1) / (t2 - t0)  # half the second derivative
    if not a > 0.0:
        return False
    vertex = 0.5 * (t1 + t2) - 0.5 * d2 / a  # where the parabola's slope vanishes
    return t1 < vertex < t2


@kernel
def update_track(track: FloatArray, t: float, N: float, T_force: float) -> None:
    """Fold one evaluation of the contact force into ``track``."""
    if N < track[MIN_NORMAL]:
        track[MIN_NORMAL] = N
        track[T_MIN_NORMAL] = t
    if N < 0.0 and math.isnan(track[T_CONTACT_LOST]):
        track[T_CONTACT_LOST] = t
    if N > 0.0:
        ratio = T_force / N
        if ratio > track[MAX_RATIO]:
            track[MAX_RATIO] = ratio
            track[T_MAX_RATIO] = t
