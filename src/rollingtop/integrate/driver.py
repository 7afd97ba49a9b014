"""Validated entry point of the compiled integrator."""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, NamedTuple, TypedDict

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import _dop853 as dop
from rollingtop._compiled import compiling, for_code, packages_of
from rollingtop._compiled._dop853_dense import dense_eval
from rollingtop._compiled._dop853_stages import dense_stage, scaled_errors, step_stage
from rollingtop._compiled._events import EVENTS, NONE
from rollingtop._compiled._kernel import frame_rates, reaction, workspace
from rollingtop._errors import IntegrationError, NotFiniteAtStart
from rollingtop._jit import call
from rollingtop._layout import N_PARAMS, N_STATE, WARMUP_PARAMS
from rollingtop._types import FloatArray, IntArray
from rollingtop.contact import DEFAULT_MODEL, ContactModel
from rollingtop.integrate import _compile_helper
from rollingtop.integrate._held import held_arrays
from rollingtop.integrate._pace import check_pace
from rollingtop.integrate._rows import Rows, loop_args, work_arrays

__all__ = ["IntegrationResult", "StepReactions", "integrate", "compile_code", "compile_kernels"]

#: Accepted steps per call of the compiled loop (tens of milliseconds). Between calls the driver
#: is back in Python: the progress callback runs and so do signal handlers (Ctrl-C, SIGTERM;
#: :mod:`rollingtop._signals`). Resuming does not change the step sequence.
PROGRESS_CHUNK = 20_000

#: Seconds each compiled package's integrator took to compile or load in this process.
_compiled: dict[tuple[str, bool, bool], float] = {}


class StepReactions(TypedDict, total=False):
    """Contact reactions monitored at every accepted step (:attr:`IntegrationResult.reactions`,
    :attr:`rollingtop.Trajectory.step_reactions`)."""

    min_normal_force: float
    t_min_normal_force: float
    contact_lost_at: float | None
    max_friction_ratio: float
    t_max_friction_ratio: float


@dataclass
class IntegrationResult:
    """Samples and statistics of one integration.

    Attributes
    ----------
    t : ndarray, shape (n,)
    y : ndarray, shape (n, 18)
        States at ``t``, each projected onto the constraint manifold.
    steps, rejected_steps, rhs_evals : int
    wall_time_s : float
        Time spent in the compiled loop (compilation excluded).
    compile_time_s : float
        Time this call spent compiling or loading the cached kernels (0 once they are loaded).
    reactions : StepReactions
        ``min_normal_force`` and ``t_min_normal_force``, ``contact_lost_at`` (first accepted step
        with negative normal force, or ``None``), ``max_friction_ratio`` and its time, monitored at
        every accepted step.
    event_t : ndarray, shape (k,)
        Times of the located events (empty without ``events``).
    event_y : ndarray, shape (k, 18)
        States at the events, projected onto the constraints.
    events_dropped : int
        Events found beyond ``max_events`` (not stored).
    projection_passes, projection_deferred : int
        With ``project_integrals``: the projection's passes over the run (Newton iterations:
        one per accepted step for the linear integrals, one more per step that moved a
        nonlinear one) and the steps at which it left the energy for the next ones (a turning
        point, where no velocity direction changes it).
    monitor_evals : int
        Right-hand sides evaluated to find the normal force's minima inside steps (not in
        ``rhs_evals``, the integration's own).
    """

    t: FloatArray
    y: FloatArray
    steps: int
    rejected_steps: int
    rhs_evals: int
    wall_time_s: float
    compile_time_s: float
    reactions: StepReactions = field(default_factory=StepReactions)
    event_t: FloatArray = field(default_factory=lambda: np.empty(0))
    event_y: FloatArray = field(default_factory=lambda: np.empty((0, N_STATE)))
    events_dropped: int = 0
    projection_passes: int = 0
    projection_deferred: int = 0
    monitor_evals: int = 0


