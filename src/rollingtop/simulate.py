"""One entry point for simulations: :func:`simulate`."""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from rollingtop._errors import ContactLostWarning
from rollingtop.contact import ContactModel, get_model
from rollingtop.integrate import integrate
from rollingtop.scenario import InitialConditions, Scenario, check_model_name, load_scenario
from rollingtop.trajectory import Trajectory

__all__ = ["simulate", "simulate_models", "switch_model"]


def switch_model(scenario: Scenario, model) -> tuple[Scenario, np.ndarray]:
    """The scenario's initial state under another contact model, as :func:`simulate_models`
    starts it: projected onto ``model``'s constraints
    (:func:`rollingtop.dynamics.state.project_state`: orientation and position kept,
    velocities moved to the nearest admissible ones in the kinetic-energy metric).

    Returns the new scenario (its ``[level]`` dropped: the reduction is the meridian model's)
    and the change of the velocities ``(v, omega)``, shape (6,); for the scenario's own model,
    the scenario itself and zeros.
    """
    if not isinstance(model, ContactModel):
        model = get_model(check_model_name("model", model))
    if model.name == scenario.model.name:
        return scenario, np.zeros(6)
    switched = _projected(scenario, model)
    return switched, switched.require_state()[:6] - scenario.require_state()[:6]


def _projected(scenario: Scenario, model) -> Scenario:
    from rollingtop.dynamics.state import project_state

    y = project_state(scenario.body, model, scenario.require_state())
    return replace(scenario, model=model, initial=InitialConditions.from_state(y), level=None)


def simulate(
    scenario: Scenario | str | os.PathLike,
    *,
    progress: Callable[[float], None] | None = None,
    events: str | None = None,
    event_direction: int = 0,
    **overrides,
) -> Trajectory:
    """Integrate a scenario and return its :class:`~rollingtop.trajectory.Trajectory`.

    Parameters
    ----------
    scenario : Scenario or path
        A :class:`~rollingtop.scenario.Scenario` or the path of a TOML scenario file.
    progress : callable, optional
        Called with the current time now and then during the run (see
        :func:`rollingtop.integrate.integrate`).
    events : str, optional
        Locate the zeros of an event function along the motion (``"w_tau"``: the turning points
        of ``gamma3``); they are in :attr:`Trajectory.event_t` and :attr:`Trajectory.event_y`.
    event_direction : int
        ``+1`` rising zeros only, ``-1`` falling only, ``0`` both.
    **overrides
        ``t_end, rtol, atol, samples, max_steps`` or ``model``, replacing the scenario's values;
        under another ``model`` the initial state is projected onto its constraints
        (:func:`switch_model`).

    Warns
    -----
    ContactLostWarning
        When the normal reaction turns negative: the motion leaves the model's assumption that the
        contact is kept. The trajectory is still returned, with ``contact_lost_at`` recorded.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    model = overrides.pop("model", None)
    if model is not None:
        scenario, _ = switch_model(scenario, model)
    scenario = scenario.with_overrides(**overrides)
    opts = scenario.integration
    y0 = scenario.require_state()
    code = scenario.model.kernel_code(scenario.body, y0)  # meridian: pole cases carry nu
    result = integrate(
        code,
        scenario.body.params,
        y0,
        opts.t_eval,
        rtol=opts.rtol,
        atol=opts.resolved_atol,
        max_steps=opts.max_steps,
        progress=progress,
        events=events,
        event_direction=event_direction,
    )
    traj = Trajectory(
        body=scenario.body,
        model=scenario.model,
        t=result.t,
        y=result.y,
        rtol=opts.rtol,
        atol=opts.resolved_atol,
        stats={
            "steps": result.steps,
            "rejected_steps": result.rejected_steps,
            "rhs_evals": result.rhs_evals,
            "wall_time_s": result.wall_time_s,
            "compile_time_s": result.compile_time_s,
        },
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
                f"plane, and the {scenario.model.name!r} model (contact kept) no longer applies"
            ),
            stacklevel=2,
        )
    return traj


def simulate_models(
    scenario: Scenario | str | os.PathLike,
    models=("meridian", "smooth", "rough"),
    **overrides,
) -> dict[str, Trajectory]:
    """Run the scenario's initial state under several contact models, side by side.

    The scenario's state is projected onto each model's constraints
    (:func:`rollingtop.dynamics.state.project_state`: orientation and position kept, velocities
    moved to the nearest admissible ones in the kinetic-energy metric), so each model starts as
    close as it allows to the same state. Returns ``{model name: Trajectory}``.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    scenario.require_state()
    runs = {}
    for name in models:
        runs[name] = simulate(_projected(scenario, get_model(name)), **overrides)
    return runs
