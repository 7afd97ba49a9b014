"""The smooth model's reduction to one degree of freedom: the heavy symmetric top on a
frictionless plane (``docs/model.md``, "Reductions of the other models").

On a smooth plane the only force besides gravity is the vertical reaction ``N gamma``. So the
horizontal momentum is conserved (the centre of mass drifts uniformly; its size
``p_horizontal = m |v_horizontal|`` is a level variable), and so are ``F3 = I3 w3 = M3``
(Lagrange: the reaction has no torque about the axis of a body of revolution whose centre lies
on it) and the area integral ``F5 = (I w, gamma) = C1`` (no torque about the vertical through
the centre of mass). The height of the centre of mass is ``R + a3 gamma3``, so its vertical
velocity is ``a3 gamma3' = a3 s w_tau``; ``w_n`` follows from ``C1`` as in the meridian model
(``C1 = gamma3 M3 - I1 s w_n``). Then

    h   = rho_s(theta) w_tau^2 / 2 + U_s(theta),      theta' = -w_tau,
    U_s = (C1 - M3 cos theta)^2 / (2 I1 sin^2 theta) + m g a3 cos theta + p_horizontal^2 / (2 m),
    rho_s = I1 + m a3^2 sin^2 theta,

with ``h = E - I3 w3^2 / 2 - m g R`` as for the meridian model: Lagrange's top about its centre
of mass, with the mass ``m a3^2 sin^2`` of the vertical motion added (Routh, "Advanced Rigid
Dynamics", Sec. 242; Goldstein, "Classical Mechanics", Sec. 5.7, for the top on a fixed point).
The level ``(M3, C1)`` has the meridian model's pole structure (``C1 = +-M3`` lets a pole touch
the plane), so the signed nutation angle and the pole cases of
:class:`~rollingtop.reduction.LevelSet` carry over unchanged; ``C2`` is not an integral here and
is 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop.body import SphericalTop
from rollingtop.reduction._services import (
    _Analytic,
    _AnalyticResult,
    check_level_size,
    check_level_values,
)
from rollingtop.reduction.level import (
    Level,
    LevelSetError,
    Real,
    SpinAndArea,
)

__all__ = ["SmoothLevel", "smooth_integrals"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SmoothLevel(SpinAndArea, Level):
    """A level set ``(M3, C1, p_horizontal)`` of the Lagrange and area integrals and the size of
    the horizontal momentum on a smooth plane (module docstring): the spin, ``w_n``, the
    precession and the pole cases ``C1 = +-M3`` of the meridian model's
    (:class:`~rollingtop.reduction.level.SpinAndArea`), with the smooth model's potential and
    mass."""

    integrals: ClassVar[tuple[str, ...]] = ("M3", "C1", "p_horizontal")
    model: ClassVar[str] = "smooth"
    pole_advice: ClassVar[str] = "for the pole case set C1 = +-M3 exactly; or rescale M3, C1"

    body: SphericalTop
    M3: float
    C1: float
    #: The size ``m |v_horizontal|`` of the horizontal momentum (its direction is free).
    p_horizontal: float = field(default=0.0, kw_only=True)
    scale: float = field(default=0.0, kw_only=True)
    #: Set from ``(M3, C1)`` at construction (:class:`~rollingtop.reduction.LevelSet`'s).
    pole: str | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        p = self.p_horizontal
        if isinstance(p, bool) or not isinstance(p, int | float | np.floating | np.integer):
            raise LevelSetError(f"level p_horizontal = {p!r} must be a number")
        if not (math.isfinite(p) and p >= 0.0):
            raise LevelSetError(
                f"level p_horizontal = {p!r} must be finite and >= 0 (the size "
                "of the horizontal momentum)"
            )
        object.__setattr__(self, "p_horizontal", float(p))
        check_level_values(self, ("M3", "C1"))
        self._decide_pole()
        check_level_size(self)

    def mirrored(self) -> SmoothLevel:
        """The same motions with the body axis reversed: ``theta -> pi - theta``, ``a3 -> -a3``,
        ``M3 -> -M3``, ``C1`` kept (``U``, ``rho`` and ``psi'`` agree at ``pi - theta``)."""
        body = replace(self.body, a3=-self.body.a3)
        return SmoothLevel(body, -self.M3, self.C1, p_horizontal=self.p_horizontal)

    def P(self, theta: Real) -> Real:
        """0: no rolling ties the horizontal velocity to the turning (it is constant)."""
        return 0.0 * theta

    def U(self, theta: Real) -> Real:
        """``U_s = q1^2 / (2 I1) + m g a3 cos(theta) + p_horizontal^2 / (2 m)``,
        ``q1 = (C1 - M3 cos) / sin`` (module docstring; :meth:`~rollingtop.reduction.LevelSet._q`
        keeps it exact near a pole)."""
        b = self.body
        q1, _, _, _ = self._q(theta)
        drift = self.p_horizontal * self.p_horizontal / (2 * b.m)  # inf, not OverflowError
        U: Real = q1**2 / (2 * b.I1) + b.m * b.g * b.a3 * np.cos(theta) + drift
        return U

    def dU(self, theta: _Analytic) -> _AnalyticResult:  # type: ignore[override]
        """``dU_s/dtheta`` (analytic: the complex step of ``d2U`` goes through it)."""
        b = self.body
        q1, _, dq1, _ = self._q(theta)
        return q1 * dq1 / b.I1 - b.m * b.g * b.a3 * np.sin(theta)

    def rho(self, theta: Real) -> Real:
        """``rho_s = I1 + m a3^2 sin^2(theta)``: the reduced motion's mass, and the density of
        its invariant measure."""
        b = self.body
        rho: Real = b.I1 + b.m * b.a3**2 * np.sin(theta) ** 2
        return rho

    def drho(self, theta: Real) -> Real:
        """``d rho_s / dtheta = 2 m a3^2 sin(theta) cos(theta)``."""
        b = self.body
        drho: Real = 2 * b.m * b.a3**2 * np.sin(theta) * np.cos(theta)
        return drho

    def com_velocity(self, theta: Real, w_tau: Real, frame: dict[str, FloatArray]) -> FloatArray:
        """The centre of mass's velocity (body frame): ``a3 s w_tau gamma`` vertically (the
        height ``R + a3 gamma3`` changes at ``a3 gamma3' = a3 s w_tau``) and
        ``p_horizontal / m`` along ``tau`` (horizontal); shapes as in
        :meth:`~rollingtop.reduction.LevelSet.com_velocity`."""
        s = np.sin(np.asarray(theta, dtype=float))[..., None]
        wt = np.asarray(w_tau, dtype=float)[..., None]
        b = self.body
        out: FloatArray = b.a3 * s * wt * frame["gamma"] + self.p_horizontal / b.m * frame["tau"]
        return out

    def uniform_drift(self) -> float:
        """``p_horizontal / m``: the centre of mass drifts uniformly at this speed, in a
        direction the level does not fix (the horizontal momentum's)."""
        return self.p_horizontal / self.body.m

    #: No reduced equations of the paper's (eq. 3.3) for this model: the one degree of freedom's
    #: own linearisation (:meth:`~rollingtop.reduction.Level.curvature_eigenvalues`).
    linearised_eigenvalues = Level.curvature_eigenvalues

    def describe(self) -> str:
        """One line naming the level set."""
        drift = f", p_horizontal = {self.p_horizontal:g}" if self.p_horizontal else ""
        return f"M3 = {self.M3:g}, C1 = {self.C1:g}{drift}{self.pole_label()}"


def smooth_integrals(body: SphericalTop, Y: ArrayLike) -> dict[str, FloatArray]:
    """``M3 = I3 w3``, ``C1 = (I w, gamma)``, ``p_horizontal = m |v_horizontal|`` and the
    reduced energy ``h = E - I3 w3^2/2 - m g R`` of states ``Y`` (shape ``(..., 18)``) under
    the smooth model, each of shape ``(...)`` (module docstring)."""
    from rollingtop.dynamics.integrals import area, energy, lagrange

    Y = np.asarray(Y, dtype=float)
    v, gamma = Y[..., 0:3], Y[..., 12:15]
    vertical = np.sum(v * gamma, axis=-1)
    horizontal2 = np.sum(v * v, axis=-1) - vertical**2
    M3 = lagrange(body, Y)
    h = energy(body, Y) - M3**2 / (2 * body.I3) - body.m * body.g * body.R
    p = body.m * np.sqrt(np.maximum(horizontal2, 0.0))
    return {"M3": M3, "C1": area(body, Y), "p_horizontal": p, "h": h}
