"""A trajectory of the explore page, started from a point of its phase portrait."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

from rollingtop._errors import ContactLostWarning, ScenarioError
from rollingtop._types import FloatArray
from rollingtop.explore.view import ExploreState, joined, orbit_curves

__all__ = ["PATH_SAMPLES", "PATH_T_END", "PathView", "path_view"]

#: Time a click-to-start trajectory runs.
PATH_T_END = 20.0
#: Samples of that trajectory.
PATH_SAMPLES = 801


@dataclass(frozen=True)
class PathView:
    """A trajectory started from a point of the portrait (:func:`path_view`): the contact
    point's path on the plane, the orbit's rotation-number class, and the trajectory itself
    (for the device's frame)."""

    x: FloatArray
    y: FloatArray
    h: float
    gamma3: float
    w_tau: float
    summary: str
    trajectory: Any
    orbit: tuple[FloatArray, FloatArray]


def path_view(
    state: ExploreState, x: float, w_tau: float, *, t_end: float = PATH_T_END
) -> PathView:
    """The motion that starts at the portrait's point ``(x, w_tau)`` (``x = gamma3``, or
    ``theta`` on a pole level), completed onto the level: its energy is ``h = rho w_tau^2 / 2 +
    U`` there and its state :func:`rollingtop.reduction.state_from_level`'s, the construction of
    ``rollingtop simulate`` from a ``[level]``; integrated by the full system for ``t_end``.

    Raises
    ------
    ScenarioError
        A point outside the portrait's domain.
    """
    from rollingtop.reduction import orbits, state_from_level
    from rollingtop.reduction.rotation import classify_rotation, rotation_number
    from rollingtop.simulate import simulate

    level = state.level_set()
    pole = level.pole is not None
    if pole:
        theta = float(x)
        gamma3 = math.cos(theta)
    else:
        if not -1.0 < x < 1.0:
            raise ScenarioError(f"gamma3 = {x:.4g} lies outside (-1, 1)")
        theta, gamma3 = math.acos(x), float(x)
    h = float(level.energy(theta, w_tau))
    branch = 1 if w_tau >= 0 else -1
    y0 = state_from_level(level, h, gamma3, branch=branch, theta=theta)
    with warnings.catch_warnings():  # the loss of contact is in the page's summary instead
        warnings.simplefilter("ignore", ContactLostWarning)
        traj = simulate(state.body, state.contact_model, y0, t_end=t_end, samples=PATH_SAMPLES)
    pos = traj.y[:, 15:17]
    summary = f"h = {h:.6g}"
    found = [o for o in orbits(level, h) if o.theta_min - 1e-9 <= theta <= o.theta_max + 1e-9]
    if found and found[0].kind == "periodic":
        N, _ = rotation_number(level, h, found[0])
        cls = classify_rotation(N)
        kind = cls["class"] if cls["q"] is None else f"{cls['class']} p/q = {cls['p']}/{cls['q']}"
        summary += f", rotation number N = {N:.6f} ({kind})"
    elif found:
        what = "a steady motion" if found[0].kind == "steady" else "its period is infinite"
        summary += f" ({found[0].kind} orbit: {what})"
    curve = joined(orbit_curves(level, h))
    return PathView(
        pos[:, 0].copy(), pos[:, 1].copy(), h, gamma3, float(w_tau), summary, traj, curve
    )
