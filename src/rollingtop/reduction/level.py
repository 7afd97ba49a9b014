"""Level sets of the integrals and the effective potential (paper Sec. 3.3, eqs. 3.8-3.11).

On a level set ``(M3, C1, C2)`` of the Lagrange, area and F6 integrals the meridian model reduces
to one degree of freedom (``docs/model.md``, "One degree of freedom"):

    w_n(gamma3)      = (M3 gamma3 - C1) / (I1 s)
    I1 v_tau(gamma3) = [R (M3 - C1 gamma3) + a3 (M3 gamma3 - C1)] / s + C2 + M3 a3 arccos(gamma3)
    U(gamma3)        = (C1 - M3 gamma3)^2 / (2 I1 s^2) + m (I1 v_tau)^2 / (2 I1^2) + m g a3 gamma3
    h = rho w_tau^2 / 2 + U(gamma3),   s = sqrt(1 - gamma3^2).

Internally everything is written in the nutation angle ``theta`` with ``gamma3 = cos(theta)``
and a *signed* ``s = sin(theta)``: then ``theta' = -w_tau`` and ``h = rho theta'^2/2 + U(theta)``,
a particle of position-dependent mass ``rho(cos theta)`` in the potential ``U``. For
``theta in (0, pi)`` this is exactly the paper's description. The signed angle is what makes the
pole cases regular: when ``C1 = M3`` (south pole, ``gamma3 = 1``) or ``C1 = -M3`` (north pole,
``gamma3 = -1``) the terms ``(C1 - M3 cos)/sin`` and ``N/sin`` have finite limits (they become
``M3 tan(theta/2)``, ``-M3 cot(theta/2)``, ...), ``U`` is smooth through the pole, and a motion can
pass through it: ``theta`` changes sign (south) or crosses ``pi`` (north). In the paper's unsigned
variables such a passage flips the signs of ``tau, n, w_tau, w_n, v_tau`` and maps ``C2`` to
``-C2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, overload

import numpy as np

from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.contact.meridian import POLE_CASE_TOLERANCE, pole_case
from rollingtop.reduction._services import (
    ComplexArray,
    Level,
    LevelSetError,
    PoleLevelError,
    Real,
    _Analytic,
    _AnalyticResult,
    check_level_size,
    check_level_values,
)

__all__ = [
    "Level",
    "LevelSet",
    "LevelSetError",
    "POLE_TOLERANCE",
    "PoleLevelError",
    "Real",
    "LagrangeSpin",
    "RollingMass",
    "SpinAndArea",
    "SpinInPotential",
    "near_north",
]

#: ``|C1 -+ M3|`` below this times ``max(|M3|, |C1|)`` is a pole case: the simulator's tolerance
#: (:data:`rollingtop.contact.meridian.POLE_CASE_TOLERANCE`), one decision for every command.
POLE_TOLERANCE = POLE_CASE_TOLERANCE


class LagrangeSpin:
    """Lagrange's integral ``M3 = I3 w3`` of a level (the meridian, smooth and shell-rotor
    models'): the spin is constant and its energy is not part of ``U`` (a mixin of
    :class:`Level` kinds with a field ``M3``)."""

    body: SphericalTop
    M3: float
    #: :meth:`full_energy` in words.
    energy_formula: ClassVar[str] = "h + M3^2/(2 I3) + m g R"

    def spin(self, theta: Real) -> Real:
        """The spin ``w3`` at ``theta``: ``M3 / I3``, constant (Lagrange's integral)."""
        out: Real = self.M3 / self.body.I3 + 0.0 * theta
        return out

    def full_energy(self, h: float) -> float:
        """The energy ``E`` of the full system on this level at reduced energy ``h``:
        ``h + M3^2 / (2 I3) + m g R`` (:func:`rollingtop.reduction.start.level_energy`)."""
        b = self.body
        return h + self.M3 * self.M3 / (2.0 * b.I3) + b.m * b.g * b.R


class SpinInPotential:
    """A level whose spin varies with ``theta`` (the rough and rubber models'): the spin's
    energy is part of ``U``, so ``E = h + m g R`` (a mixin of :class:`Level` kinds)."""

    body: SphericalTop
    #: :meth:`full_energy` in words.
    energy_formula: ClassVar[str] = "h + m g R"

    def full_energy(self, h: float) -> float:
        """The energy ``E = h + m g R`` of the full system at reduced energy ``h`` (the spin's
        energy is in ``U``)."""
        b = self.body
        return h + b.m * b.g * b.R


class SpinAndArea(LagrangeSpin):
    """The Lagrange and area integrals ``M3 = I3 w3`` and ``C1 = (I w, gamma)`` of a level (the
    meridian and smooth models'): the spin, ``w_n``, the precession and the pole decision
    ``C1 = +-M3`` that they fix (a mixin of :class:`Level` kinds with fields ``M3`` and ``C1``).
    """

    C1: float
    scale: float
    pole: str | None

    def _decide_pole(self) -> None:
        """Set :attr:`pole` from ``(M3, C1)`` (:func:`rollingtop.contact.meridian.pole_case`,
        shared with the simulator), snapping ``C1`` to ``+-M3`` exactly on a pole level."""
        pole = pole_case(self.M3, self.C1, scale=abs(float(self.scale)))
        if pole == "south":
            object.__setattr__(self, "C1", self.M3)
        elif pole == "north":
            object.__setattr__(self, "C1", -self.M3)
        elif pole == "both":
            object.__setattr__(self, "M3", 0.0)
            object.__setattr__(self, "C1", 0.0)
        object.__setattr__(self, "pole", pole)

    def pole_offsets(self) -> tuple[float, float]:
        """How far the level is from its south and north pole levels: ``C1 - M3`` and
        ``C1 + M3`` (:func:`near_north`)."""
        return self.C1 - self.M3, self.C1 + self.M3

    @overload
    def _q(self, theta: Real) -> tuple[Real, Real, Real, Real]: ...
    @overload
    def _q(self, theta: ComplexArray) -> tuple[ComplexArray, ...]: ...
    def _q(self, theta: _Analytic) -> tuple[_Analytic, ...]:
        """``q1 = (C1 - M3 cos)/sin`` and ``q2 = N/sin`` with their theta-derivatives."""
        b = self.body
        M3, C1 = self.M3, self.C1
        if self.pole == "south":
            t = np.tan(theta / 2)
            sec2 = 1 / (2 * np.cos(theta / 2) ** 2)
            return M3 * t, M3 * (b.R - b.a3) * t, M3 * sec2, M3 * (b.R - b.a3) * sec2
        if self.pole == "north":
            ct = 1 / np.tan(theta / 2)
            csc2 = 1 / (2 * np.sin(theta / 2) ** 2)
            return -M3 * ct, M3 * (b.R + b.a3) * ct, M3 * csc2, -M3 * (b.R + b.a3) * csc2
        if self.pole == "both":
            z = 0.0 * np.asarray(theta)  # real, or complex for the complex-step derivative
            return z, z, z, z
        c, s = np.cos(theta), np.sin(theta)
        # Free of cancellation near either pole (class Notes): with d = M3 - C1 (exact for
        # nearby floats) and u = 1 - cos = 2 sin^2(theta/2), or d = M3 + C1 and v = 1 + cos.
        if abs(M3 - C1) <= abs(M3 + C1):
            d, u = M3 - C1, 2 * np.sin(theta / 2) ** 2
            a, b_, e = M3 * u - d, M3 * u + d * c, d - M3 * u  # C1-M3c, M3-C1c, M3c-C1
        else:
            d, v = M3 + C1, 2 * np.cos(theta / 2) ** 2
            a, b_, e = d - M3 * v, M3 * v - d * c, M3 * v - d
        N = b.R * b_ + b.a3 * e
        return (
            a / s,
            N / s,
            b_ / s**2,
            (b.R * C1 - b.a3 * M3) - N * c / s**2,
        )

    def w_n(self, theta: Real) -> Real:
        """``w_n = (M3 gamma3 - C1) / (I1 s)`` (eq. 3.8)."""
        q1, _, _, _ = self._q(theta)
        return -q1 / self.body.I1

    @overload
    def psi_dot(self, theta: float) -> float: ...
    @overload
    def psi_dot(self, theta: FloatArray) -> FloatArray: ...
    def psi_dot(self, theta: float | FloatArray) -> float | FloatArray:
        """Precession rate ``psi' = -w_n / s`` (``docs/model.md``, "Motion in absolute space"),
        finite at the pole in a pole case."""
        I1 = self.body.I1
        rate: float | FloatArray
        if self.pole == "both":
            return np.zeros_like(np.asarray(theta, dtype=float))  # a numpy float for a float
        if self.pole == "south":
            rate = self.M3 / (I1 * (1 + np.cos(theta)))
        elif self.pole == "north":
            rate = -self.M3 / (I1 * (1 - np.cos(theta)))
        else:
            q1, _, _, _ = self._q(theta)
            rate = q1 / (I1 * np.sin(theta))
        return rate


class RollingMass:
    """The reduced mass of a body rolling along ``tau`` (the meridian, rough and rubber
    models'): ``rho(cos theta) = I1 + m (R^2 + a3^2 + 2 a3 R cos theta)`` (paper eq. 3.5), also
    the density of the invariant measure (a mixin of :class:`Level` kinds)."""

    body: SphericalTop

    def rho(self, theta: Real) -> Real:
        """Invariant-measure density, also the reduced motion's mass: ``rho(cos theta)`` (3.5)."""
        rho: Real = self.body.rho(np.cos(theta))
        return rho

    def drho(self, theta: Real) -> Real:
        """``d rho(cos theta) / dtheta = -2 m a3 R sin(theta)``."""
        b = self.body
        drho: Real = -2 * b.m * b.a3 * b.R * np.sin(theta)
        return drho


@dataclass(frozen=True)
class LevelSet(SpinAndArea, RollingMass, Level):
    """A level set ``(M3, C1, C2)`` of the linear integrals of the meridian model.

    Parameters
    ----------
    body : SphericalTop
        Must be dynamically symmetric (``I1 == I2``): the reduction needs the Lagrange integral.
    M3 : float
        Lagrange integral ``F3 = I3 w3``.
    C1 : float
        Area integral ``F5 = (I w, gamma) = gamma3 M3 - I1 s w_n``.
    C2 : float
        The paper's integral ``F6``.
    scale : float, optional
        Size of the terms ``M3`` and ``C1`` were computed from, for values read from a state
        (``|I w|``): then ``M3, C1`` within round-off of that size count as zero in the pole
        decision (:func:`rollingtop.contact.meridian.pole_case`). Default 0: given values.

    Attributes
    ----------
    pole : {None, "south", "north", "both"}
        ``"south"`` when ``C1 = M3`` (the pole ``gamma3 = 1`` can touch the plane), ``"north"``
        when ``C1 = -M3``, within :data:`POLE_TOLERANCE`; in these cases ``C1`` is snapped to
        ``+-M3`` exactly. ``"both"`` when ``M3 = C1 = 0`` (no spin): then ``w_n = 0``,
        ``v_tau = C2 / I1`` and ``U = m C2^2 / (2 I1^2) + m g a3 cos(theta)`` is smooth on the
        whole circle -- the planar rocking and rolling-over motions, through both poles.
        The decision is :func:`rollingtop.contact.meridian.pole_case`, shared with the simulator.

    Notes
    -----
    Near a pole level (``0 < |C1 -+ M3|`` small) ``U`` has a wall of width about
    ``|C1 -+ M3| / sqrt(I1 h)`` next to the pole. The differences ``C1 - M3 cos(theta)`` etc.
    are then formed from ``M3 - C1`` (or ``M3 + C1``), which is exact for nearby floats, and
    ``1 -+ cos(theta) = 2 sin^2(theta/2)`` (``2 cos^2``), so ``U`` keeps its relative accuracy
    inside the wall (see :meth:`_q`).
    """

    #: The contact model whose reduction this is (:mod:`rollingtop.reduction.models`).
    model: ClassVar[str] = "meridian"
    integrals: ClassVar[tuple[str, ...]] = ("M3", "C1", "C2")
    #: Whether :func:`rollingtop.reduction.near_pole.near_pole` knows this model's limits on
    #: its pole levels (the meridian model's only, so far).
    near_pole_limits: ClassVar[bool] = True
    #: What to do about a wall of ``U`` too thin for doubles next to a pole (a level within
    #: round-off of a pole level): :func:`rollingtop.reduction.orbits.orbits`' refusal says it.
    pole_advice: ClassVar[str] = "for the pole case set C1 = +-M3 exactly; or rescale M3, C1"

    body: SphericalTop
    M3: float
    C1: float
    C2: float
    scale: float = 0.0
    #: Set from ``(M3, C1)`` at construction (see Attributes).
    pole: str | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_level_values(self, ("M3", "C1", "C2"))
        self._decide_pole()
        check_level_size(self)

    def mirrored(self) -> LevelSet:
        """The same motions seen with the body axis reversed (``e3 -> -e3``): ``theta -> pi -
        theta``, ``a3 -> -a3``, ``M3 -> -M3``, ``C1`` kept, ``C2 -> -C2 - pi M3 a3``.

        ``U``, ``rho`` and ``psi'`` at ``pi - theta`` on the mirrored level equal those at
        ``theta`` here (tested), so a level near the north pole can be computed as one near the
        south pole, where the distance to the pole is a float of its own (``theta`` itself)
        rather than the difference ``pi - theta``, which keeps only absolute precision.
        """
        from dataclasses import replace

        return LevelSet(
            replace(self.body, a3=-self.body.a3),
            -self.M3,
            self.C1,
            -self.C2 - math.pi * self.M3 * self.body.a3,
        )

    # ---- the reduced quantities -------------------------------------------------------------
    def P(self, theta: Real) -> Real:
        """``I1 v_tau`` as a function of ``theta`` (eq. 3.8), signed-``s`` convention.

        The integral ``F6 = C2`` (:func:`rollingtop.dynamics.integrals.F6_reduced`) solved for
        ``I1 v_tau`` with :meth:`w_n` substituted, in the cancellation-free form of :meth:`_q`
        (tested against ``F6_reduced``).
        """
        _, q2, _, _ = self._q(theta)
        return q2 + self.C2 + self.M3 * self.body.a3 * theta

    def U(self, theta: Real) -> Real:
        """Effective potential ``U`` (eq. 3.11, ``docs/model.md``) at ``theta``."""
        b = self.body
        q1, _, _, _ = self._q(theta)
        P = self.P(theta)
        U: Real = q1**2 / (2 * b.I1) + b.m * P**2 / (2 * b.I1**2) + b.m * b.g * b.a3 * np.cos(theta)
        return U

    @overload
    def dU(self, theta: Real) -> Real: ...
    @overload
    def dU(self, theta: ComplexArray) -> ComplexArray: ...
    def dU(self, theta: _Analytic) -> _AnalyticResult:
        """``dU/dtheta`` (analytic)."""
        b = self.body
        q1, q2, dq1, dq2 = self._q(theta)
        P = q2 + self.C2 + self.M3 * b.a3 * theta
        dP = dq2 + self.M3 * b.a3
        return q1 * dq1 / b.I1 + b.m * P * dP / b.I1**2 - b.m * b.g * b.a3 * np.sin(theta)

    def linearised_eigenvalues(self, gamma3: float) -> ComplexArray:
        """Eigenvalues of the reduced equations (eq. 3.3) linearised at the steady motion at
        ``gamma3``, by central differences of :func:`rollingtop.reduction.reduced_rhs` at
        ``(gamma3, v_tau, w_n, 0)`` (:func:`rollingtop.reduction.steady.linearised_eigenvalues`
        says why)."""
        from rollingtop.reduction.system import reduced_eigenvalues

        theta = math.acos(gamma3)
        x0 = np.array([gamma3, float(self.v_tau(theta)), float(self.w_n(theta)), 0.0])
        return reduced_eigenvalues(self.body, self.M3, x0)

    def describe(self) -> str:
        """One line naming the level set."""
        return f"M3 = {self.M3:g}, C1 = {self.C1:g}, C2 = {self.C2:g}{self.pole_label()}"


def near_north(level: Level) -> bool:
    """A level that is no pole case and lies nearer its north pole level than its south one
    (:meth:`LevelSet.pole_offsets`; the meridian model's: ``C1 = -M3`` and ``C1 = M3``): computed
    on its mirror image (:meth:`LevelSet.mirrored`). On a tie (the rubber model's two poles
    are one level) the pole the weight favours: north for ``a3 > 0``, where a small spin's
    centre then lies within ``sqrt(rubber_spin)`` of ``theta = pi``, beyond what ``theta``
    resolves there but not its mirror image near 0."""
    south, north = level.pole_offsets()
    if abs(north) == abs(south):
        return level.pole is None and level.body.a3 > 0.0
    return level.pole is None and abs(north) < abs(south)