def compile_kernels(model: str | ContactModel = DEFAULT_MODEL, *, variants: bool = False) -> float:
    """Compile (or load from numba's cache) ``model``'s integrator kernels -- its projection,
    plain stepper and diagnostics -- and no other model's; returns the seconds spent (the event
    and held steppers compile on their first run: :func:`compile_code`).

    ``variants``: also the kernels of the model's variants (the meridian model's pole cases,
    a package of their own: :data:`rollingtop._compiled.GROUPS`). Only the first call for a
    package in a process does work; later calls return 0. When numba compiles (its cache holds
    nothing for them yet) the compiled core's notifier says so first
    (:func:`rollingtop._compiled.compiling`).
    """
    return sum(_compile_package(kernels) for kernels in packages_of(model, variants=variants))


def compile_code(code: int, *, held: bool = False, events: bool = False) -> float:
    """:func:`compile_kernels` for the package that runs kernel code ``code`` (a model's own, or
    its variants'); ``held``: the stepper that holds integrals by projection instead of the plain
    one (``project_integrals``: a separate compile, so that a run without it never pays for it);
    ``events``: the stepper that locates events (the held one does too); seconds spent."""
    return _compile_package(for_code(int(code)), held, events)


def _warmup_state() -> FloatArray:
    """The state of :func:`compile_code`'s warm-up run: the axis tilted, so that no model is
    singular."""
    y = np.zeros(N_STATE)
    y[6:15] = (1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8)
    y[3:6] = (0.1, 0.2, 0.3)
    return y


class _Warmup(NamedTuple):
    """What compiles a package's integrator (:func:`compile_code`, :func:`_warmup`)."""

    #: Compiles (or loads) all but the stepper's loop: the right-hand side and the constraint
    #: projection (which the loop calls) and the samples' diagnostics (a helper's half).
    rest: Callable[[], None]
    #: Runs the warm-up run (compiles the loop, loads the rest).
    loop: Callable[[], None]
    #: The stepper copy's ``run_rows`` dispatcher and its argument types in the warm-up run;
    #: computed once.
    signature: Callable[[], tuple[Any, tuple[Any, ...]]]
    #: The compile's key in ``_compiled`` and of its helper.
    key: tuple[str, bool, bool]


def _warmup(kernels: ModuleType, held: bool, events: bool) -> _Warmup:
    """The warm-up of ``kernels``' integrator: the plain stepper, the held one (``held``) or the
    one that locates events (``events``)."""
    p = np.array(WARMUP_PARAMS)
    y = _warmup_state()
    code = kernels._dispatch.CODES[0]
    # with a projection onto an integral (held): the held stepper's loop
    event = (1, 0, 1) if events or held else (0, 0, 0)
    held_codes = np.array([0], dtype=np.int64) if held else None
    t_eval = np.array([0.0, 1e-3])

    def rest() -> None:
        # the right-hand side first: the loop compiled beside it (by another process) calls it
        # soonest, after the shared pieces (:func:`compile_shared`); then the projection
        call(kernels.dynamics.rhs, code, p, y.copy(), np.zeros(N_STATE), workspace())
        call(kernels.dynamics.project, code, p, y, workspace())  # y on the constraints
        call(kernels.dynamics.diagnostics, code, p, y[None, :].copy(), np.zeros((1, 8)))

    def loop() -> None:
        _run_compiled(code, p, y, t_eval, 1e-6, 1e-9, None, None, event, held_codes)

    @functools.cache
    def signature() -> tuple[Any, tuple[Any, ...]]:
        stepper, args, _ = _stepper_calls(
            code, p, _warmup_state(), t_eval, 1e-6, 1e-9, event, held_codes
        )
        return stepper.run_rows, tuple(stepper.run_rows.typeof_pyval(a) for a in args(1))

    return _Warmup(rest, loop, signature, (kernels.PACKAGE, held, events))


