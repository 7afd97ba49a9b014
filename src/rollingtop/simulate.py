"""One entry point for simulations: :func:`simulate`.

It takes typed objects, ``simulate(body, model, state, options)``, or a scenario (a
:class:`~rollingtop.scenario.Scenario` or the path of its TOML file) that holds them. Keyword
options replace single integration options in either form.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import (
    ContactLostWarning,
    InitialStateError,
    NotFiniteAtStart,
    ScenarioError,
)
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop.body import OVERFLOW_DECADES, SphericalTop, largest_input
from rollingtop.contact import ContactModel, get_model, models_for
from rollingtop.dynamics.start import InitialConditions
from rollingtop.dynamics.state import UNIT_TOLERANCE, constraint_residuals, project_state
from rollingtop.integrate import integrate
from rollingtop.integrate.options import IntegrationOptions
from rollingtop.scenario import Scenario, check_model_name, load_scenario
from rollingtop.trajectory import Trajectory

__all__ = ["simulate", "simulate_models", "switch_model"]

ScenarioLike = Scenario | str | os.PathLike[str]


def _model(model: ContactModel | str) -> ContactModel:
    if isinstance(model, ContactModel):
        return model
    return get_model(check_model_name("model", model))


def switch_model(
    scenario: Scenario, model: ContactModel | str
) -> tuple[Scenario, NDArray[np.float64]]:
    """The scenario's initial state under another contact model, as :func:`simulate_models`
    starts it: projected onto ``model``'s constraints
    (:func:`rollingtop.dynamics.state.project_state`: orientation and position kept,
    velocities moved to the nearest admissible ones in the kinetic-energy metric).

    Returns the new scenario (its ``[level]`` dropped: a level belongs to the scenario's own
    model) and the change of the velocities ``(v, omega)``, shape (6,); for the scenario's own
    model, the scenario itself and zeros.
    """
    model = _model(model)
    if model is scenario.model:
        return scenario, np.zeros(6)
    switched = _projected(scenario, model)
    return switched, switched.require_state()[:6] - scenario.require_state()[:6]


def _body_for(model: ContactModel, body: SphericalTop) -> SphericalTop:
    """:meth:`ContactModel.body_for`, its refusal as an :class:`InitialStateError`."""
    try:
        return model.body_for(body)
    except ValueError as err:
        raise InitialStateError(str(err)) from None


def _projected(scenario: Scenario, model: ContactModel) -> Scenario:
    body = _body_for(model, scenario.body)
    y = project_state(body, model, scenario.require_state(), source=scenario.model)
    return replace(scenario, model=model, initial=InitialConditions.from_state(y), level=None)


def _given_state(
    body: SphericalTop, model: ContactModel, state: ArrayLike | InitialConditions
) -> NDArray[np.float64]:
    """The initial state of ``simulate(body, model, state)``: built from initial conditions, or
    a full state vector checked against the model's constraints."""
    if isinstance(state, InitialConditions):
        return state.state(body, model)
    try:
        y = np.array(state, dtype=float)
    except (TypeError, ValueError):
        raise InitialStateError(f"state must be {N_STATE} numbers") from None
    if y.shape != (N_STATE,) or not np.all(np.isfinite(y)):
        raise InitialStateError(f"state must be {N_STATE} finite numbers, got shape {y.shape}")
    if model.own is not None:  # the model's own velocity must agree with v
        projected = y.copy()
        code = model.kernel_code(body, y)
        call(
            for_code(code).dynamics.project,
            code,
            model.params(body),
            projected,
            workspace(),
        )
        gap = float(np.max(np.abs(projected[0:3] - y[0:3])))
        if gap > UNIT_TOLERANCE * max(1.0, float(np.max(np.abs(y[0:6])))):
            raise InitialStateError(
                f"the state's v and its last slot (model {model.name!r}: the shell's spin) "
                f"disagree by {gap:.3g}: build it with initial_state or project_state"
            )
    residuals = constraint_residuals(body, model, y)
    for name, res in zip(model.constraints, residuals, strict=True):
        if abs(res) > UNIT_TOLERANCE:
            raise InitialStateError(
                f"the state violates the constraint {name} of model {model.name!r} (residual "
                f"{res:.3g}, tolerance {UNIT_TOLERANCE:g}): build it with initial_state or "
                "project_state"
            )
    return y


@overload
def simulate(
    source: SphericalTop,
    model: ContactModel | str,
    state: ArrayLike | InitialConditions,
    options: IntegrationOptions | None = None,
    *,
    t_end: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    samples: int | None = None,
    max_steps: int | None = None,
    progress: Callable[[float], None] | None = None,
    events: str | None = None,
    event_direction: int = 0,
    project_integrals: bool | None = None,
) -> Trajectory: ...


