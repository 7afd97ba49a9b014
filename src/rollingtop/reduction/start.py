"""Between full states and the reduction: the level set and energy of a state, and a state
started on a given level (paper Sec. 3; ``docs/model.md``, "One degree of freedom").

- :func:`level_of_state`: the level set ``(M3, C1, C2)`` a state lies on.
- :func:`reduced_energy`: its reduced energy ``h``; :func:`level_energy`: the full energy of a
  level, ``E = h + M3^2 / (2 I3) + m g R``.
- :func:`start_on_level`: a full state on ``(M3, C1, C2, h)``, by default at a turning point of
  the first orbit (how a scenario's ``[level]`` table with ``h`` starts a motion).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._layout import W
from rollingtop.body import SphericalTop
from rollingtop.reduction.level import Level, LevelSet
from rollingtop.reduction.orbits import orbits
from rollingtop.reduction.variables import reduced_integrals, state_from_level

__all__ = ["level_energy", "level_of_state", "reduced_energy", "start_on_level"]


def _meridian_default(name: str) -> None:
    warnings.warn(
        f"{name}() without model= assumes the meridian model; pass model='meridian' (or "
        f"another reduced model's name): the default goes in rollingtop 0.3",
        DeprecationWarning,
        stacklevel=3,
    )


def level_of_state(body: SphericalTop, y: ArrayLike, model: str | None = None) -> Level:
    """The level set of the state ``y`` under ``model``
    (:meth:`rollingtop.reduction.models.Reduction.level_of_state`); for the meridian model
    ``(M3, C1, C2)`` with ``y`` of shape (18,).

    .. deprecated:: 0.2
        Without ``model`` the meridian model is assumed, with a ``DeprecationWarning``; pass
        the model's name.

    The values come from :func:`~rollingtop.reduction.reduced_integrals`; ``|I w|`` of the state
    is the round-off scale of ``M3`` and ``C1`` in the pole decision
    (:class:`~rollingtop.reduction.LevelSet`, ``scale``).
    """
    if model is not None:
        from rollingtop.reduction.models import reduction_of

        return reduction_of(model).level_of_state(body, y)
    _meridian_default("level_of_state")
    y = np.asarray(y, dtype=float)
    ints = reduced_integrals(body, y)
    scale = float(np.linalg.norm(body.inertia * y[W]))
    return LevelSet(body, float(ints["M3"]), float(ints["C1"]), float(ints["C2"]), scale=scale)


def reduced_energy(body: SphericalTop, y: ArrayLike, model: str | None = None) -> float:
    """The reduced energy of the state ``y`` under ``model``
    (:meth:`rollingtop.reduction.models.Reduction.reduced_energy`); for the meridian model
    ``h = E - I3 w3^2/2 - m g R``.

    .. deprecated:: 0.2
        Without ``model`` the meridian model is assumed, with a ``DeprecationWarning``; pass
        the model's name.
    """
    if model is not None:
        from rollingtop.reduction.models import reduction_of

        return reduction_of(model).reduced_energy(body, y)
    _meridian_default("reduced_energy")
    return float(reduced_integrals(body, np.asarray(y, dtype=float))["h"])


def level_energy(body: SphericalTop, M3: float, h: float) -> float:
    """The energy ``E`` of the full system on a level with Lagrange integral ``M3`` and reduced
    energy ``h``.

    ``h = E - I3 w3^2/2 - m g R`` with ``w3 = M3 / I3`` (``docs/model.md``, "Reduced
    variables"), so ``E = h + M3^2 / (2 I3) + m g R``: the reduction drops the spin's constant
    kinetic energy and measures the height of the centre of mass from the sphere's centre.

    Parameters
    ----------
    body : SphericalTop
    M3 : float
        Lagrange integral ``I3 w3``.
    h : float
        Reduced energy.

    Returns
    -------
    float
    """
    return h + M3 * M3 / (2.0 * body.I3) + body.m * body.g * body.R


def start_on_level(
    level: Level,
    h: float,
    *,
    gamma3: float | None = None,
    branch: int = 1,
    phi: float = 0.0,
    psi: float = 0.0,
) -> NDArray[np.float64]:
    """A full state on the level ``(M3, C1, C2, h)``
    (:func:`~rollingtop.reduction.state_from_level`).

    ``gamma3`` defaults to a turning point of the first orbit on the level, its largest
    ``theta`` when that lies inside ``(0, pi)`` (else its smallest, the other side of a pole
    passage): there ``w_tau = 0``. ``branch`` is the sign of ``w_tau``; ``phi, psi`` the Euler
    angles fixing the orientation.

    Raises
    ------
    LevelSetError
        No motion on the level with this ``h`` (or at this ``gamma3``).
    """
    if gamma3 is None:  # a turning point of the first orbit, on the branch 0 < theta < pi
        first = orbits(level, h)[0]
        theta = first.start_theta
        if first.rolls_over or not 0.0 < theta < math.pi:  # no turning point on that branch
            theta = math.pi / 2
        # theta itself: a turning point beside a pole keeps its distance from it (cos rounds)
        return state_from_level(
            level, h, math.cos(theta), branch=branch, phi=phi, psi=psi, theta=theta
        )
    return state_from_level(level, h, gamma3, branch=branch, phi=phi, psi=psi)