def _helped(warm: _Warmup) -> bool:
    """Start the helper of a cold compile (:mod:`._compile_helper`) doing ``warm.rest``, unless
    one runs, the loop is compiled or cached, or no helper may run here; whether a helper runs.
    A helper of another package is stopped."""
    if warm.key in _compiled:
        return False
    if _compile_helper.running(warm.key):
        return True
    if not _compile_helper.may_fork():  # before numba is loaded: a refused file stays quick
        return False
    run, sig = warm.signature()
    if not _compile_helper.eligible(run) or _compile_helper.cached(run, sig):
        return False
    _compile_helper.stop_others(warm.key)
    return _compile_helper.start(warm.key, warm.rest)


def compile_shared() -> None:
    """Compile (or load) the pieces of the stepper's loop that every model shares, for the
    loop's argument types: the stage sums, error estimates, dense output, reaction tracking
    and the frame's kinematics (compiled once per cache, loaded in milliseconds after)."""
    w = work_arrays()
    K, Fd, ws, y, t, x = w["K"], w["Fd"], w["ws"], w["ynew"], 0.0, 0.5
    track = np.zeros(dop.N_TRACK)
    pieces: tuple[tuple[Any, tuple[Any, ...]], ...] = (
        (step_stage, (K, 1, y, x, y)),
        (dense_stage, (K, 13, y, x, y)),
        (scaled_errors, (K, y, y, x, x, y, y)),
        (dense_eval, (Fd, y, x, y)),
        (reaction, (1, y, ws)),
        (frame_rates, (y, y)),
        (dop.reset_track, (track,)),
        (dop.update_track, (track, t, x, x)),
        (dop.dip_predicted, (t, x, t, x, t, x)),
    )
    for func, args in pieces:  # numba dispatchers (typed here as their Python functions)
        call(func.compile, tuple(func.typeof_pyval(a) for a in args))


def _compile_loop(warm: _Warmup) -> None:
    """Compile the stepper's loop here while the helper compiles the rest; the helper is
    stopped if this fails or is interrupted. The shared pieces of the loop come first
    (:func:`compile_shared`): meanwhile the helper saves the right-hand side, which the loop
    then loads instead of compiling it again."""
    run, sig = warm.signature()
    try:
        compile_shared()
        call(run.compile, sig)
    except BaseException:
        _compile_helper.stop(warm.key)
        raise


def compile_ahead(code: int) -> None:
    """Compile the stepper's loop of the plain integrator of the package that runs kernel
    ``code`` while a helper process compiles the rest (the right-hand side, the constraint
    projection, the diagnostics), where the package is cold and a helper
    may run (:mod:`._compile_helper`); else nothing. For a command about to project an initial
    state and then run it: registered with :func:`rollingtop._compiled.run_before_projection`,
    it runs after the state's checks (a bad file is refused before numba loads), and the
    projection then loads what the helper saved; the run's :func:`compile_code` waits for the
    helper and loads the rest."""
    warm = _warmup(for_code(int(code)), held=False, events=False)
    if _helped(warm):
        _compile_loop(warm)


def _compile_package(kernels: ModuleType, held: bool = False, events: bool = False) -> float:
    """:func:`compile_kernels` for one compiled package (``held``, ``events``:
    :func:`compile_code`). A cold compile (the stepper's loop neither in memory nor in numba's
    cache) leaves the right-hand side, the projection and the diagnostics to a forked helper
    where one may run (:mod:`._compile_helper`), while this process compiles the loop."""
    events = events and not held  # the held stepper locates events too
    warm = _warmup(kernels, held, events)
    if warm.key in _compiled:
        return 0.0
    start = time.perf_counter()
    what = "held integrator" if held else "event integrator" if events else "integrator"
    with compiling(kernels, what):
        if _helped(warm):
            _compile_loop(warm)
            _compile_helper.join(warm.key)
        warm.rest()
        warm.loop()
    _compiled[warm.key] = time.perf_counter() - start
    return _compiled[warm.key]