@overload
def simulate(
    source: ScenarioLike,
    model: ContactModel | str | None = None,
    state: None = None,
    options: IntegrationOptions | None = None,
    *,
    t_end: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    samples: int | None = None,
    max_steps: int | None = None,
    progress: Callable[[float], None] | None = None,
    events: str | None = None,
    event_direction: int = 0,
    project_integrals: bool | None = None,
) -> Trajectory: ...


def simulate(
    source: SphericalTop | ScenarioLike,
    model: ContactModel | str | None = None,
    state: ArrayLike | InitialConditions | None = None,
    options: IntegrationOptions | None = None,
    *,
    t_end: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    samples: int | None = None,
    max_steps: int | None = None,
    progress: Callable[[float], None] | None = None,
    events: str | None = None,
    event_direction: int = 0,
    project_integrals: bool | None = None,
) -> Trajectory:
    """Integrate a motion and return its :class:`~rollingtop.trajectory.Trajectory`.

    Two forms::

        simulate(body, model, state, options=None, *, t_end=..., ...)   # no file needed
        simulate(scenario, model=None, options=None, *, t_end=..., ...)

    Parameters
    ----------
    source : SphericalTop, Scenario or path
        The body, or a :class:`~rollingtop.scenario.Scenario` (or the path of a TOML scenario
        file) that holds a body, a model, an initial state and integration options.
    model : ContactModel or str
        The contact model (an entry of :data:`rollingtop.contact.MODELS`, or its name). Needed
        with a body. With a scenario, another model than its own projects the scenario's
        initial state onto that model's constraints (:func:`switch_model`).
    state : InitialConditions or array_like, shape (18,)
        The initial state, with a body only: initial conditions (built by
        :meth:`InitialConditions.state`) or a full state vector, which must satisfy the
        model's constraints (build one with :func:`rollingtop.initial_state` or
        :func:`rollingtop.dynamics.state.project_state`).
    options : IntegrationOptions, optional
        Integration options; default :class:`IntegrationOptions` ``()`` with a body, the
        scenario's own with a scenario.
    t_end, rtol, atol, samples, max_steps, project_integrals : optional
        Replace single integration options (``None``: keep); ``project_integrals=True`` holds
        the model's integrals at their initial values by projection
        (:attr:`IntegrationOptions.project_integrals`).
    progress : callable, optional
        Called with the current time now and then during the run (see
        :func:`rollingtop.integrate.integrate`).
    events : str, optional
        Locate the zeros of an event function along the motion (``"w_tau"``: the turning points
        of ``gamma3``); they are in :attr:`Trajectory.event_t` and :attr:`Trajectory.event_y`.
    event_direction : int
        ``+1`` rising zeros only, ``-1`` falling only, ``0`` both.

    Raises
    ------
    RollingTopError
        Inadmissible input (a :class:`ScenarioError` for options, an
        :class:`InitialStateError` for a state, ...).
    IntegrationError
        The integrator could not reach ``t_end``.

    Warns
    -----
    ContactLostWarning
        When the normal reaction turns negative: the motion leaves the model's assumption that the
        contact is kept. The trajectory is still returned, with ``contact_lost_at`` recorded.
    """
    overrides = {
        "t_end": t_end,
        "rtol": rtol,
        "atol": atol,
        "samples": samples,
        "max_steps": max_steps,
        "project_integrals": project_integrals,
    }
    given: dict[str, Any] = {k: v for k, v in overrides.items() if v is not None}
    if isinstance(source, SphericalTop):
        if model is None or state is None:
            raise TypeError("simulate(body, model, state): a body needs a model and a state")
        contact = _model(model)
        source = _body_for(contact, source)
        y0 = _given_state(source, contact, state)
        opts = options if options is not None else IntegrationOptions()
        opts = replace(opts, **given) if given else opts
        return _run(source, contact, y0, opts, progress, events, event_direction)
    if state is not None:
        raise TypeError("simulate(scenario): the scenario holds the state; give none")
    scenario = source if isinstance(source, Scenario) else load_scenario(source)
    if model is not None:
        scenario, _ = switch_model(scenario, model)
    if options is not None:
        scenario = replace(scenario, integration=options)
    scenario = scenario.with_overrides(**given)
    return _run(
        scenario.body,
        scenario.model,
        scenario.require_state(),
        scenario.integration,
        progress,
        events,
        event_direction,
    )


