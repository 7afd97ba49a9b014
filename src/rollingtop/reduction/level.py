"""Level sets of the integrals and the effective potential (paper Sec. 3.3, eqs. 3.8-3.11).

On a level set ``(M3, C1, C2)`` of the Lagrange, area and F6 integrals the meridian model reduces
to one degree of freedom (``MODEL.md``, "One degree of freedom"):

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
from dataclasses import dataclass

import numpy as np

from rollingtop._errors import RollingTopError
from rollingtop.body import SphericalTop

__all__ = ["LevelSet", "LevelSetError", "POLE_TOLERANCE"]

#: ``|C1 - M3|`` (or ``|C1 + M3|``) below this times ``max(|M3|, |C1|, 1e-300)`` is a pole case.
POLE_TOLERANCE = 1e-12
#: Step of the complex-step derivative (exact to round-off for analytic functions).
_COMPLEX_STEP = 1e-30


class LevelSetError(RollingTopError):
    """Inconsistent level set, or a level with no motion."""


@dataclass(frozen=True)
class LevelSet:
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

    Attributes
    ----------
    pole : {None, "south", "north"}
        ``"south"`` when ``C1 = M3`` (the pole ``gamma3 = 1`` can touch the plane), ``"north"``
        when ``C1 = -M3``, within :data:`POLE_TOLERANCE`; in these cases ``C1`` is snapped to
        ``+-M3`` exactly.
    """

    body: SphericalTop
    M3: float
    C1: float
    C2: float

    def __post_init__(self) -> None:
        for name in ("M3", "C1", "C2"):
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, int | float | np.floating | np.integer):
                raise LevelSetError(f"level {name} = {x!r} must be a number")
            if not math.isfinite(x):
                raise LevelSetError(f"level {name} = {x!r} must be finite")
            object.__setattr__(self, name, float(x))
        if not self.body.symmetric:
            raise LevelSetError(
                f"the reduction needs a dynamically symmetric body (I1 = I2), got "
                f"I1 = {self.body.I1:g}, I2 = {self.body.I2:g}"
            )
        scale = max(abs(self.M3), abs(self.C1), 1e-300)
        pole = None
        if abs(self.C1 - self.M3) <= POLE_TOLERANCE * scale:
            pole = "south"
            object.__setattr__(self, "C1", self.M3)
        elif abs(self.C1 + self.M3) <= POLE_TOLERANCE * scale:
            pole = "north"
            object.__setattr__(self, "C1", -self.M3)
        object.__setattr__(self, "pole", pole)

    # ---- domain in theta ------------------------------------------------------------------
    @property
    def theta_domain(self) -> tuple[float, float]:
        """Open interval of ``theta`` the motion lives in: ``(0, pi)``; ``(-pi, pi)`` for a south
        pole case, ``(0, 2 pi)`` for a north pole case (the potential is finite at the pole)."""
        if self.pole == "south":
            return (-math.pi, math.pi)
        if self.pole == "north":
            return (0.0, 2 * math.pi)
        return (0.0, math.pi)

    @property
    def pole_theta(self) -> float | None:
        """``theta`` of the pole the motion can pass (0 or pi), or ``None``."""
        return {"south": 0.0, "north": math.pi}.get(self.pole)

    # ---- the reduced quantities -------------------------------------------------------------
    def _q(self, theta):
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
        c, s = np.cos(theta), np.sin(theta)
        N = b.R * (M3 - C1 * c) + b.a3 * (M3 * c - C1)
        return (
            (C1 - M3 * c) / s,
            N / s,
            (M3 - C1 * c) / s**2,
            (b.R * C1 - b.a3 * M3) - N * c / s**2,
        )

    def P(self, theta):
        """``I1 v_tau`` as a function of ``theta`` (eq. 3.8), signed-``s`` convention."""
        _, q2, _, _ = self._q(theta)
        return q2 + self.C2 + self.M3 * self.body.a3 * theta

    def w_n(self, theta):
        """``w_n = (M3 gamma3 - C1) / (I1 s)`` (eq. 3.8)."""
        q1, _, _, _ = self._q(theta)
        return -q1 / self.body.I1

    def v_tau(self, theta):
        """``v_tau`` (eq. 3.8)."""
        return self.P(theta) / self.body.I1

    def U(self, theta):
        """Effective potential ``U`` (eq. 3.11, ``MODEL.md``) at ``theta``."""
        b = self.body
        q1, _, _, _ = self._q(theta)
        P = self.P(theta)
        return q1**2 / (2 * b.I1) + b.m * P**2 / (2 * b.I1**2) + b.m * b.g * b.a3 * np.cos(theta)

    def dU(self, theta):
        """``dU/dtheta`` (analytic)."""
        b = self.body
        q1, q2, dq1, dq2 = self._q(theta)
        P = q2 + self.C2 + self.M3 * b.a3 * theta
        dP = dq2 + self.M3 * b.a3
        return q1 * dq1 / b.I1 + b.m * P * dP / b.I1**2 - b.m * b.g * b.a3 * np.sin(theta)

    def d2U(self, theta):
        """``d^2U/dtheta^2`` by the complex step ``Im dU(theta + i h)/h`` (exact to round-off)."""
        theta = np.asarray(theta, dtype=float)
        return np.imag(self.dU(theta + 1j * _COMPLEX_STEP)) / _COMPLEX_STEP

    def rho(self, theta):
        """Invariant-measure density, also the reduced motion's mass: ``rho(cos theta)`` (3.5)."""
        return self.body.rho(np.cos(theta))

    def psi_dot(self, theta):
        """Precession rate ``psi' = -w_n / s`` (``MODEL.md``, "Motion in absolute space"),
        finite at the pole in a pole case."""
        I1 = self.body.I1
        if self.pole == "south":
            return self.M3 / (I1 * (1 + np.cos(theta)))
        if self.pole == "north":
            return -self.M3 / (I1 * (1 - np.cos(theta)))
        return (self.C1 - self.M3 * np.cos(theta)) / (I1 * np.sin(theta) ** 2)

    # ---- in gamma3 (the paper's variables) ---------------------------------------------------
    @staticmethod
    def theta_of(gamma3):
        """``theta = arccos(gamma3)`` in ``[0, pi]`` (unsigned, the paper's branch)."""
        g = np.asarray(gamma3, dtype=float)
        return np.arccos(np.clip(g, -1.0, 1.0))

    def U_gamma3(self, gamma3):
        """``U(gamma3)`` exactly as ``MODEL.md`` defines it, for ``gamma3`` in ``(-1, 1)`` (and at
        the pole of a pole case)."""
        return self.U(self.theta_of(gamma3))

    def energy(self, theta, w_tau):
        """Reduced energy ``h = rho w_tau^2 / 2 + U``."""
        return 0.5 * self.rho(theta) * np.asarray(w_tau) ** 2 + self.U(theta)

    def describe(self) -> str:
        """One line naming the level set."""
        pole = {None: "", "south": " (south pole case)", "north": " (north pole case)"}[self.pole]
        return f"M3 = {self.M3:g}, C1 = {self.C1:g}, C2 = {self.C2:g}{pole}"