def _stepper_calls(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    event: tuple[int, int, int],
    held: IntArray | None = None,
    dips: bool = True,
) -> tuple[
    ModuleType,
    Callable[[int], tuple[Any, ...]],
    tuple[Rows, FloatArray, FloatArray, FloatArray],
]:
    """The copy of the stepper a run needs (:mod:`rollingtop._compiled._instances`), a function
    of a step budget giving the arguments of its ``run_rows`` for one row (started from ``y0``
    by the first call, resumed by the next ones, up to ``budget`` more accepted steps each), and
    the arrays the run fills: the row, its samples (shape (1, n, 18)), the events' times and
    states."""
    n = t_eval.shape[0]
    w = work_arrays()
    icodes, targets, pw = held_arrays(code, p, y0, held)
    package = for_code(code)
    ev_code, ev_direction, capacity = event
    stepper = (
        package.stepper_held
        if icodes.shape[0] > 0
        else package.stepper_events
        if ev_code != NONE
        else package.stepper
    )
    ev_spec = np.array([ev_code, ev_direction, int(dips)], dtype=np.int64)
    # np.empty: the pages of a large capacity are touched only by events actually found
    ev_t = np.empty(capacity)
    ev_y = np.empty((capacity, N_STATE))
    row = Rows.of(y0[None, :])
    out = np.full((1, n, N_STATE), np.nan)
    codes = np.array([code], dtype=np.int64)
    P = np.ascontiguousarray(p[None, :])
    stop = np.zeros(1, dtype=np.int64)  # the driver stops between calls instead

    def run_args(budget: int) -> tuple[Any, ...]:
        limit = int(row.COUNTS[0, dop.STEPS]) + budget
        return loop_args(codes, P, row, t_eval, out, (rtol, atol), (ev_spec, ev_t, ev_y),
                         (limit, budget), w, (icodes, targets, pw), stop)  # fmt: skip

    return stepper, run_args, (row, out, ev_t, ev_y)


def _run_compiled(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int | None,
    progress: Callable[[float], None] | None,
    event: tuple[int, int, int],
    held: IntArray | None = None,
    dips: bool = True,
) -> tuple[FloatArray, IntArray, FloatArray, float, tuple[FloatArray, FloatArray, int]]:
    stepper, run_args, (row, out, ev_t, ev_y) = _stepper_calls(
        code, p, y0, t_eval, rtol, atol, event, held, dips
    )
    ctrl, counts, track = row.CTRL[0], row.COUNTS[0], row.TRACK[0]
    t_end = float(t_eval[-1])
    start = time.perf_counter()
    while True:
        budget = PROGRESS_CHUNK
        if max_steps is not None:
            budget = min(budget, max_steps - int(counts[dop.STEPS]))
        call(stepper.run_rows, *run_args(budget))
        status = int(row.STATUS[0])
        if progress is not None:
            progress(float(ctrl[dop.T]))
        if status != dop.BUDGET_EXHAUSTED:
            break
        if max_steps is not None:
            check_pace(
                float(t_eval[0]), float(ctrl[dop.T]), t_end, int(counts[dop.STEPS]), max_steps
            )
        if max_steps is not None and counts[dop.STEPS] >= max_steps:
            raise IntegrationError(
                f"max_steps = {max_steps} accepted steps reached at t = {ctrl[dop.T]:.6g} "
                f"before t_end = {t_end:g}; raise max_steps or loosen rtol"
            )
    wall = time.perf_counter() - start
    _raise_for_status(status, ctrl, counts)
    found = int(counts[dop.N_EVENTS])
    kept = min(found, ev_t.shape[0])
    return out[0], counts, track, wall, (ev_t[:kept].copy(), ev_y[:kept].copy(), found - kept)