def _run(
    body: SphericalTop,
    model: ContactModel,
    y0: NDArray[np.float64],
    opts: IntegrationOptions,
    progress: Callable[[float], None] | None,
    events: str | None,
    event_direction: int,
) -> Trajectory:
    _check_work(body, y0, opts)
    code = model.kernel_code(body, y0)  # the model's variant for this start (pole cases)
    held: tuple[str, ...] = ()
    if opts.project_integrals:
        if model.own_inertia:
            raise ScenarioError(
                f"integration.project_integrals: not for the {model.name} model "
                "yet (its integrals carry the shell's terms)"
            )
        held = model.integrals_for(body)
    try:
        result = integrate(
            code,
            model.params(body),
            y0,
            opts.t_eval,
            rtol=opts.rtol,
            atol=opts.resolved_atol,
            max_steps=opts.max_steps,
            progress=progress,
            events=events,
            event_direction=event_direction,
            project_integrals=held,
        )
    except NotFiniteAtStart:
        blamed, size = largest_input(body, y0)
        if size < OVERFLOW_DECADES:  # no input far enough from 1 to make a product overflow
            raise
        raise InitialStateError(  # a bad input, named (the reduction's commands say the same)
            f"the derivative of the initial state is not finite at t = {opts.t_eval[0]:.9g}: "
            f"{blamed} overflows double precision in the products of the equations; rescale "
            "the units of the scenario"
        ) from None
    stats = {
        "steps": result.steps,
        "rejected_steps": result.rejected_steps,
        "rhs_evals": result.rhs_evals,
        "wall_time_s": result.wall_time_s,
        "compile_time_s": result.compile_time_s,
    }
    if held:
        stats |= {
            "projection_passes": result.projection_passes,
            "projection_deferred": result.projection_deferred,
        }
    traj = Trajectory(
        body=body,
        model=model,
        t=result.t,
        y=result.y,
        rtol=opts.rtol,
        atol=opts.resolved_atol,
        stats=stats,
        step_reactions=result.reactions,
        event_t=result.event_t,
        event_y=result.event_y,
        kernel_code=code,
    )
    lost = traj.contact_lost_at
    if lost is not None:
        warnings.warn(
            ContactLostWarning(
                f"the normal reaction turns negative at t = {lost:.6g}: the body would leave the "
                f"plane, and the {model.name!r} model (contact kept) no longer applies"
            ),
            stacklevel=3,  # the caller of simulate
        )
    return traj


def _check_work(body: SphericalTop, y0: NDArray[np.float64], opts: IntegrationOptions) -> None:
    """Refuse a run whose fastest time scale makes ``t_end`` need a hundred times ``max_steps``
    steps even at one step per oscillation (issue 27: ``g = 1e50`` ran for hours): the rate is the
    largest of the spin ``|w|``, ``|v| / R``, ``sqrt(g / R)`` and ``sqrt(m g (R + |a3|) /
    I_min)`` (the pendulum of the body about its contact point)."""
    with np.errstate(all="ignore"):
        rate = max(
            float(np.linalg.norm(y0[3:6])),
            float(np.linalg.norm(y0[0:3])) / body.R,
            math.sqrt(body.g / body.R),
            math.sqrt(body.m * body.g * (body.R + abs(body.a3)) / float(np.min(body.inertia))),
        )
    periods = opts.t_end * rate / (2 * math.pi)
    # a hundredfold: a run near its budget reaches max_steps and says so itself; an overflowing
    # state (periods not finite) is the stepper's to report
    if math.isfinite(periods) and periods > 100 * opts.max_steps:
        raise ScenarioError(
            f"t_end = {opts.t_end:g} spans about {periods:.2g} periods of the motion's fastest "
            f"rate ({rate:.3g} per time unit, from the spin, g / R and the inertia): far more than "
            f"max_steps = {opts.max_steps} steps even at one a period; shorten t_end, rescale "
            "the units or raise max_steps"
        )


def simulate_models(
    scenario: ScenarioLike,
    models: Iterable[ContactModel | str] | None = None,
    *,
    t_end: float | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    samples: int | None = None,
    max_steps: int | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> dict[str, Trajectory]:
    """Run the scenario's initial state under several contact models, side by side.

    The scenario's state is projected onto each model's constraints
    (:func:`rollingtop.dynamics.state.project_state`: orientation and position kept, velocities
    moved to the nearest admissible ones in the kinetic-energy metric), so each model starts as
    close as it allows to the same state.

    Parameters
    ----------
    scenario : Scenario or path
    models : iterable of ContactModel or str, optional
        Default: every registered model (:data:`rollingtop.contact.MODELS`), in its order,
        that takes the scenario's body (``shell-rotor`` only with a shell).
    t_end, rtol, atol, samples, max_steps : optional
        Replace the scenario's integration options (as in :func:`simulate`).
    progress : callable, optional
        ``progress(name, t)``: the run of the model ``name`` has reached time ``t``; each run
        goes from 0 to ``t_end`` in turn.

    Returns
    -------
    dict
        ``{model name: Trajectory}``, in the order of ``models``.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    scenario.require_state()
    chosen = [get_model(m) for m in (models_for(scenario.body) if models is None else models)]
    runs = {}
    for model in chosen:
        report = None if progress is None else _tagged(progress, model.name)
        runs[model.name] = simulate(
            _projected(scenario, model),
            t_end=t_end,
            rtol=rtol,
            atol=atol,
            samples=samples,
            max_steps=max_steps,
            progress=report,
        )
    return runs


def _tagged(progress: Callable[[str, float], None], name: str) -> Callable[[float], None]:
    return lambda t: progress(name, t)
