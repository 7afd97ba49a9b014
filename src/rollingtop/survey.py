"""What the reduction says about a level or a motion, in one call each.

- :func:`survey_orbits`: every orbit on ``(M3, C1, C2, h)`` with its per-period map in the plane
  (:func:`rollingtop.absolute.period_map`) and, next to a pole level, its limits
  (:func:`rollingtop.reduction.near_pole.near_pole`): what ``rollingtop orbits`` prints.
- :func:`motion_period_map`: the per-period map of a scenario's own motion, when the motion is
  a periodic orbit of a reduction (what ``rollingtop path`` draws).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from rollingtop.absolute import PeriodMap, period_map
from rollingtop.reduction import LevelSetError, Orbit, orbits, reduce_state
from rollingtop.reduction.level import Level
from rollingtop.reduction.near_pole import NearPole, near_pole
from rollingtop.scenario import Scenario

__all__ = ["OrbitSurvey", "motion_period_map", "survey_orbits"]

#: A state's ``theta`` this close (rad) outside an orbit's turning points still lies on it.
ON_ORBIT = 1e-9


@dataclass(frozen=True)
class OrbitSurvey:
    """One orbit and what follows from it.

    Attributes
    ----------
    orbit : Orbit
    period_map : PeriodMap or None
        Its per-period map (periodic orbits only).
    near_pole : NearPole or None
        Its limits as the level approaches a pole level (orbits next to the wall only).
    """

    orbit: Orbit
    period_map: PeriodMap | None
    near_pole: NearPole | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the orbit's, with ``near_pole`` and, for a periodic orbit, the
        map's ``delta_psi, delta_psi_error, motion, near_resonant, displacement`` and either
        ``center, radius`` (bounded), ``drift_velocity`` (drifting) or ``drift_speed`` (a uniform
        drift, the smooth plane's: no displacement)."""
        row: dict[str, Any] = self.orbit.to_dict()
        row["near_pole"] = None if self.near_pole is None else self.near_pole.to_dict()
        pm = self.period_map
        if pm is not None:
            row.update(
                delta_psi=pm.delta_psi,
                delta_psi_error=pm.delta_psi_error,
                motion=pm.motion,
                near_resonant=pm.near_resonant,
                displacement=list(pm.displacement),
            )
            if pm.motion == "bounded":
                assert pm.center is not None
                row.update(center=list(pm.center), radius=pm.radius)
            elif pm.motion == "uniform drift":  # a speed: the direction is not the level's
                row.update(displacement=None, drift_speed=pm.drift_speed)
            elif pm.motion == "unresolved":  # too close to the vertical to follow the path
                row.update(displacement=None)
            else:
                assert pm.drift_velocity is not None
                row.update(drift_velocity=list(pm.drift_velocity))
        return row


def survey_orbits(level: Level, h: float) -> list[OrbitSurvey]:
    """Every orbit on ``(M3, C1, C2, h)``, sorted by ``gamma3_min``
    (:func:`rollingtop.reduction.orbits`), with its per-period map and near-pole limits.

    Raises
    ------
    LevelSetError
        No motion on the level with this ``h``.
    """
    found = orbits(level, h)
    return [OrbitSurvey(o, _map_or_none(level, h, o), near_pole(level, h, o)) for o in found]


def _map_or_none(level: Level, h: float, orbit: Orbit) -> PeriodMap | None:
    """The orbit's per-period map, or ``None`` where there is none (not periodic) or where its
    reconstruction in space fails (a wall within round-off of the far pole: the precession rate
    there is beyond what the quadrature resolves): the orbit is still listed, without it."""
    if orbit.kind != "periodic":
        return None
    try:
        with np.errstate(all="ignore"):
            return period_map(level, h, orbit)
    except LevelSetError:
        return None


def motion_period_map(scenario: Scenario) -> PeriodMap | None:
    """The per-period map of the scenario's motion: of the orbit through its initial state on
    its level set (:meth:`Scenario.level_set`, :meth:`Scenario.level_h`).

    ``None`` where there is none: a model without a reduction, a body that is not dynamically
    symmetric, a level without motion, a state on a steady motion or a separatrix.
    """
    from rollingtop.reduction.models import closed_form_diagram

    if not closed_form_diagram(scenario.model) or not scenario.body.symmetric:
        return None
    try:
        level, h = scenario.level_set(), scenario.level_h()
        theta = float(reduce_state(scenario.require_state(), model=scenario.model)["theta"])
        found = [
            o for o in orbits(level, h) if o.theta_min - ON_ORBIT <= theta <= o.theta_max + ON_ORBIT
        ]
        if not found or found[0].kind != "periodic":
            return None
        return period_map(level, h, found[0])
    except LevelSetError:
        return None
