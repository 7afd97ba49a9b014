"""The rough model's reduction to one degree of freedom: Routh's sphere, rolling without slipping
(``docs/model.md``, "Reductions of the other models").

Rolling without slipping, ``v = r x w`` with the arm ``r = -R gamma - a3 e3`` from the centre of
mass to the contact point; in the basis ``(tau, n, e3)`` of ``docs/model.md`` ("Reduced
variables"), ``r = R s n - k e3`` with ``k = R cos(theta) + a3``. A dynamically symmetric body
keeps its energy, Jellett's integral and Routh's (Routh, "Advanced Rigid Dynamics", Sec. 243;
Borisov and Mamaev, "Rigid Body Dynamics", Sec. 2.4 of ch. 4):

    jellett = (I w, r) = I1 R s w_n - I3 k w3,
    routh   = w3 sqrt(f),   f = I1 I3 + m I1 R^2 s^2 + m I3 k^2,

so on a level ``(jellett, routh)`` the spin and ``w_n`` are functions of ``theta``:

    w3  = routh / sqrt(f),     w_n = (jellett + I3 k w3) / (I1 R s),

and the energy ``h = E - m g R`` (the spin's energy is not constant here, so it stays in ``U``):

    h   = rho(theta) w_tau^2 / 2 + U_r(theta),      theta' = -w_tau,
    U_r = I1 w_n^2 / 2 + I3 w3^2 / 2 + m (R s w3 + k w_n)^2 / 2 + m g a3 cos(theta),
    v   = (R s w3 + k w_n) tau - k w_tau n - R s w_tau e3   (so v_tau = R s w3 + k w_n),
    rho = I1 + m (R^2 + a3^2 + 2 a3 R cos theta)   (the meridian model's: the same rolling
                                                     along tau),

from ``T = (I w, w)/2 + m |r x w|^2/2`` with ``|r x w|^2 = |r|^2 |w|^2 - (r, w)^2``.

``w_n`` grows like ``1/s`` at a pole unless ``jellett + I3 k w3`` vanishes there: every other
level has walls at both poles and its motions stay inside ``0 < theta < pi``. On a **pole
level** (``pole = "south"``: ``jellett = -I3 k0 w3(0)`` with ``k0 = R + a3``, the level of the
sleeping top and of every motion through the upright vertical; ``"north"`` likewise at
``theta = pi``) ``U`` is finite and smooth through the pole and ``theta`` is signed, in
``(-pi, pi)`` (``(0, 2 pi)`` for the north pole), as for the meridian model's pole cases. There
``jellett + I3 k w3 = I3 routh (k / sqrt(f) - k0 / sqrt(f0))``, a difference that cancels next
to the pole; with ``sigma = sin^2(theta/2)`` it is written without cancellation,

    k^2 f0 - k0^2 f = -2 R I1 sigma (I3 (k + k0) + 2 m R (1 - sigma) k0^2),

so ``w_n = -I3 routh tan(theta/2) (I3 (k + k0) + 2 m R (1 - sigma) k0^2)
/ (sqrt(f f0) (k sqrt(f0) + k0 sqrt(f)))`` (while ``k > 0``; beyond, the two terms of the
difference have opposite signs and it is taken as it stands). The north pole level is the
south one of the mirrored body (:meth:`RoughLevel.mirrored`). With no spin at all
(``jellett = routh = 0``) both poles are pole levels: ``w3 = w_n = 0`` and ``U = m g a3 cos``,
the planar rocking and rolling over of :mod:`rollingtop.reduction.no_spin`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

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
    Real,
    RollingMass,
    SpinInPotential,
)

__all__ = ["RoughLevel", "rough_integrals"]

FloatArray = NDArray[np.float64]
#: ``|jellett + I3 k w3|`` at a pole below this times the level's size is a pole level.
POLE_LEVEL_TOLERANCE = 1e-9


@dataclass(frozen=True, kw_only=True)
class RoughLevel(SpinInPotential, RollingMass, Level):
    """A level set ``(jellett, routh)`` of Routh's sphere (module docstring): the rough model's
    potential, spin and centre-of-mass velocity, with the rolling body's mass
    (:class:`~rollingtop.reduction.level.RollingMass`)."""

    integrals: ClassVar[tuple[str, ...]] = ("jellett", "routh")
    pole_noun: ClassVar[str] = "level"
    model: ClassVar[str] = "rough"
    near_pole_limits: ClassVar[bool] = False
    #: :attr:`LevelSet.pole_advice`.
    pole_advice: ClassVar[str] = "for the pole level set jellett = -I3 (R +- a3) w3 exactly"

    #: Keyword-only: only ``body`` is positional, so a value given in the meridian model's
    #: order (``M3, C1, C2``) is refused.
    body: SphericalTop = field(kw_only=False)
    scale: float = 0.0
    #: Set at construction: the pole levels (module docstring).
    pole: str | None = field(init=False, repr=False, compare=False)
    jellett: float
    routh: float

    def __post_init__(self) -> None:
        check_level_values(self, ("jellett", "routh"))
        # values read from a state: round-off of |I w| |r| (scale) counts as zero
        size = max(
            abs(self.jellett),
            abs(self.routh) * self.body.R,
            abs(float(self.scale)) * (self.body.R + abs(self.body.a3)),
            1e-300,
        )
        south, north = (abs(x) <= POLE_LEVEL_TOLERANCE * size for x in self.pole_offsets())
        pole = "both" if south and north else "south" if south else "north" if north else None
        if pole == "both":  # no spin: jellett = routh = 0 exactly (module docstring)
            object.__setattr__(self, "jellett", 0.0)
            object.__setattr__(self, "routh", 0.0)
        elif pole is not None:  # snapped to the pole level exactly, so that its mirror image
            b = self.body  # (the north one's computation) is the same pole level
            k = b.R * (1.0 if pole == "south" else -1.0) + b.a3
            exact = -b.I3 * k * self.routh / math.sqrt(b.I1 * b.I3 + b.m * b.I3 * k * k)
            object.__setattr__(self, "jellett", exact)
        object.__setattr__(self, "pole", pole)
        check_level_size(self)

    def mirrored(self) -> RoughLevel:
        """The same motions with the body axis reversed: ``theta -> pi - theta``,
        ``a3 -> -a3``, ``w3 -> -w3`` (so ``routh -> -routh``), ``jellett`` kept."""
        body = replace(self.body, a3=-self.body.a3)
        return RoughLevel(body, jellett=self.jellett, routh=-self.routh)

    # ---- the spin, w_n and their derivatives, complex-safe (the complex step of d2U) -------
    def _parts(self, theta: Any) -> tuple[Any, ...]:
        """``(s, c, k, w3, w_n)`` and their theta-derivatives ``(k', w3', w_n')``."""
        if self.pole == "north":  # the south pole level of the mirrored body, theta -> pi - theta
            s, c, k, w3, w_n, dk, dw3, dw_n = self.mirrored()._parts(np.pi - theta)
            return s, -c, -k, -w3, w_n, dk, dw3, -dw_n
        b = self.body
        s, c = np.sin(theta), np.cos(theta)
        k, dk = b.R * c + b.a3, -b.R * s
        f = b.I1 * b.I3 + b.m * b.I1 * b.R**2 * s**2 + b.m * b.I3 * k**2
        df = 2 * b.m * b.R * s * (b.I1 * b.R * c - b.I3 * k)
        w3 = self.routh / np.sqrt(f)
        dw3 = -0.5 * w3 * df / f
        if self.pole == "both":  # no spin: w3 = w_n = 0
            zero = 0.0 * s
            return s, c, k, w3, zero, dk, dw3, zero
        if self.pole == "south":
            w_n = self._pole_w_n(theta, k, f)
            # d(w_n)/dtheta from N' = I1 R (s w_n)': w_n' = (N' / (I1 R) - c w_n) / s, regular
            # at the pole by l'Hopital: there w_n' = N''(0) / (2 I1 R)
            dN = b.I3 * (dw3 * k + w3 * dk)
            with np.errstate(all="ignore"):
                dw_n = (dN / (b.I1 * b.R) - c * w_n) / s
            dw_n = np.where(np.abs(s) < 1e-8, self._pole_dw_n0(), dw_n)
            if not np.ndim(s):
                dw_n = dw_n[()]
            return s, c, k, w3, w_n, dk, dw3, dw_n
        N = self.jellett + b.I3 * k * w3
        dN = b.I3 * (dw3 * k + w3 * dk)
        w_n = N / (b.I1 * b.R * s)
        dw_n = dN / (b.I1 * b.R * s) - w_n * c / s
        return s, c, k, w3, w_n, dk, dw3, dw_n

    def _pole_w_n(self, theta: Any, k: Any, f: Any) -> Any:
        """``w_n`` on the south pole level, free of cancellation next to the pole (module
        docstring)."""
        b = self.body
        k0 = b.R + b.a3
        f0 = b.I1 * b.I3 + b.m * b.I3 * k0 * k0
        half = np.sin(theta / 2)
        sigma = half * half
        rf, rf0 = np.sqrt(f), math.sqrt(f0)
        bracket = b.I3 * (k + k0) + 2 * b.m * b.R * (1 - sigma) * k0 * k0
        with np.errstate(all="ignore"):
            denominator = rf * rf0 * (k * rf0 + k0 * rf)
            near = -b.I3 * self.routh * np.tan(theta / 2) * bracket / denominator
            far = b.I3 * self.routh * (k / rf - k0 / rf0) / (b.I1 * b.R * np.sin(theta))
        out = np.where(np.real(k) > 0, near, far)
        return out if np.ndim(k) else out[()]

    def _pole_dw_n0(self) -> float:
        """``w_n'(0)`` on the south pole level: ``tan(theta/2) ~ theta/2`` in :meth:`_pole_w_n`."""
        b = self.body
        k0 = b.R + b.a3
        f0 = b.I1 * b.I3 + b.m * b.I3 * k0 * k0
        bracket = 2 * b.I3 * k0 + 2 * b.m * b.R * k0 * k0
        return float(-b.I3 * self.routh * 0.5 * bracket / (f0 * 2 * k0 * math.sqrt(f0)))

    def _numerator(self, theta: float) -> float:
        """``jellett + I3 k w3`` at ``theta``: ``I1 R s w_n``, 0 at a pole of a pole level."""
        b = self.body
        k = b.R * math.cos(theta) + b.a3
        s = math.sin(theta)
        f = b.I1 * b.I3 + b.m * b.I1 * b.R**2 * s**2 + b.m * b.I3 * k**2
        return self.jellett + b.I3 * k * self.routh / math.sqrt(f)

    def spin(self, theta: Real) -> Real:
        """``w3 = routh / sqrt(f)`` (module docstring)."""
        out: Real = self._parts(theta)[3]
        return out

    def w_n(self, theta: Real) -> Real:
        """``w_n = (jellett + I3 k w3) / (I1 R s)`` (module docstring)."""
        out: Real = self._parts(theta)[4]
        return out

    def P(self, theta: Real) -> Real:
        """``I1 v_tau``: rolling ties ``v_tau`` to the spin and ``w_n``. With ``v = r x w``,
        ``r = R s n - k e3`` and the right-handed ``(tau, n, e3)``:
        ``v = (R s w3 + k w_n) tau - k w_tau n - R s w_tau e3`` -- the meridian model's ``n`` and
        ``e3`` components (:meth:`~rollingtop.reduction.LevelSet.com_velocity` serves both)."""
        s, _, k, w3, w_n, _, _, _ = self._parts(theta)
        out: Real = self.body.I1 * (self.body.R * s * w3 + k * w_n)
        return out

    def U(self, theta: Real) -> Real:
        """``U_r`` (module docstring)."""
        b = self.body
        s, c, k, w3, w_n, _, _, _ = self._parts(theta)
        A = b.R * s * w3 + k * w_n
        U: Real = 0.5 * (b.I1 * w_n**2 + b.I3 * w3**2 + b.m * A**2) + b.m * b.g * b.a3 * c
        return U

    def dU(self, theta: _Analytic) -> _AnalyticResult:  # type: ignore[override]
        """``dU_r/dtheta`` (analytic: the complex step of ``d2U`` goes through it)."""
        b = self.body
        s, c, k, w3, w_n, dk, dw3, dw_n = self._parts(theta)
        A = b.R * s * w3 + k * w_n
        dA = b.R * c * w3 + b.R * s * dw3 + dk * w_n + k * dw_n
        out: _AnalyticResult = (
            b.I1 * w_n * dw_n + b.I3 * w3 * dw3 + b.m * A * dA - b.m * b.g * b.a3 * s
        )
        return out

    def psi_dot(self, theta: float | FloatArray) -> float | FloatArray:
        """Precession rate ``psi' = -w_n / s`` (kinematics, as for every model); on a pole level
        finite at the pole (``w_n ~ s``): its limit there."""
        parts = self._parts(theta)  # s of the mirror image (pi - theta) for the north pole
        s, w_n = parts[0], parts[4]
        if self.pole in ("south", "north"):  # w_n ~ w_n'(pole) s next to the pole
            pole, mirror = (0.0, self) if self.pole == "south" else (math.pi, self.mirrored())
            with np.errstate(all="ignore"):
                away = -w_n / s
            near = np.abs(np.asarray(theta) - pole) < 1e-8
            rate: float | FloatArray = np.where(near, -mirror._pole_dw_n0(), away)
            return rate if np.ndim(theta) else float(rate)
        rate = -w_n / s
        return rate

    def pole_offsets(self) -> tuple[float, float]:
        """``jellett + I3 k w3`` at the south and north poles: 0 on a pole level
        (:func:`~rollingtop.reduction.level.near_north` mirrors a level nearer the north one)."""
        return self._numerator(0.0), self._numerator(math.pi)

    #: No reduced equations of the paper's (eq. 3.3) for this model: the one degree of freedom's
    #: own linearisation (:meth:`~rollingtop.reduction.Level.curvature_eigenvalues`).
    linearised_eigenvalues = Level.curvature_eigenvalues

    def describe(self) -> str:
        """One line naming the level set."""
        return f"jellett = {self.jellett:g}, routh = {self.routh:g}{self.pole_label()}"


def rough_integrals(body: SphericalTop, Y: ArrayLike) -> dict[str, FloatArray]:
    """Jellett's and Routh's integrals and the reduced energy ``h = E - m g R`` of states ``Y``
    (shape ``(..., 18)``) under the rough model, each of shape ``(...)``."""
    from rollingtop.dynamics.integrals import energy, jellett, routh

    Y = np.asarray(Y, dtype=float)
    h = energy(body, Y) - body.m * body.g * body.R
    return {"jellett": jellett(body, Y), "routh": routh(body, Y), "h": h}
