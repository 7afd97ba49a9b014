"""One entry point for simulations: :func:`simulate`."""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable

from rollingtop._errors import ContactLostWarning
from rollingtop.contact import meridian
from rollingtop.integrate import integrate
from rollingtop.scenario import Scenario, load_scenario
from rollingtop.trajectory import Trajectory

__all__ = ["simulate", "simulate_models"]


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
        ``t_end, rtol, atol, samples, max_steps`` or ``model``, replacing the scenario's values.

    Warns
    -----
    ContactLostWarning
        When the normal reaction turns negative: the motion leaves the model's assumption that the
        contact is kept. The trajectory is still returned, with ``contact_lost_at`` recorded.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    scenario = scenario.with_overrides(**overrides)
    opts = scenario.integration
    y0 = scenario.require_state()
    code = scenario.model.code
    if scenario.model.name == "meridian":
        code = meridian.kernel_code(scenario.body, y0)  # pole cases carry nu through the pole
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
    from dataclasses import replace

    from rollingtop.dynamics.state import project_state
    from rollingtop.scenario import InitialConditions

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    y0 = scenario.require_state()
    runs = {}
    for name in models:
        ic = InitialConditions.from_state(project_state(scenario.body, name, y0))
        sc = replace(scenario, model=name, initial=ic, level=None)
        runs[name] = simulate(sc, **overrides)
    return runs
