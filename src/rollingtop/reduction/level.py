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
from typing import TYPE_CHECKING, Any, ClassVar, TypeAlias, overload

import numpy as np
from numpy.typing import NDArray

from rollingtop._figures import draw
from rollingtop._html import html_view
from rollingtop.body import SphericalTop
from rollingtop.contact.meridian import POLE_CASE_TOLERANCE, pole_case
from rollingtop.reduction._services import (
    LevelServices,
    LevelSetError,
    PoleLevelError,
    Real,
    check_level_size,
    check_level_values,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["LevelSet", "LevelSetError", "POLE_TOLERANCE", "PoleLevelError", "Real", "near_north"]

FloatArray: TypeAlias = NDArray[np.float64]
ComplexArray: TypeAlias = NDArray[np.complex128]
#: ``theta`` for :meth:`LevelSet.dU`, also complex (the complex step of ``d2U``).
_Analytic: TypeAlias = float | FloatArray | ComplexArray
#: What numpy's stubs make of arithmetic on ``_Analytic`` (complex of unspecified precision).
_AnalyticResult: TypeAlias = float | FloatArray | NDArray[np.complexfloating[Any, Any]]

#: ``|C1 -+ M3|`` below this times ``max(|M3|, |C1|)`` is a pole case: the simulator's tolerance
#: (:data:`rollingtop.contact.meridian.POLE_CASE_TOLERANCE`), one decision for every command.
POLE_TOLERANCE = POLE_CASE_TOLERANCE
#: Step of the complex-step derivative (exact to round-off for analytic functions).
_COMPLEX_STEP = 1e-30


@dataclass(frozen=True)
class LevelSet(LevelServices):
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
        pole = pole_case(self.M3, self.C1, scale=abs(float(self.scale)))
        if pole == "south":
            object.__setattr__(self, "C1", self.M3)
        elif pole == "north":
            object.__setattr__(self, "C1", -self.M3)
        elif pole == "both":
            object.__setattr__(self, "M3", 0.0)
            object.__setattr__(self, "C1", 0.0)
        object.__setattr__(self, "pole", pole)
        check_level_size(self)

    def pole_offsets(self) -> tuple[float, float]:
        """How far the level is from its south and north pole levels: ``C1 - M3`` and
        ``C1 + M3`` (:func:`near_north`)."""
        return self.C1 - self.M3, self.C1 + self.M3

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

    # ---- domain in theta ------------------------------------------------------------------
    @property
    def theta_domain(self) -> tuple[float, float]:
        """Open interval of ``theta`` the motion lives in: ``(0, pi)``; ``(-pi, pi)`` for a south
        pole case, ``(0, 2 pi)`` for a north pole case (the potential is finite at the pole)."""
        if self.pole == "south":
            return (-math.pi, math.pi)
        if self.pole == "north":
            return (0.0, 2 * math.pi)
        if self.pole == "both":
            return (-math.pi / 2, 3 * math.pi / 2)  # the whole circle, both poles inside
        return (0.0, math.pi)

    @property
    def pole_theta(self) -> float | None:
        """``theta`` of the pole the motion can pass (0 or pi), or ``None`` (also for ``"both"``:
        see :attr:`pole_thetas`)."""
        return None if self.pole is None else {"south": 0.0, "north": math.pi}.get(self.pole)

    @property
    def pole_thetas(self) -> tuple[float, ...]:
        """``theta`` of every pole the motion can pass: ``()``, ``(0,)``, ``(pi,)`` or both."""
        poles = {"south": (0.0,), "north": (math.pi,), "both": (0.0, math.pi)}
        return () if self.pole is None else poles.get(self.pole, ())

    # ---- the reduced quantities -------------------------------------------------------------
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

    def P(self, theta: Real) -> Real:
        """``I1 v_tau`` as a function of ``theta`` (eq. 3.8), signed-``s`` convention.

        The integral ``F6 = C2`` (:func:`rollingtop.dynamics.integrals.F6_reduced`) solved for
        ``I1 v_tau`` with :meth:`w_n` substituted, in the cancellation-free form of :meth:`_q`
        (tested against ``F6_reduced``).
        """
        _, q2, _, _ = self._q(theta)
        return q2 + self.C2 + self.M3 * self.body.a3 * theta

    def w_n(self, theta: Real) -> Real:
        """``w_n = (M3 gamma3 - C1) / (I1 s)`` (eq. 3.8)."""
        q1, _, _, _ = self._q(theta)
        return -q1 / self.body.I1

    def v_tau(self, theta: Real) -> Real:
        """``v_tau`` (eq. 3.8)."""
        return self.P(theta) / self.body.I1

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

    @overload
    def d2U(self, theta: float) -> float: ...
    @overload
    def d2U(self, theta: FloatArray) -> FloatArray: ...
    def d2U(self, theta: float | FloatArray) -> float | FloatArray:
        """``d^2U/dtheta^2`` by the complex step ``Im dU(theta + i h)/h`` (exact to round-off)."""
        z: ComplexArray = np.asarray(theta, dtype=float) + 1j * _COMPLEX_STEP
        return np.imag(self.dU(z)) / _COMPLEX_STEP  # a numpy float for a float theta

    def rho(self, theta: Real) -> Real:
        """Invariant-measure density, also the reduced motion's mass: ``rho(cos theta)`` (3.5)."""
        rho: Real = self.body.rho(np.cos(theta))
        return rho

    def drho(self, theta: Real) -> Real:
        """``d rho(cos theta) / dtheta = -2 m a3 R sin(theta)``."""
        b = self.body
        drho: Real = -2 * b.m * b.a3 * b.R * np.sin(theta)
        return drho

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

    # ---- in gamma3 (the paper's variables) ---------------------------------------------------
    @overload
    @staticmethod
    def theta_of(gamma3: float) -> float: ...
    @overload
    @staticmethod
    def theta_of(gamma3: FloatArray) -> FloatArray: ...
    @staticmethod
    def theta_of(gamma3: float | FloatArray) -> float | FloatArray:
        """``theta = arccos(gamma3)`` in ``[0, pi]`` (unsigned, the paper's branch)."""
        g = np.asarray(gamma3, dtype=float)
        theta: float | FloatArray = np.arccos(np.clip(g, -1.0, 1.0))  # numpy float for a float
        return theta

    def U_gamma3(self, gamma3: Real) -> Real:
        """``U(gamma3)`` exactly as ``docs/model.md`` defines it, for ``gamma3`` in ``(-1, 1)``
        (and at the pole of a pole case)."""
        return self.U(self.theta_of(gamma3))

    # ---- the one-degree-of-freedom system: h = rho w_tau^2 / 2 + U(theta), theta' = -w_tau ------
    def energy(self, theta: Real, w_tau: Real) -> Real:
        """Reduced energy ``h = rho w_tau^2 / 2 + U`` at ``(theta, w_tau)`` (arrays broadcast)."""
        return self.U(theta) + 0.5 * self.rho(theta) * w_tau * w_tau

    def w_tau(self, theta: Real, h: float, gap: Real | None = None) -> Real:
        """``|w_tau| = sqrt(2 (h - U) / rho)`` at ``theta`` on the orbit of reduced energy ``h``
        (:meth:`energy` solved for ``w_tau``; the sign is the branch), 0 where ``h < U``.

        ``gap`` replaces ``h - U(theta)`` where it is known more accurately (next to a turning
        point, :func:`rollingtop.reduction._quadrature.energy_gap`).
        """
        if gap is None:
            gap = h - self.U(theta)
        w_tau: Real = np.sqrt(np.maximum(2 * gap / self.rho(theta), 0.0))
        return w_tau

    def flow(self, theta: Real, w_tau: Real) -> tuple[Real, Real]:
        """The equations of motion ``(theta', w_tau')`` on the level set:

            theta' = -w_tau,    w_tau' = (U'(theta) + rho'(theta) w_tau^2 / 2) / rho,

        from ``h = rho theta'^2 / 2 + U`` conserved; regular through the pole of a pole case. The
        same motion as the reduced system :func:`rollingtop.reduction.reduced_rhs` (eq. 3.3), in
        the variables of the level set.
        """
        w_tau_dot: Real = (self.dU(theta) + 0.5 * self.drho(theta) * w_tau**2) / self.rho(theta)
        return -w_tau, w_tau_dot

    def linearised_eigenvalues(self, gamma3: float) -> ComplexArray:
        """Eigenvalues of the reduced equations (eq. 3.3) linearised at the steady motion at
        ``gamma3``, by central differences of :func:`rollingtop.reduction.reduced_rhs` at
        ``(gamma3, v_tau, w_n, 0)`` (:func:`rollingtop.reduction.steady.linearised_eigenvalues`
        says why)."""
        from rollingtop.reduction.system import reduced_eigenvalues

        theta = math.acos(gamma3)
        x0 = np.array([gamma3, float(self.v_tau(theta)), float(self.w_n(theta)), 0.0])
        return reduced_eigenvalues(self.body, self.M3, x0)

    def curvature_eigenvalues(self, gamma3: float) -> ComplexArray:
        """``+-sqrt(-U''/rho)`` and 0 at the steady motion at ``gamma3``: the one degree of
        freedom ``(theta, w_tau)`` linearised, the level's integrals held (a model without the
        reduced equations of :meth:`linearised_eigenvalues`)."""
        theta = math.acos(gamma3)
        root = np.sqrt(complex(-float(self.d2U(theta)) / float(self.rho(theta))))
        return np.array([root, -root, 0.0], dtype=complex)

    def pole_label(self) -> str:
        """The pole case in words, for :meth:`describe` (empty for no pole case)."""
        return {
            None: "",
            "south": " (south pole case)",
            "north": " (north pole case)",
            "both": " (no spin: both poles)",
        }[self.pole]

    def describe(self) -> str:
        """One line naming the level set."""
        return f"M3 = {self.M3:g}, C1 = {self.C1:g}, C2 = {self.C2:g}{self.pole_label()}"

    def _repr_html_(self) -> str:
        """The notebook's view: model, integrals, body, the steady motions' count."""
        return html_view(self)

    def plot(self, ax: Axes | None = None, **kw: Any) -> Axes:
        """Draw the phase portrait of ``rollingtop portrait`` (upper panel) on ``ax`` (default:
        a new figure's) and return ``ax``; ``kw`` go to
        :func:`rollingtop.plot.portrait.draw_portrait` (``h_levels``, ``show_contact``)."""
        axes: Axes = draw("portrait", ax, self, **kw)
        return axes


def near_north(level: LevelSet) -> bool:
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
