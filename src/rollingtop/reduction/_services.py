"""The reduction's protocol: :class:`Level`, the abstract level set of a model reduced to one
degree of freedom, and the checks every level runs at construction.

A level is a particle of mass ``rho(theta)`` in the potential ``U(theta)``, ``theta`` the
nutation angle (``gamma3 = cos theta``): ``h = rho theta'^2 / 2 + U``, ``theta' = -w_tau``.
Each reduced model implements the abstract methods (its integrals, ``U`` and ``dU``, ``rho``,
the spin, ``w_n`` and ``I1 v_tau``, the precession rate, the full energy, its poles, its
mirror image, its eigenvalues); :class:`Level` derives the rest from them (the energy and
``w_tau``, the flow, the normal force, the centre of mass's velocity, the domain in ``theta``).
Everything downstream (steady motions, orbits, portraits, starting a motion on a level, the
motion in absolute space) asks the level through these, whatever the model. A new reduced model
is one module with its :class:`Level` and one entry in
:data:`rollingtop.reduction.models.REDUCTIONS`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any, ClassVar, TypeAlias, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from rollingtop._errors import RollingTopError
from rollingtop._figures import draw
from rollingtop._html import html_view
from rollingtop._layout import N_STATE
from rollingtop.body import OVERFLOW_DECADES, SphericalTop, largest_input

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "ComplexArray",
    "Level",
    "LevelSetError",
    "PoleLevelError",
    "Real",
    "check_level_size",
    "check_level_values",
]

FloatArray: TypeAlias = NDArray[np.float64]
ComplexArray: TypeAlias = NDArray[np.complex128]
#: ``theta`` for :meth:`Level.dU`, also complex (the complex step of ``d2U``).
_Analytic: TypeAlias = float | FloatArray | ComplexArray
#: What numpy's stubs make of arithmetic on ``_Analytic`` (complex of unspecified precision).
_AnalyticResult: TypeAlias = float | FloatArray | NDArray[np.complexfloating[Any, Any]]
#: Step of the complex-step derivative (exact to round-off for analytic functions).
_COMPLEX_STEP = 1e-30
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
        blamed, decades = largest_input(level.body, np.zeros(N_STATE))  # the body's alone
        cause = f"; {blamed}" if decades >= OVERFLOW_DECADES else ""
        raise LevelSetError(
            f"level {level.describe()} is too large for double precision: its effective "
            f"potential reaches {size:.3g} at gamma3 = 0 (at most {_MAX_U:g}{cause}; rescale "
            "units)"
        )


class Level(ABC):
    """A level set of a reduced model (module docstring): the abstract methods are the model's,
    the others follow from them.

    Attributes
    ----------
    body : SphericalTop
        Dynamically symmetric.
    scale : float
        The size of the terms the level's values were computed from (``|I w|`` of a state; 0
        for given values): round-off of that size counts as zero in the pole decision.
    pole : {None, "south", "north", "both"}
        The poles a motion of the level can pass (``theta`` is then signed, see
        :attr:`theta_domain`); set at construction.
    """

    body: SphericalTop
    scale: float
    pole: str | None
    #: The contact model whose reduction this is (:mod:`rollingtop.reduction.models`).
    model: ClassVar[str]
    #: The integrals that name the level, in order (:attr:`ContactModel.reduction`): the keys
    #: of a ``[level]`` table and of the level in JSON output (:meth:`values`).
    integrals: ClassVar[tuple[str, ...]]
    #: :meth:`full_energy` in words.
    energy_formula: ClassVar[str]
    #: What to do about a wall of ``U`` too thin for doubles next to a pole (a level within
    #: round-off of a pole level): :func:`rollingtop.reduction.orbits.orbits`' refusal says it.
    pole_advice: ClassVar[str] = "rescale the level's integrals"
    #: What :meth:`pole_label` calls a level through one pole: the meridian model's "pole case"
    #: (``C1 = +-M3``), another model's "pole level".
    pole_noun: ClassVar[str] = "case"
    #: Whether :func:`rollingtop.reduction.near_pole.near_pole` knows this model's limits on
    #: its pole levels (the meridian model's only, so far).
    near_pole_limits: ClassVar[bool] = False

    # ---- the model's own ------------------------------------------------------------------
    @abstractmethod
    def U(self, theta: Real) -> Real:
        """The effective potential at ``theta``."""

    @overload
    def dU(self, theta: Real) -> Real: ...
    @overload
    def dU(self, theta: ComplexArray) -> ComplexArray: ...
    @abstractmethod
    def dU(self, theta: _Analytic) -> _AnalyticResult:
        """``dU/dtheta``, analytic (a complex ``theta`` gives the complex step of :meth:`d2U`)."""

    @abstractmethod
    def rho(self, theta: Real) -> Real:
        """The reduced motion's mass, also the density of its invariant measure."""

    @abstractmethod
    def drho(self, theta: Real) -> Real:
        """``d rho / dtheta``."""

    @abstractmethod
    def P(self, theta: Real) -> Real:
        """``I1 v_tau`` at ``theta``."""

    @abstractmethod
    def w_n(self, theta: Real) -> Real:
        """The angular velocity's component along ``n`` at ``theta``."""

    @abstractmethod
    def spin(self, theta: Real) -> Real:
        """The spin ``w3`` at ``theta``."""

    @abstractmethod
    def psi_dot(self, theta: Any) -> Any:
        """The precession rate ``psi' = -w_n / s`` (finite at a pole the level passes)."""

    @abstractmethod
    def full_energy(self, h: float) -> float:
        """The energy ``E`` of the full system on this level at reduced energy ``h``
        (:attr:`energy_formula`)."""

    @abstractmethod
    def pole_offsets(self) -> tuple[float, float]:
        """How far the level is from its south and north pole levels, in the model's own
        measure (0 on a pole level; :func:`rollingtop.reduction.level.near_north`)."""

    @abstractmethod
    def mirrored(self) -> Level:
        """The same motions seen with the body axis reversed: ``theta -> pi - theta``,
        ``a3 -> -a3``; ``U``, ``rho`` and ``psi'`` at ``pi - theta`` there equal those at
        ``theta`` here."""

    @abstractmethod
    def linearised_eigenvalues(self, gamma3: float) -> ComplexArray:
        """Eigenvalues of the motion linearised at the steady motion at ``gamma3`` (a model
        without reduced equations of its own: :meth:`curvature_eigenvalues`)."""

    @abstractmethod
    def describe(self) -> str:
        """One line naming the level set."""

    # ---- derived ----------------------------------------------------------------------------
    @property
    def theta_domain(self) -> tuple[float, float]:
        """Open interval of ``theta`` the motion lives in: ``(0, pi)``; ``(-pi, pi)`` for a south
        pole case, ``(0, 2 pi)`` for a north pole case (the potential is finite at the pole),
        the whole circle for both."""
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

    @overload
    def d2U(self, theta: float) -> float: ...
    @overload
    def d2U(self, theta: FloatArray) -> FloatArray: ...
    def d2U(self, theta: float | FloatArray) -> float | FloatArray:
        """``d^2U/dtheta^2`` by the complex step ``Im dU(theta + i h)/h`` (exact to round-off).

        Next to a pole the step is ``1e-10`` times the distance to it (a truncation error of
        1e-20 relative; the complex step has no cancellation): a steady motion there (a
        mirrored level's, 1e-30 or 1e-75 from the pole) has its curvature on the scale of that
        distance, which a fixed step of 1e-30 straddled, and a step far below it underflowed in
        the barrier's products (``rubber_spin = 1e-150``: the curvature without the barrier)."""
        t = np.asarray(theta, dtype=float)
        near = np.minimum(np.abs(t), np.abs(math.pi - t))
        h = np.where((near > 0) & (near < 1e-20), 1e-10 * near, _COMPLEX_STEP)
        return np.imag(self.dU(t + 1j * h)) / h  # a numpy float for a float theta

    def v_tau(self, theta: Real) -> Real:
        """``v_tau = P / I1`` (:meth:`P`)."""
        return self.P(theta) / self.body.I1

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
        """``U(gamma3)``, for ``gamma3`` in ``(-1, 1)`` (and at the pole of a pole case)."""
        return self.U(self.theta_of(gamma3))

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

        from ``h = rho theta'^2 / 2 + U`` conserved; regular through the pole of a pole case.
        """
        w_tau_dot: Real = (self.dU(theta) + 0.5 * self.drho(theta) * w_tau**2) / self.rho(theta)
        return -w_tau, w_tau_dot

    def curvature_eigenvalues(self, gamma3: float) -> ComplexArray:
        """``+-sqrt(-U''/rho)`` and 0 at the steady motion at ``gamma3``: the one degree of
        freedom ``(theta, w_tau)`` linearised, the level's integrals held."""
        theta = math.acos(gamma3)
        root = np.sqrt(complex(-float(self.d2U(theta)) / float(self.rho(theta))))
        return np.array([root, -root, 0.0], dtype=complex)

    def pole_label(self) -> str:
        """The pole case in words, for :meth:`describe` (empty for no pole case)."""
        if self.pole is None:
            return ""
        if self.pole == "both":
            return " (no spin: both poles)"
        return f" ({self.pole} pole {self.pole_noun})"

    def _repr_html_(self) -> str:
        """The notebook's view: model, integrals, body, the steady motions' count."""
        return html_view(self)

    def plot(self, ax: Axes | None = None, **kw: Any) -> Axes:
        """Draw the phase portrait of ``rollingtop portrait`` (upper panel) on ``ax`` (default:
        a new figure's) and return ``ax``; ``kw`` go to
        :func:`rollingtop.plot.portrait.draw_portrait` (``h_levels``, ``show_contact``)."""
        axes: Axes = draw("portrait", ax, self, **kw)
        return axes

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
