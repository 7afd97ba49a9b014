"""The rubber model's reduction to one degree of freedom: a body of revolution rolling without
slipping or spinning (``docs/model.md``, "Reductions of the other models").

Rubber rolling keeps ``v = r x w`` and ``(w, gamma) = 0``, so the angular velocity is horizontal:
in the basis ``(tau, n, e3)`` of ``docs/model.md`` ("Reduced variables"), with
``nu = s e3 + gamma3 n`` the horizontal projection of the symmetry axis,

    w = w_tau tau + Omega nu,      w3 = Omega s,   w_n = Omega gamma3.

The full equations give (``rollingtop verify`` proves it; ``tests/symbolic``) a *linear* equation
for ``Omega`` along the motion, ``dOmega / dgamma3 = A(gamma3) Omega`` with

    A = gamma3 / s^2 - J'(gamma3) / (2 J),
    J(gamma3) = (I nu, nu) + m (r, gamma)^2 = I1 gamma3^2 + I3 s^2 + m (R + a3 gamma3)^2,

so the integral linear in ``w`` is ``f(gamma3) Omega`` with ``f' = -A f``, a linear ODE in
``gamma3`` whose solution for a sphere is elementary, ``f = s sqrt(J)``. Scaled to the units of
an angular momentum it reads

    rubber_spin = w3 sqrt(I3 J) = w3 sqrt(I3 (I1 + I3 - (I gamma, gamma) + m (r, gamma)^2)),

the analogue of Routh's integral for rolling without spinning (Borisov, Mamaev and Bizyaev,
"The hierarchy of dynamics of a rigid body rolling without slipping and spinning on a plane and
a sphere", Rus. J. Nonlin. Dyn. 9(2), 2013; Borisov and Mamaev, RCD 7(2), 2002, for the body of
revolution). The kinetic energy ``T = (I w, w)/2 + m |r x w|^2 / 2`` splits into
``rho w_tau^2 / 2 + J Omega^2 / 2`` (``(r, w) = -a3 s Omega``, ``r`` has no ``tau`` part), and
``J Omega^2 = rubber_spin^2 / (I3 s^2)``, so on a level ``rubber_spin = F``

    h   = rho(theta) w_tau^2 / 2 + U(theta),      theta' = -w_tau,   h = E - m g R,
    U   = F^2 / (2 I3 sin^2 theta) + m g a3 cos theta,
    rho = I1 + m (R^2 + a3^2 + 2 a3 R cos theta)   (the meridian model's),

where ``I1`` enters through ``rho`` and ``I3`` through the scaling of ``F``; the spin
``w3 = F / sqrt(I3 J)`` carries the rest of the moments into the precession and the path.
``U' = 0`` reads ``F^2 cos = -m g a3 I3 sin^4``: one steady motion, a centre, on every level
with ``F != 0`` (the axis tilted to the side away from the centre of mass), and on ``F = 0``
the rests at the poles (a centre at the pole below the centre of mass).

``F = 0`` is the pole level: ``Omega = 0``, the body rolls in a vertical plane through both poles
(``U = m g a3 cos theta``, the meridian model's no-spin level with ``C2 = 0``), reduced on the
whole circle as the pole case ``"both"`` of :class:`~rollingtop.reduction.LevelSet`.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop.body import SphericalTop
from rollingtop.reduction._services import (
    LevelSetError,
    _Analytic,
    _AnalyticResult,
    check_level_size,
    check_level_values,
)
from rollingtop.reduction.level import (
    POLE_TOLERANCE,
    Level,
    Real,
    RollingMass,
    SpinInPotential,
)

__all__ = ["RubberLevel", "rubber_integrals"]

FloatArray = NDArray[np.float64]

#: The smallest ``|rubber_spin|`` whose level is computed: its square, which the barrier of
#: ``U`` next to the poles holds, stays a normal double with four decades to spare (below it
#: the barrier underflows and the centre next to the pole took the curvature of no spin: a
#: period twice too long at 1e-160, none at all at 1e-200).
SPIN_FLOOR = math.sqrt(1e4 * sys.float_info.min)


@dataclass(frozen=True, kw_only=True)
class RubberLevel(SpinInPotential, RollingMass, Level):
    """A level set ``rubber_spin = F`` of a body of revolution rolling without slipping or
    spinning (module docstring): the rubber model's potential, spin and centre-of-mass velocity,
    with the rolling body's mass (:class:`~rollingtop.reduction.level.RollingMass`). ``F``
    within :data:`~rollingtop.reduction.level.POLE_TOLERANCE` of the level's ``scale`` (``|I w|``
    of a state) is the pole level ``F = 0`` (``pole = "both"``)."""

    integrals: ClassVar[tuple[str, ...]] = ("rubber_spin",)
    model: ClassVar[str] = "rubber"
    near_pole_limits: ClassVar[bool] = False
    #: :attr:`LevelSet.pole_advice`: the pole level is reduced on the whole circle.
    pole_advice: ClassVar[str] = "for the pole level set rubber_spin = 0 exactly"

    #: Keyword-only: only ``body`` is positional, so a value given in the meridian model's
    #: order (``M3, C1, C2``) is refused.
    body: SphericalTop = field(kw_only=False)
    scale: float = 0.0
    #: Set at construction: the pole levels (module docstring).
    pole: str | None = field(init=False, repr=False, compare=False)
    rubber_spin: float

    def __post_init__(self) -> None:
        check_level_values(self, ("rubber_spin",))
        F = self.rubber_spin
        # the round-off of a value read from a state: |F| <~ |w| sqrt(I3 J) <~ |I w| * O(1)
        scale = abs(float(self.scale)) * math.sqrt(
            1.0 + self.body.m * self.body.R**2 / min(self.body.I1, self.body.I3)
        )
        if F == 0.0 or abs(F) <= POLE_TOLERANCE * scale:
            F = 0.0
        elif abs(F) < SPIN_FLOOR:
            raise LevelSetError(
                f"rubber_spin = {F:g} is below {SPIN_FLOOR:.1e}: its steady motion lies within "
                f"{math.sqrt(abs(F)):.0e} of a pole, where the barrier of U underflows double "
                "precision; give rubber_spin = 0 (the level of no spin) or a larger spin"
            )
        object.__setattr__(self, "rubber_spin", F)
        object.__setattr__(self, "pole", "both" if F == 0.0 else None)
        check_level_size(self)

    def pole_offsets(self) -> tuple[float, float]:
        """``rubber_spin`` at both poles: the one pole level ``F = 0`` lets both touch."""
        return self.rubber_spin, self.rubber_spin

    def mirrored(self) -> RubberLevel:
        """The same motions with the body axis reversed: ``theta -> pi - theta``,
        ``a3 -> -a3``, ``w3 -> -w3`` (so ``rubber_spin -> -rubber_spin``; ``J`` is kept)."""
        body = replace(self.body, a3=-self.body.a3)
        return RubberLevel(body, rubber_spin=-self.rubber_spin)

    def _J(self, theta: Any) -> Any:
        """``J = I1 cos^2 + I3 sin^2 + m (R + a3 cos)^2`` (module docstring)."""
        b = self.body
        c, s = np.cos(theta), np.sin(theta)
        return b.I1 * c * c + b.I3 * s * s + b.m * (b.R + b.a3 * c) ** 2

    def spin(self, theta: Real) -> Real:
        """``w3 = rubber_spin / sqrt(I3 J)``."""
        out: Real = self.rubber_spin / np.sqrt(self.body.I3 * self._J(theta))
        return out

    def _omega(self, theta: Real) -> Real:
        """``Omega = w3 / s``, the rate about the axis's horizontal projection (0 on ``F = 0``)."""
        if self.pole == "both":
            zero: Real = 0.0 * theta
            return zero
        out: Real = self.spin(theta) / np.sin(theta)
        return out

    def w_n(self, theta: Real) -> Real:
        """``w_n = Omega gamma3``: ``(w, gamma) = 0``."""
        out: Real = self._omega(theta) * np.cos(theta)
        return out

    def P(self, theta: Real) -> Real:
        """``I1 v_tau = I1 (R s w3 + k w_n)``: rolling, ``v = r x w`` (as
        :meth:`RoughLevel.P <rollingtop.reduction.RoughLevel.P>`; ``k = R cos + a3``)."""
        b = self.body
        k = b.R * np.cos(theta) + b.a3
        out: Real = b.I1 * (b.R * np.sin(theta) * self.spin(theta) + k * self.w_n(theta))
        return out

    def U(self, theta: Real) -> Real:
        """``U = rubber_spin^2 / (2 I3 sin^2) + m g a3 cos`` (module docstring)."""
        b = self.body
        gravity = b.m * b.g * b.a3 * np.cos(theta)
        if self.pole == "both":
            return gravity  # type: ignore[no-any-return]
        F = np.float64(self.rubber_spin)  # overflows to inf (refused), not OverflowError
        U: Real = F * F / (2 * b.I3 * np.sin(theta) ** 2) + gravity
        return U

    def dU(self, theta: _Analytic) -> _AnalyticResult:  # type: ignore[override]
        """``dU/dtheta = -rubber_spin^2 cos / (I3 sin^3) - m g a3 sin`` (analytic: the complex
        step of ``d2U`` goes through it)."""
        b = self.body
        gravity = -b.m * b.g * b.a3 * np.sin(theta)
        if self.pole == "both":
            return gravity
        F = np.float64(self.rubber_spin)
        out: _AnalyticResult = -(F * F) * np.cos(theta) / (b.I3 * np.sin(theta) ** 3) + gravity
        return out

    def psi_dot(self, theta: float | FloatArray) -> float | FloatArray:
        """Precession rate ``psi' = -w_n / s = -Omega cos / sin`` (kinematics; 0 on
        ``F = 0``)."""
        if self.pole == "both":
            return np.zeros_like(np.asarray(theta, dtype=float))
        t = np.asarray(theta, dtype=float)
        rate: float | FloatArray = -self.w_n(t) / np.sin(t)
        return rate

    #: No reduced equations of the paper's (eq. 3.3) for this model: the one degree of freedom's
    #: own linearisation (:meth:`~rollingtop.reduction.Level.curvature_eigenvalues`).
    linearised_eigenvalues = Level.curvature_eigenvalues

    def describe(self) -> str:
        """One line naming the level set."""
        return f"rubber_spin = {self.rubber_spin:g}{self.pole_label()}"


def rubber_integrals(body: SphericalTop, Y: ArrayLike) -> dict[str, FloatArray]:
    """The integral ``rubber_spin`` and the reduced energy ``h = E - m g R`` of states ``Y``
    (shape ``(..., 18)``) under the rubber model, each of shape ``(...)``."""
    from rollingtop.dynamics.integrals import energy, rubber_spin

    Y = np.asarray(Y, dtype=float)
    h = energy(body, Y) - body.m * body.g * body.R
    return {"rubber_spin": rubber_spin(body, Y), "h": h}
