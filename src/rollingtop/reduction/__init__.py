"""Reduction of the meridian model to one degree of freedom (paper Sec. 3), and of the other
models that have one (:mod:`.models`: the smooth model's, :mod:`.smooth`, the rough model's,
:mod:`.rough`, and the rubber model's, :mod:`.rubber`).

- :mod:`.variables`: full state <-> reduced variables and integrals.
- :mod:`.system`: the reduced system (eq. 3.3).
- :class:`Level` (:mod:`._services`): the abstract level set every reduced model implements
  (its potential, mass, spin, precession, poles, eigenvalues); the rest derives from them.
- :mod:`.level`: the meridian model's level sets ``(M3, C1, C2)`` (:class:`LevelSet`) and the
  effective potential ``U``.
- :mod:`.steady`: steady motions (critical points of ``U``), as a list that knows its level
  (:class:`~.steady.SteadyMotions`).
- :mod:`.orbits`: orbits on ``(M3, C1, C2, h)``, turning points, periods; the quadrature of
  the time along an orbit is the private :mod:`._quadrature`, and :class:`~.orbits.Orbit` with
  its turning points and :class:`~.orbits.Orbits` (the list of one energy; shared with
  :mod:`.no_spin`) the private :mod:`._orbit`.
- In a notebook the levels, their steady motions and orbits and the bifurcation diagrams show
  themselves as HTML tables (the private :mod:`._display`, registered on import) and draw
  themselves (``.plot()``, with :mod:`rollingtop.plot`, named in :mod:`rollingtop._figures`).
- :mod:`.curves`: the curves of a phase portrait as data (what the figures draw).
- :mod:`.no_spin`, :mod:`.near_pole`: the no-spin level and levels near a pole level.
"""

from rollingtop.reduction import _display  # noqa: F401  (registers the objects' HTML views)
from rollingtop.reduction.level import POLE_TOLERANCE, Level, LevelSet, LevelSetError
from rollingtop.reduction.models import REDUCTIONS, Reduction, reduction_of
from rollingtop.reduction.orbits import Orbit, Orbits, orbits
from rollingtop.reduction.rough import RoughLevel
from rollingtop.reduction.rubber import RubberLevel
from rollingtop.reduction.shell_rotor import ShellRotorLevel
from rollingtop.reduction.smooth import SmoothLevel
from rollingtop.reduction.steady import SteadyMotion, SteadyMotions, steady_motions
from rollingtop.reduction.system import integrate_reduced, reduced_integrals_of, reduced_rhs
from rollingtop.reduction.variables import (
    euler_angles,
    reduce_state,
    reduced_integrals,
    state_from_level,
    states_on_level,
)

__all__ = [
    "POLE_TOLERANCE",
    "Level",
    "LevelSet",
    "LevelSetError",
    "Orbit",
    "Orbits",
    "REDUCTIONS",
    "Reduction",
    "RoughLevel",
    "RubberLevel",
    "ShellRotorLevel",
    "SmoothLevel",
    "SteadyMotion",
    "SteadyMotions",
    "euler_angles",
    "integrate_reduced",
    "orbits",
    "reduce_state",
    "reduced_integrals",
    "reduced_integrals_of",
    "reduced_rhs",
    "reduction_of",
    "state_from_level",
    "states_on_level",
    "steady_motions",
]