def _raise_for_status(status: int, ctrl: FloatArray, counts: IntArray) -> None:
    """:class:`IntegrationError` (one line) for a status of the stepper's ``run_rows`` that ends
    a run early."""
    t, h = float(ctrl[dop.T]), float(ctrl[dop.H_ABS])
    if status == dop.STEP_TOO_SMALL and np.isnan(h):
        raise IntegrationError(
            f"no initial step size at t = {t:.9g}: the state or its derivative, scaled by the "
            f"tolerances (atol = {ctrl[dop.ATOL]:.3g}, rtol = {ctrl[dop.RTOL]:.3g}), overflows"
        )
    if status == dop.STEP_TOO_SMALL:
        raise IntegrationError(
            f"step size underflow at t = {t:.9g} (h = {h:.3g}): "
            "the equations are singular or the tolerance is too tight"
        )
    if status == dop.NOT_FINITE:
        if counts[dop.STEPS] == 0 and counts[dop.REJECTED] == 0:
            raise NotFiniteAtStart(
                f"the initial state or its derivative is not finite at t = {t:.9g} "
                "(initial values too large?)"
            )
        raise IntegrationError(
            f"the state (or every trial step from it) became non-finite at t = {t:.9g} "
            "(for the meridian model: the symmetry axis reached the vertical?)"
        )
    if status == dop.PROJECTION_FAILED:
        raise IntegrationError(
            f"the projection onto the integrals' level set gave a non-finite state at "
            f"t = {t:.9g}: the integrals' gradients are degenerate there"
        )
    if status == dop.TOO_MANY_REJECTED:
        raise IntegrationError(
            f"{dop.MAX_REJECTED_IN_A_ROW} rejected steps in a row at t = {t:.9g} (h = {h:.3g}): "
            "the tolerance is too tight or the equations are singular"
        )


