"""Poincare sections and chaos indicators, for every contact model of the registry.

Everything runs through the compiled dispatch (the kernel code of a model), so a model added
to :mod:`rollingtop.contact` is served without code here:

- :func:`poincare_section`: crossings of ``w_tau = 0`` (upward) by many trajectories on one
  level set of the integrals, in parallel (:mod:`.section`);
- :func:`level_states`: initial states on the level set of a state (:mod:`.level`);
- :func:`chaos_indicators`: the maximal Lyapunov exponent and MEGNO from the tangent dynamics
  integrated with the motion (:mod:`.lyapunov`, :mod:`._tangent`);
- :func:`indicator_map`: the indicators over many initial states, in parallel or on Dask
  (:mod:`.maps`);
- :func:`periodic_orbits`: the relative periodic orbits on a level, fixed points of the
  section's map with their multipliers (:mod:`.periodic`);
- :func:`continue_orbit`: such an orbit followed in a body parameter or the energy, its
  bifurcations located (:mod:`.continuation`).
"""

from __future__ import annotations

from rollingtop.chaos.continuation import Branch, continue_orbit
from rollingtop.chaos.level import level_states
from rollingtop.chaos.lyapunov import ChaosIndicators, chaos_indicators
from rollingtop.chaos.maps import indicator_map
from rollingtop.chaos.periodic import PeriodicOrbit, PeriodicOrbits, periodic_orbits
from rollingtop.chaos.section import poincare_section, section_summary

__all__ = [
    "Branch",
    "ChaosIndicators",
    "PeriodicOrbit",
    "PeriodicOrbits",
    "chaos_indicators",
    "continue_orbit",
    "indicator_map",
    "level_states",
    "periodic_orbits",
    "poincare_section",
    "section_summary",
]
