"""What every model's level set provides besides its potential and mass: its integrals by
name, the full energy and the spin, the centre of mass's velocity, the normal force and a
uniform drift (:class:`LevelServices`, a base of :class:`~rollingtop.reduction.LevelSet`).

The defaults are the meridian model's; the other models' levels
(:mod:`rollingtop.reduction.smooth`, :mod:`rollingtop.reduction.rough`) override what differs.
Everything downstream (steady motions, orbits, portraits, starting a motion on a level, the
motion in absolute space) asks the level through these, whatever the model.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, ClassVar, TypeAlias, TypeVar

import numpy as np
from numpy.typing import NDArray

from rollingtop._errors import RollingTopError
from rollingtop.body import SphericalTop

__all__ = [
    "LevelServices",
    "LevelSetError",
    "PoleLevelError",
    "Real",
    "check_level_size",
    "check_level_values",
]

FloatArray: TypeAlias = NDArray[np.float64]
#: A value or an array of values: the functions of ``theta`` are vectorised (numpy broadcasting),
#: a float gives a float (a numpy float) and an array of shape ``(...)`` an array of that shape.
Real = TypeVar("Real", float, FloatArray)


class LevelSetError(RollingTopError):
    """Inconsistent level set, or a level with no motion."""


class PoleLevelError(LevelSetError):
    """A pole level the model's reduction does not reduce (yet): the rough model's."""


#: Largest effective potential a level may reach at ``gamma3 = 0``: beyond it ``U``, its
#: derivatives and ``h - U`` would overflow (or lose every digit) in double precision.
_MAX_U = 1e100


def check_level_values(level: Any, names: tuple[str, ...]) -> None:
    """Each integral ``names`` of ``level`` a finite number (stored as a float), and its body
    dynamically symmetric; a :class:`~rollingtop.reduction.LevelSetError` in one line if not
    (every model's level, at construction)."""
    for name in names:
        x = getattr(level, name)
        if isinstance(x, bool) or not isinstance(x, int | float | np.floating | np.integer):
            raise LevelSetError(f"level {name} = {x!r} must be a number")
        if not math.isfinite(x):
            raise LevelSetError(f"level {name} = {x!r} must be finite")
        object.__setattr__(level, name, float(x))
    b = level.body
    if not b.symmetric:
        raise LevelSetError(
            f"the reduction needs a dynamically symmetric body (I1 = I2), got "
            f"I1 = {b.I1:g}, I2 = {b.I2:g}"
        )


def check_level_size(level: Any) -> None:
    """``U`` at ``gamma3 = 0`` within :data:`_MAX_U`, else a one-line
    :class:`~rollingtop.reduction.LevelSetError` naming the level (every model's level, once its
    values are set)."""
    try:
        with np.errstate(all="ignore"):
            size = abs(float(level.U(math.pi / 2)))
    except (OverflowError, ZeroDivisionError):  # Python floats raise where numpy's give inf
        size = math.inf
    if not size <= _MAX_U:
        raise LevelSetError(
            f"level {level.describe()} is too large for double precision: its effective "
            f"potential reaches {size:.3g} at gamma3 = 0 (at most {_MAX_U:g}; rescale units)"
        )


class LevelServices(ABC):
    """The services of a level set (module docstring); a level provides ``body``, ``M3``,
    :attr:`integrals`, ``v_tau(theta)`` and ``flow(theta, w_tau)``."""

    body: SphericalTop
    M3: float
    #: The integrals that name the level, in order (:attr:`ContactModel.reduction`): the keys
    #: of a ``[level]`` table and of the level in JSON output (:meth:`values`).
    integrals: ClassVar[tuple[str, ...]] = ("M3", "C1", "C2")

    @abstractmethod
    def v_tau(self, theta: Any) -> Any:
        """``v_tau`` at ``theta`` (the level's own)."""

    @abstractmethod
    def flow(self, theta: Any, w_tau: Any) -> tuple[Any, Any]:
        """``(theta', w_tau')`` (the level's own)."""

    #: :meth:`full_energy` in words.
    energy_formula: ClassVar[str] = "h + M3^2/(2 I3) + m g R"

    def full_energy(self, h: float) -> float:
        """The energy ``E`` of the full system on this level at reduced energy ``h``:
        ``h + M3^2 / (2 I3) + m g R`` (:func:`rollingtop.reduction.start.level_energy`)."""
        b = self.body
        return h + self.M3 * self.M3 / (2.0 * b.I3) + b.m * b.g * b.R

    def spin(self, theta: Real) -> Real:
        """The spin ``w3`` at ``theta``: ``M3 / I3``, constant (Lagrange's integral)."""
        out: Real = self.M3 / self.body.I3 + 0.0 * theta
        return out

    def normal_force(self, theta: Real, w_tau: Real) -> Real:
        """The plane's normal force at ``(theta, w_tau)`` on the level: the centre of mass is at
        height ``R + a3 gamma3`` and only gravity and the normal force act on it vertically
        (every model's other reactions are horizontal), so ``N = m (g + a3 gamma3'')`` with
        ``gamma3'' = s w_tau' - gamma3 w_tau^2`` and ``w_tau'`` from :meth:`flow`. NumPy only:
        the reduction's pictures need no compiled code."""
        b = self.body
        _, dw = self.flow(theta, w_tau)
        N: Real = b.m * (b.g + b.a3 * (np.sin(theta) * dw - np.cos(theta) * w_tau * w_tau))
        return N

    def last_slot(self, theta: Real, psi: float) -> Real:
        """The state's last entry at ``theta``: the carried direction's azimuth, ``psi`` (the
        shell-rotor pair's level puts its shell's relative spin there)."""
        out: Real = psi + 0.0 * theta
        return out

    def uniform_drift(self) -> float | None:
        """The speed of the centre of mass when it drifts uniformly whatever the axis does (a
        model with conserved horizontal momentum: its direction is not part of the level),
        else ``None``: the meridian model's velocity turns with the axis
        (:func:`rollingtop.absolute.period_map`)."""
        return None

    def values(self) -> dict[str, float]:
        """The level's integrals by name (:attr:`integrals`)."""
        return {name: float(getattr(self, name)) for name in self.integrals}

    def com_velocity(self, theta: Real, w_tau: Real, frame: dict[str, FloatArray]) -> FloatArray:
        """The centre of mass's velocity (body frame) at ``theta`` with ``w_tau``, from the
        constraints and :meth:`v_tau`: ``v_tau tau - (R gamma3 + a3) w_tau n - R s w_tau e3``
        (``docs/model.md``, "Reduced variables"). ``frame`` holds the unit vectors ``tau, n, e3,
        gamma`` (shape ``(..., 3)``, broadcast with ``theta`` and ``w_tau`` of shape ``(...)``).
        """
        b = self.body
        t = np.asarray(theta, dtype=float)[..., None]
        wt = np.asarray(w_tau, dtype=float)[..., None]
        v_tau = (np.asarray(self.v_tau(theta), dtype=float) + 0.0 * wt[..., 0])[..., None]
        v: FloatArray = (
            v_tau * frame["tau"]
            - (b.R * np.cos(t) + b.a3) * wt * frame["n"]
            - b.R * np.sin(t) * wt * frame["e3"]
        )
        return v