def integrate(
    code: int,
    params: ArrayLike,
    y0: ArrayLike,
    t_eval: ArrayLike,
    *,
    rtol: float,
    atol: float,
    max_steps: int | None = None,
    progress: Callable[[float], None] | None = None,
    events: str | None = None,
    event_direction: int = 0,
    max_events: int = 100_000,
    project_integrals: tuple[str, ...] = (),
    locate_dips: bool = True,
) -> IntegrationResult:
    """Integrate the constrained equations from ``y0`` at ``t_eval[0]`` to ``t_eval[-1]``.

    Parameters
    ----------
    code : int
        Kernel code (:class:`rollingtop.contact.Kernel`): ``model.kernel(body, y0).code``, the
        model's own or the variant it picks for this state.
    params : ndarray, shape (9,)
        ``SphericalTop.params`` (:data:`~rollingtop._layout.N_PARAMS` entries).
    y0 : ndarray, shape (18,)
        Constraint-consistent initial state (:func:`rollingtop.dynamics.state.initial_state`).
    t_eval : ndarray, shape (n,)
        Strictly increasing sample times, ``n >= 2``; the integration spans them.
    rtol, atol : float
        Tolerances of the error control (mixed, per component: ``atol + rtol |y|``).
    max_steps : int, optional
        Bound on accepted steps; :class:`IntegrationError` when reached. Rejected attempts are
        bounded separately: :data:`~._dop853.MAX_REJECTED_IN_A_ROW` in a row end the run.
    progress : callable, optional
        Called with the current time every :data:`PROGRESS_CHUNK` steps and at the end. Does
        not change the step sequence.

    Raises
    ------
    IntegrationError
        When ``t_eval[-1]`` cannot be reached, with one line saying why: ``max_steps`` reached, a
        non-finite state or derivative (also at the start, e.g. from huge initial values), a
        step size below ten units in the last place of ``t``, or too many rejected steps in a
        row. Every run ends after finitely many attempted steps.
    KeyboardInterrupt
        Signal handlers (Ctrl-C) run between calls of the compiled loop, every
        :data:`PROGRESS_CHUNK` accepted steps, whether or not ``progress`` is given.
    events : str, optional
        Name of an event function (``"w_tau"``: zeros of ``w_tau``, the turning points of
        ``gamma3``) whose zeros are located on the dense output of each step.
    event_direction : int
        ``+1``: only rising zeros, ``-1``: only falling, ``0``: both.
    max_events : int
        Events stored at most (further ones are counted in ``events_dropped``).
    project_integrals : tuple of str
        Integrals (names of :data:`rollingtop.dynamics.integrals.INTEGRALS`) held at their
        values at ``y0`` by a projection of the velocity after every accepted step
        (:mod:`rollingtop._compiled._template.invariants`); empty: none.
    locate_dips : bool
        Locate the normal force's minima inside steps on the dense output (default): the
        reported minimum normal force, largest friction ratio and loss of contact then hold
        between step ends too (:func:`rollingtop._compiled._dop853.dip_predicted`; about a
        tenth more right-hand sides on the paper's motions, ``monitor_evals``). ``False``
        monitors the reactions at step ends only, as the C limit (``benchmarks/c_limit.py``)
        does; a run without dips pays one comparison a step for the search.
    """
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    y0 = np.ascontiguousarray(y0, dtype=float)
    if t_eval.ndim != 1 or t_eval.size < 2 or np.any(np.diff(t_eval) <= 0):
        raise ValueError("t_eval must be strictly increasing with at least 2 entries")
    if not np.all(np.isfinite(t_eval)):
        raise ValueError("t_eval must be finite")
    if y0.shape != (N_STATE,):
        raise ValueError(f"y0 must have shape ({N_STATE},), got {y0.shape}")
    params = np.ascontiguousarray(params, dtype=float)
    if params.shape != (N_PARAMS,):  # the kernels do not check their reads
        raise ValueError(f"params must have shape ({N_PARAMS},), got {params.shape}")
    if events is not None and events not in EVENTS:
        raise ValueError(f"unknown event {events!r} (known: {', '.join(EVENTS)})")
    if event_direction not in (-1, 0, 1):
        raise ValueError(f"event_direction must be -1, 0 or 1, got {event_direction!r}")
    event = (EVENTS[events], event_direction, max(int(max_events), 1)) if events else (NONE, 0, 1)
    from rollingtop._compiled._integrals import CODES

    unknown = [n for n in project_integrals if n not in CODES]
    if unknown:
        raise ValueError(f"no compiled integral {unknown[0]!r} (known: {', '.join(CODES)})")
    held = np.array([CODES[n] for n in project_integrals], dtype=np.int64)
    compile_s = compile_code(code, held=held.shape[0] > 0, events=event[0] != 0)
    out, counts, track, wall, (ev_t, ev_y, dropped) = _run_compiled(
        int(code),
        params,
        y0,
        t_eval,
        float(rtol),
        float(atol),
        max_steps,
        progress,
        event,
        held if held.size else None,
        bool(locate_dips),
    )
    return IntegrationResult(
        t=t_eval,
        y=out,
        steps=int(counts[dop.STEPS]),
        rejected_steps=int(counts[dop.REJECTED]),
        rhs_evals=int(counts[dop.NFEV]),
        wall_time_s=wall,
        compile_time_s=compile_s,
        reactions={
            "min_normal_force": float(track[dop.MIN_NORMAL]),
            "t_min_normal_force": float(track[dop.T_MIN_NORMAL]),
            "contact_lost_at": None
            if np.isnan(track[dop.T_CONTACT_LOST])
            else float(track[dop.T_CONTACT_LOST]),
            "max_friction_ratio": float(track[dop.MAX_RATIO]),
            "t_max_friction_ratio": float(track[dop.T_MAX_RATIO]),
        },
        event_t=ev_t,
        event_y=ev_y,
        events_dropped=dropped,
        projection_passes=int(counts[dop.PROJ_PASSES]),
        projection_deferred=int(counts[dop.PROJ_DEFERRED]),
        monitor_evals=int(counts[dop.MONITOR_EVALS]),
    )
