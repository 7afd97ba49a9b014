"""The shell-rotor pair's reduction to one degree of freedom (``docs/model.md``, "Reductions of
the other models"; the pair: :mod:`rollingtop.contact.shell_rotor`).

The rotor obeys the meridian model's kinematics whatever the shell's relative spin ``delta``; the
shell turns with ``Omega = w + delta e3``. In the basis ``(tau, n, e3)`` of ``docs/model.md``
("Reduced variables") the pair's kinetic energy has no cross term in ``w_tau`` (derived with
sympy; ``k_p = (m + ms) R cos + m a3``, ``Omega3 = w3 + delta``):

    2 T = rho_p w_tau^2 + A w_n^2 + 2 R s k_p w_n Omega3 + I3 w3^2
          + (Js + (m + ms) R^2 s^2) Omega3^2,
    rho_p = I1 + Js + ms R^2 + m (R^2 + a3^2 + 2 a3 R cos),
    A     = I1 + Js + (m + ms) R^2 cos^2 + 2 m R a3 cos + m a3^2,

and its integrals (proved by :mod:`rollingtop.symbolic.shell_rotor`) are Lagrange's
``M3 = I3 w3``, a Jellett integral and the pair's ``F6 = C2``, linear in ``w_n`` and ``Omega3``:

    (m + ms) jellett = R s (K + (m + ms) Js) w_n - k_p (M3 + Js Omega3),
    C2 = Omega3 sqrt(N) + R M3 Phi(cos),       K = (m + ms) I1 + m ms a3^2

(``N``, ``Phi``: :func:`rollingtop.contact._shell_pair.pair_weight`). On a level
``(M3, jellett, C2)`` they give ``Omega3(theta)`` and then ``w_n(theta)``, and

    h = rho_p w_tau^2 / 2 + U(theta),    theta' = -w_tau,    h = E - M3^2/(2 I3) - m g R,
    U = A w_n^2 / 2 + R s k_p w_n Omega3 + (Js + (m + ms) R^2 s^2) Omega3^2 / 2 + m g a3 cos.

With ``ms = Js = 0`` this is the meridian model's reduction. The rotor's velocity along ``tau``
is ``v_tau = (R cos + a3) w_n + R s Omega3``; along ``n`` and ``e3`` it is the meridian model's.
``w_n`` grows like ``1/s`` at a pole unless ``num = (m + ms) jellett + k_p (M3 + Js Omega3)``
vanishes there. On such a **pole level** (``pole = "south"``: ``(m + ms) jellett = -k_p0 (M3 +
Js Omega3(0))``, ``k_p0 = (m + ms) R + m a3``: the sleeping top's level and that of every motion
through the upright vertical; ``"north"`` likewise at ``theta = pi``, computed as the south one of
the mirrored pair) ``U`` is finite and smooth through the pole and ``theta`` is signed, as for
the other models' pole levels. Next to the pole ``num`` is the difference of two nearly equal
terms; with ``sigma = sin^2(theta/2)`` (``1 - cos = 2 sigma``) it is written without cancellation,

    num = -2 sigma (m + ms) R (M3 + Js Omega3) + k_p0 Js (Omega3 - Omega3(0)),
    sqrt(N) (Omega3 - Omega3(0)) = Omega3(0) (sqrt N(0) - sqrt N) - R M3 (Phi - Phi(0)),
    sqrt N(0) - sqrt N = 2 sigma (beta - kappa (1 + cos)) / (sqrt N(0) + sqrt N),

and ``Phi``'s arccos term through the half angles, ``arccos x = 2 arctan t`` with
``t = (1 - x) / sqrt(1 - x^2)`` and ``arctan t - arctan t0 = arctan((t - t0) / (1 + t t0))``,
each difference a multiple of ``sigma`` computed as such; ``w_n = num / (R s D0)`` then carries
``2 sigma / s = tan(theta/2)``, so ``w_n / s`` (the precession) is finite at the pole. A level
that is a pole level at both poles is the pair at rest in spin (``M3 = jellett = C2 = 0``: the
planar rocking and rolling over); one with spin at both poles is refused in one line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop.body import SphericalTop
from rollingtop.contact._shell_pair import pair_energy, pair_F6, pair_jellett, pair_weight
from rollingtop.reduction._services import (
    _Analytic,
    _AnalyticResult,
    check_level_size,
    check_level_values,
)
from rollingtop.reduction.level import (
    LagrangeSpin,
    Level,
    LevelSetError,
    PoleLevelError,
    Real,
)

__all__ = ["ShellRotorLevel", "shell_rotor_integrals"]

FloatArray = NDArray[np.float64]
#: The pole numerator below this times the level's size is a pole level (refused).
POLE_LEVEL_TOLERANCE = 1e-9


@dataclass(frozen=True, kw_only=True)
class ShellRotorLevel(LagrangeSpin, Level):
    """A level set ``(M3, jellett, C2)`` of the shell-rotor pair (module docstring)."""

    integrals: ClassVar[tuple[str, ...]] = ("M3", "jellett", "C2")
    pole_noun: ClassVar[str] = "level"
    model: ClassVar[str] = "shell-rotor"
    near_pole_limits: ClassVar[bool] = False
    #: :attr:`LevelSet.pole_advice`.
    pole_advice: ClassVar[str] = (
        "for the pole level set (m + ms) jellett = -k_p (M3 + Js Omega3) at the pole exactly"
    )

    #: Keyword-only: only ``body`` is positional, so a value given in the meridian model's
    #: order (``M3, C1, C2``) is refused.
    body: SphericalTop = field(kw_only=False)
    M3: float
    C2: float
    scale: float = 0.0
    jellett: float
    #: Set at construction: the pole levels (module docstring).
    pole: str | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_level_values(self, ("M3", "jellett", "C2"))
        b = self.body
        if not b.has_shell:
            raise LevelSetError(
                "the shell-rotor reduction needs a shell (shell_mass, shell_inertia > 0)"
            )
        object.__setattr__(self, "pole", None)
        size = max(
            abs(self.jellett) * (b.m + b.shell_mass),
            abs(self.M3) * b.R,
            abs(self.C2),
            abs(float(self.scale)) * (b.R + abs(b.a3)),
            1e-300,
        )
        south, north = (abs(x) <= POLE_LEVEL_TOLERANCE * size for x in self.pole_offsets())
        pole = "both" if south and north else "south" if south else "north" if north else None
        if pole == "both":
            if max(abs(self.M3) * b.R, abs(self.C2)) > POLE_LEVEL_TOLERANCE * size:
                raise PoleLevelError(
                    f"level {self.describe()} touches both poles with spin: the shell-rotor "
                    "pair's levels through both poles are reduced only without spin"
                )
            for name in ("M3", "C2", "jellett"):  # no spin (module docstring)
                object.__setattr__(self, name, 0.0)
        elif pole is not None:  # snapped to the pole level exactly, so that its mirror image
            c = 1.0 if pole == "south" else -1.0  # (the north one's computation) is one too
            N, phi = pair_weight(b, c)
            omega3 = (self.C2 - b.R * self.M3 * float(phi)) / math.sqrt(float(N))
            kp = (b.m + b.shell_mass) * b.R * c + b.m * b.a3
            exact = -kp * (self.M3 + b.shell_inertia * omega3) / (b.m + b.shell_mass)
            object.__setattr__(self, "jellett", exact)
        object.__setattr__(self, "pole", pole)
        check_level_size(self)

    # ---- the pair's coefficients and the level's Omega3, w_n (complex-safe) -----------------
    def _parts(self, theta: Any) -> tuple[Any, ...]:
        """``(s, c, k_p, Omega3, w_n)`` and the theta-derivatives ``(k_p', Omega3', w_n')``."""
        if self.pole == "north":  # the south pole level of the mirrored pair, theta -> pi - theta
            s, c, kp, om, w_n, dkp, dom, dw_n = self.mirrored()._parts(np.pi - theta)
            return s, -c, -kp, -om, w_n, dkp, dom, -dw_n
        b = self.body
        M, ms, Js = b.m + b.shell_mass, b.shell_mass, b.shell_inertia
        s, c = np.sin(theta), np.cos(theta)
        N, phi = pair_weight(b, c)
        K = M * b.I1 + b.m * ms * b.a3**2
        beta = 2.0 * Js * b.m * b.R * b.a3
        dN_dc = beta - 2.0 * b.R**2 * K * c
        kp, dkp = M * b.R * c + b.m * b.a3, -M * b.R * s
        sqrtN = np.sqrt(N)
        omega3 = (self.C2 - b.R * self.M3 * phi) / sqrtN
        # N dOmega3/dc = -(N'/2 Omega3 + R M3 k_p) (the pair's F6, proved), dc/dtheta = -s
        domega3 = s * (0.5 * dN_dc * omega3 + b.R * self.M3 * kp) / N
        D0 = K + M * Js
        if self.pole is not None:  # south or both: w_n / s regular at the pole
            over_s = self._w_n_over_s(theta, c, kp, omega3, sqrtN)
            w_n = over_s * s
            # w_n' = num' / (R s D0) - c w_n / s with num' = s G (G below): regular at the pole
            G = (
                -M * b.R * (self.M3 + Js * omega3)
                + kp * Js * (0.5 * dN_dc * omega3 + b.R * self.M3 * kp) / N
            )
            dw_n = G / (b.R * D0) - c * over_s
            return s, c, kp, omega3, w_n, dkp, domega3, dw_n
        num = M * self.jellett + kp * (self.M3 + Js * omega3)
        dnum = dkp * (self.M3 + Js * omega3) + kp * Js * domega3
        w_n = num / (b.R * s * D0)
        dw_n = dnum / (b.R * s * D0) - w_n * c / s
        return s, c, kp, omega3, w_n, dkp, domega3, dw_n

    def _w_n_over_s(self, theta: Any, c: Any, kp: Any, omega3: Any, sqrtN: Any) -> Any:
        """``w_n / s`` on the south pole level (or with no spin), free of cancellation next to
        the pole (module docstring); complex-safe."""
        b = self.body
        M, ms, Js = b.m + b.shell_mass, b.shell_mass, b.shell_inertia
        if self.pole == "both":
            return 0.0 * c
        K = M * b.I1 + b.m * ms * b.a3**2
        alpha = Js * (b.I1 + Js + ms * b.R**2 + b.m * b.R**2 + b.m * b.a3**2) + b.R**2 * K
        beta = 2.0 * Js * b.m * b.R * b.a3
        kappa = b.R**2 * K
        D = math.sqrt(beta**2 + 4 * alpha * kappa)
        p = M * b.R
        B = b.m * b.a3 + p * beta / (2 * kappa)
        N0 = alpha + beta - kappa
        sqrtN0 = math.sqrt(N0)
        omega30 = (self.C2 - b.R * self.M3 * float(pair_weight(b, 1.0)[1])) / sqrtN0
        kp0 = M * b.R + b.m * b.a3
        half = np.sin(theta / 2)
        sigma = half * half
        # (sqrt N0 - sqrt N) / (2 sigma)
        dsqrt = (beta - kappa * (1 + c)) / (sqrtN0 + sqrtN)
        # arccos x = 2 arctan t, t = sqrt(1 - x^2) / (1 + x), sqrt(1 - x^2) = 2 sqrt(kappa N) / D
        x, x0 = (2 * kappa * c - beta) / D, (2 * kappa - beta) / D
        t = 2 * math.sqrt(kappa) * sqrtN / (D * (1 + x))
        t0 = 2 * math.sqrt(kappa) * sqrtN0 / (D * (1 + x0))
        # (t - t0) / sigma: sqrt N (1 + x0) - sqrt N0 (1 + x) = -(sqrtN0 - sqrtN)(1 + x0)
        # + sqrtN0 (x0 - x), x0 - x = 4 kappa sigma / D
        dt = (
            (2 * math.sqrt(kappa) / D)
            * (-2 * dsqrt * (1 + x0) + sqrtN0 * 4 * kappa / D)
            / ((1 + x) * (1 + x0))
        )
        z = dt / (1 + t * t0)  # arctan(sigma z) = arctan t - arctan t0
        with np.errstate(all="ignore"):
            ratio = np.arctan(sigma * z) / sigma
        ratio = np.where(sigma == 0, z, ratio)
        darc = ratio  # (arccos x - arccos x0) / (2 sigma) = 2 arctan(sigma z) / (2 sigma)
        dphi = p / kappa * dsqrt - B / math.sqrt(kappa) * darc  # (Phi - Phi(0)) / (2 sigma)
        domega3 = (omega30 * dsqrt - b.R * self.M3 * dphi) / sqrtN  # (Omega3 - Omega3(0))/(2 sigma)
        bracket = -M * b.R * (self.M3 + Js * omega3) + kp0 * Js * domega3  # num / (2 sigma)
        # w_n / s = num / (R s^2 D0), 2 sigma / s^2 = 1 / (2 cos^2(theta/2))
        out = bracket / (2 * np.cos(theta / 2) ** 2 * b.R * (K + M * Js))
        return out if np.ndim(out) else out[()]

    def pole_offsets(self) -> tuple[float, float]:
        """``(m + ms) jellett + k_p (M3 + Js Omega3)`` at the south and north poles: 0 on a pole
        level."""
        b = self.body
        out = []
        for c in (1.0, -1.0):
            N, phi = pair_weight(b, c)
            omega3 = (self.C2 - b.R * self.M3 * float(phi)) / math.sqrt(float(N))
            kp = (b.m + b.shell_mass) * b.R * c + b.m * b.a3
            out.append(
                (b.m + b.shell_mass) * self.jellett + kp * (self.M3 + b.shell_inertia * omega3)
            )
        return out[0], out[1]

    def mirrored(self) -> ShellRotorLevel:
        """The same motions with the rotor's axis reversed: ``theta -> pi - theta``,
        ``a3 -> -a3``, ``w3, Omega3 -> -w3, -Omega3``, ``jellett`` kept; ``C2`` becomes
        ``-C2 - R M3 (Phi_mirror(-c) - Phi(c))`` (a constant: both ``Phi`` have the derivative
        ``k_p / sqrt(N)``)."""
        body = replace(self.body, a3=-self.body.a3)
        shift = float(pair_weight(body, 0.0)[1]) - float(pair_weight(self.body, 0.0)[1])
        return ShellRotorLevel(
            body=body,
            M3=-self.M3,
            C2=-self.C2 - self.body.R * self.M3 * shift,
            jellett=self.jellett,
        )

    def omega3(self, theta: Real) -> Real:
        """The shell's spin about the axis, ``Omega3 = (C2 - R M3 Phi) / sqrt(N)``."""
        out: Real = self._parts(theta)[3]
        return out

    def w_n(self, theta: Real) -> Real:
        """``w_n`` from the Jellett integral (module docstring)."""
        out: Real = self._parts(theta)[4]
        return out

    def last_slot(self, theta: Real, psi: float) -> Real:
        """The shell's relative spin ``delta = Omega3 - w3`` (the pair's last state entry)."""
        out: Real = self.omega3(theta) - self.M3 / self.body.I3
        return out

    def P(self, theta: Real) -> Real:
        """``I1 v_tau = I1 ((R cos + a3) w_n + R s Omega3)``: the rotor's velocity along
        ``tau``."""
        b = self.body
        s, c, _, omega3, w_n, _, _, _ = self._parts(theta)
        out: Real = b.I1 * ((b.R * c + b.a3) * w_n + b.R * s * omega3)
        return out

    def U(self, theta: Real) -> Real:
        """``U`` (module docstring)."""
        b = self.body
        M = b.m + b.shell_mass
        s, c, kp, omega3, w_n, _, _, _ = self._parts(theta)
        A = b.I1 + b.shell_inertia + M * b.R**2 * c * c + 2 * b.m * b.R * b.a3 * c + b.m * b.a3**2
        U: Real = (
            0.5 * A * w_n * w_n
            + b.R * s * kp * w_n * omega3
            + 0.5 * (b.shell_inertia + M * b.R**2 * s * s) * omega3 * omega3
            + b.m * b.g * b.a3 * c
        )
        return U

    def dU(self, theta: _Analytic) -> _AnalyticResult:  # type: ignore[override]
        """``dU/dtheta`` (analytic: the complex step of ``d2U`` goes through it)."""
        b = self.body
        M = b.m + b.shell_mass
        s, c, kp, om, wn, dkp, dom, dwn = self._parts(theta)
        A = b.I1 + b.shell_inertia + M * b.R**2 * c * c + 2 * b.m * b.R * b.a3 * c + b.m * b.a3**2
        dA = -s * (2 * M * b.R**2 * c + 2 * b.m * b.R * b.a3)
        B, dB = b.R * s * kp, b.R * (c * kp + s * dkp)
        W, dW = b.shell_inertia + M * b.R**2 * s * s, 2 * M * b.R**2 * s * c
        out: _AnalyticResult = (
            0.5 * dA * wn * wn
            + A * wn * dwn
            + dB * wn * om
            + B * (dwn * om + wn * dom)
            + 0.5 * dW * om * om
            + W * om * dom
            - b.m * b.g * b.a3 * s
        )
        return out

    def rho(self, theta: Real) -> Real:
        """``rho_p = I1 + Js + ms R^2 + m |r|^2``: the reduced motion's mass."""
        b = self.body
        out: Real = b.rho(np.cos(theta)) + b.shell_inertia + b.shell_mass * b.R**2
        return out

    def drho(self, theta: Real) -> Real:
        """``d rho_p / dtheta = -2 m a3 R sin(theta)`` (the shell's terms are constant)."""
        b = self.body
        out: Real = -2 * b.m * b.a3 * b.R * np.sin(theta)
        return out

    def psi_dot(self, theta: float | FloatArray) -> float | FloatArray:
        """Precession rate ``psi' = -w_n / s`` (kinematics, as for every model); on a pole level
        finite at the pole (:meth:`_w_n_over_s`)."""
        if self.pole == "north":  # w_n kept, s the mirror's
            mirror = self.mirrored()
            return (
                mirror.psi_dot(np.pi - np.asarray(theta))
                if np.ndim(theta)
                else float(mirror.psi_dot(math.pi - theta))
            )
        if self.pole is not None:
            parts = self._parts(theta)
            over = self._w_n_over_s(
                theta, parts[1], parts[2], parts[3], np.sqrt(pair_weight(self.body, parts[1])[0])
            )
            rate: float | FloatArray = -over
            return rate if np.ndim(theta) else float(rate)
        rate = -self._parts(theta)[4] / np.sin(theta)
        return rate

    def normal_force(self, theta: Real, w_tau: Real) -> Real:
        """``N = (m + ms) g + m a3 gamma3''``: the shell's centre stays at height ``R``, the
        rotor's centre of mass at ``R + a3 gamma3``."""
        b = self.body
        _, dw = self.flow(theta, w_tau)
        N: Real = (b.m + b.shell_mass) * b.g + b.m * b.a3 * (
            np.sin(theta) * dw - np.cos(theta) * w_tau * w_tau
        )
        return N

    #: No reduced equations of the paper's (eq. 3.3) for this model: the one degree of freedom's
    #: own linearisation (:meth:`~rollingtop.reduction.Level.curvature_eigenvalues`).
    linearised_eigenvalues = Level.curvature_eigenvalues

    def describe(self) -> str:
        """One line naming the level set."""
        return f"M3 = {self.M3:g}, jellett = {self.jellett:g}, C2 = {self.C2:g}{self.pole_label()}"


def shell_rotor_integrals(body: SphericalTop, Y: ArrayLike) -> dict[str, FloatArray]:
    """``M3 = I3 w3``, the pair's Jellett integral and ``C2 = F6`` and the reduced energy
    ``h = E - M3^2/(2 I3) - m g R`` of states ``Y`` (shape ``(..., 18)``)."""
    from rollingtop.dynamics.integrals import lagrange

    Y = np.asarray(Y, dtype=float)
    M3 = lagrange(body, Y)
    h = pair_energy(body, Y) - M3**2 / (2 * body.I3) - body.m * body.g * body.R
    return {"M3": M3, "jellett": pair_jellett(body, Y), "C2": pair_F6(body, Y), "h": h}
