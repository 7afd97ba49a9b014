"""Motion in absolute space: reconstruction on the plane and the per-period map.

``docs/model.md``, "Motion in absolute space": with ``psi`` the azimuth of the constraint direction
``nu = (cos psi, sin psi)`` in the fixed frame (the horizontal projection of the axis; carried
through the pole in a pole case), ``Z = X + i Y`` the CoM position and the signed nutation angle
``theta`` of :mod:`rollingtop.reduction.level`,

    theta' = -w_tau,    w_tau' = (U'(theta) + rho_theta w_tau^2 / 2) / rho  (LevelSet.flow)
    psi'   = -w_n / s  (a function of theta on the level set)
    Z'     = exp(i psi) (-(R + a3 gamma3) w_tau - i v_tau)
    contact point = Z - a3 s exp(i psi).

Over one period ``T`` of ``theta`` the azimuth advances by ``Delta psi`` and, by the rotational
symmetry of the plane, the CoM moves by ``exp(i psi0) D`` with ``D`` fixed by the orbit: the map
``(psi, Z) -> (psi + Delta psi, Z + exp(i psi) D)`` is a rigid motion of the plane. Unless
``Delta psi`` is a multiple of ``2 pi`` it is a rotation about the centre
``c = Z0 + exp(i psi0) D / (1 - exp(i Delta psi))``: the once-per-period positions lie on the
circle of radius ``|D| / (2 |sin(Delta psi / 2)|)`` about it and the motion is bounded. At a
multiple of ``2 pi`` it is a translation: the CoM drifts with mean velocity ``exp(i psi0) D / T``.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

from rollingtop.reduction.level import Level, LevelSetError
from rollingtop.reduction.orbits import Orbit, canonical_orbit, orbits
from rollingtop.reduction.rotation import rotation_number

__all__ = ["PeriodMap", "period_map", "reconstruct", "RESONANCE_TOLERANCE", "NEAR_RESONANT"]

#: ``|Delta psi / 2 pi - k|`` below this: resonant, the CoM drifts.
RESONANCE_TOLERANCE = 1e-9
#: A bounded orbit whose circle of once-per-period points is larger than this many radii ``R``
#: of the sphere is flagged near-resonant.
NEAR_RESONANT = 100.0

FloatArray: TypeAlias = NDArray[np.float64]
#: Most evaluations of the path's right-hand side in one :func:`reconstruct` (about a second):
#: beyond them the axis passes so close to the vertical that its azimuth swings faster than the
#: path can be followed (rubber rolling next to its pole level: ``psi' ~ h / rubber_spin``).
MAX_PATH_EVALUATIONS = 60_000


class PathUnresolvedError(LevelSetError):
    """The reconstruction would need more than :data:`MAX_PATH_EVALUATIONS` evaluations."""


def _path_rhs(level: Level) -> Callable[[float, FloatArray], list[float]]:
    """The right-hand side for ``solve_ivp`` of ``z = (theta, w_tau, psi, X, Y)`` (module
    docstring): :meth:`LevelSet.flow` with the quadratures for ``psi``, ``X`` and ``Y``; raises
    :class:`PathUnresolvedError` past :data:`MAX_PATH_EVALUATIONS` calls."""
    b = level.body
    calls = [0]

    def f(t: float, z: FloatArray) -> list[float]:
        calls[0] += 1
        if calls[0] > MAX_PATH_EVALUATIONS:
            raise PathUnresolvedError(
                f"the path on {level.describe()} is not reconstructed: the axis passes so close "
                "to the vertical that its azimuth swings faster than the path can be followed "
                f"({MAX_PATH_EVALUATIONS} evaluations)"
            )
        theta, w_tau, psi = z[0], z[1], z[2]
        theta_dot, w_tau_dot = level.flow(theta, w_tau)
        k = (b.R + b.a3 * np.cos(theta)) * w_tau
        v_tau = level.v_tau(theta)
        c, s = np.cos(psi), np.sin(psi)
        return [
            theta_dot,
            w_tau_dot,
            level.psi_dot(theta),
            -k * c + v_tau * s,
            -k * s - v_tau * c,
        ]

    return f


def reconstruct(
    level: Level,
    t: ArrayLike,
    *,
    theta0: float,
    w_tau0: float,
    psi0: float = 0.0,
    position0: Sequence[float] = (0.0, 0.0),
    rtol: float = 1e-13,
    atol: float = 1e-14,
) -> dict[str, FloatArray]:
    """Reconstruct the motion on the plane from the reduced one (a level whose centre of mass
    drifts uniformly, :meth:`~rollingtop.reduction.LevelSet.uniform_drift`, is refused: the
    drift's direction is not part of it).

    Integrates ``(theta, w_tau)`` of the one-degree-of-freedom system together with the
    quadratures for ``psi``, ``X`` and ``Y`` (module docstring) with ``solve_ivp`` (DOP853).

    Parameters
    ----------
    level : LevelSet
    t : array_like, shape (n,)
        Increasing times, starting at the initial time.
    theta0, w_tau0 : float
        Initial signed nutation angle and ``w_tau`` (``theta0 = arccos(gamma3)`` off a pole).
    psi0 : float
        Initial azimuth of the axis (``atan2(beta3, alpha3)``).
    position0 : (float, float)
        Initial CoM position.

    Returns
    -------
    dict
        ``t, theta, gamma3, w_tau, psi, position (n, 2), contact_point (n, 2)``.
    """
    if level.uniform_drift() is not None:
        raise LevelSetError(
            f"the {level.model} model's centre of mass drifts uniformly in a "
            "direction its level does not fix: reconstruct its path from a full "
            "state (rollingtop simulate)"
        )
    t = np.asarray(t, dtype=float)
    z0 = [theta0, w_tau0, psi0, float(position0[0]), float(position0[1])]
    sol = solve_ivp(
        _path_rhs(level), (t[0], t[-1]), z0, method="DOP853", rtol=rtol, atol=atol, t_eval=t
    )
    if not sol.success:
        raise LevelSetError(f"reconstruction failed: {sol.message}")
    theta, w_tau, psi, X, Y = sol.y
    s = np.sin(theta)
    a3 = level.body.a3
    return {
        "t": t,
        "theta": theta,
        "gamma3": np.cos(theta),
        "w_tau": w_tau,
        "psi": psi,
        "position": np.stack([X, Y], axis=1),
        "contact_point": np.stack([X - a3 * s * np.cos(psi), Y - a3 * s * np.sin(psi)], axis=1),
    }


@dataclass(frozen=True)
class PeriodMap:
    """The rigid motion of the plane after one period of ``gamma3``, and what it implies.

    Positions refer to the canonical start of the orbit: the CoM at the origin at the turning
    point ``start_theta`` (the lowest ``gamma3`` on the branch ``0 < theta < pi``), with the axis
    azimuth ``psi = 0`` there. For another start ``(psi0, Z0)`` rotate by ``psi0`` and shift by
    ``Z0``.

    Attributes
    ----------
    period : float
    delta_psi : float
        Advance of the azimuth per period (by quadrature, like the period).
    delta_psi_error : float
        Estimated absolute error of ``delta_psi`` (two quadrature levels).
    displacement : (float, float)
        CoM displacement over one period from the canonical start.
    motion : {"bounded", "drifting", "uniform drift", "unresolved"}
    center, radius : (float, float) and float, or None
        Circle on which the once-per-period CoM positions lie (bounded motion).
    drift_velocity : (float, float) or None
        Mean CoM velocity (drifting motion).
    near_resonant : bool
        Bounded, but the circle is larger than :data:`NEAR_RESONANT` sphere radii.
    start_theta : float
    """

    period: float
    delta_psi: float
    displacement: tuple[float, float]
    motion: str
    center: tuple[float, float] | None
    radius: float | None
    drift_velocity: tuple[float, float] | None
    near_resonant: bool
    start_theta: float
    delta_psi_error: float = math.nan
    #: The speed of a uniform drift (``motion == "uniform drift"``: the smooth plane's centre
    #: of mass, whose direction the level does not fix), else ``None``.
    drift_speed: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        d = asdict(self)
        for key in ("displacement", "center", "drift_velocity"):
            if d[key] is not None:
                d[key] = list(d[key])
        return d

    def center_from(self, psi0: float, position0: Sequence[float]) -> tuple[float, float] | None:
        """Centre of the circle for a motion started at the canonical point with azimuth ``psi0``
        and CoM position ``position0``."""
        if self.center is None:
            return None
        c = complex(*position0) + cmath.exp(1j * psi0) * complex(*self.center)
        return (c.real, c.imag)


def start_theta(orbit: Orbit) -> float:
    """The canonical starting turning point of an orbit (see :class:`PeriodMap`):
    :attr:`rollingtop.reduction.Orbit.start_theta`."""
    return orbit.start_theta


def period_map(level: Level, h: float, orbit: Orbit | None = None) -> PeriodMap:
    """Per-period map of an orbit on ``(M3, C1, C2, h)`` (the first one if ``orbit`` is None).

    ``Delta psi`` comes from the quadrature of ``psi'(theta)`` over one period with the same
    singularity-free rule as the period; the displacement from integrating the reconstruction
    over one period (:func:`reconstruct`).
    """
    if orbit is None:
        orbit = orbits(level, h)[0]
    if orbit.kind != "periodic":
        raise LevelSetError(f"no per-period map for a {orbit.kind} orbit ({orbit.note})")
    T = orbit.period
    drift = level.uniform_drift()
    if drift is not None:  # the CoM drifts uniformly whatever the axis does (smooth plane)
        turns, turns_err = rotation_number(level, h, orbit)
        theta0 = start_theta(orbit)
        dpsi, dpsi_err = 2 * math.pi * turns, 2 * math.pi * turns_err
        if drift == 0:  # at rest: the CoM stays where it is
            return PeriodMap(
                T, dpsi, (0.0, 0.0), "bounded", (0.0, 0.0), 0.0, None, False, theta0, dpsi_err
            )
        # its direction is the horizontal momentum's, not part of the level: only its speed
        return PeriodMap(
            T,
            dpsi,
            (math.nan, math.nan),
            "uniform drift",
            None,
            None,
            None,
            False,
            theta0,
            dpsi_err,
            drift_speed=drift,
        )
    try:
        dpsi, dpsi_err, theta0, D = _displacement(level, h, orbit)
    except PathUnresolvedError:  # Delta psi by quadrature all the same; no displacement
        turns, turns_err = rotation_number(level, h, orbit)
        return PeriodMap(
            T,
            2 * math.pi * turns,
            (math.nan, math.nan),
            "unresolved",
            None,
            None,
            None,
            False,
            start_theta(orbit),
            2 * math.pi * turns_err,
        )
    turns = dpsi / (2 * math.pi)
    if abs(turns - round(turns)) < RESONANCE_TOLERANCE:
        v = D / T
        return PeriodMap(
            T,
            dpsi,
            (D.real, D.imag),
            "drifting",
            None,
            None,
            (v.real, v.imag),
            False,
            theta0,
            dpsi_err,
        )
    c = D / (1 - cmath.exp(1j * dpsi))
    radius = abs(c)
    return PeriodMap(
        T,
        dpsi,
        (D.real, D.imag),
        "bounded",
        (c.real, c.imag),
        radius,
        None,
        radius > NEAR_RESONANT * level.body.R,
        theta0,
        dpsi_err,
    )


def _displacement(level: Level, h: float, orbit: Orbit) -> tuple[float, float, float, complex]:
    """``(Delta psi, its error, theta0, D)``: the quadrature of ``psi'`` and the CoM's
    displacement over one period from the canonical start (:func:`reconstruct`)."""
    T = orbit.period
    if level.pole == "both":  # no spin: the axis does not precess (rollingtop.reduction.no_spin)
        dpsi, dpsi_err = 0.0, 0.0
        theta0, w_tau0 = start_theta(orbit), 0.0
        if orbit.rolls_over:  # no turning point: start where theta' is known, moving forwards
            theta0 = orbit.theta_min
            w_tau0 = -float(level.w_tau(theta0, h))
        path = reconstruct(level, [0.0, T], theta0=theta0, w_tau0=w_tau0)
    else:
        exact_level, exact_orbit = canonical_orbit(level, h, orbit)  # near north: its mirror
        turns, turns_err = rotation_number(level, h, orbit)  # the same quadrature of psi'
        dpsi, dpsi_err = 2 * math.pi * turns, 2 * math.pi * turns_err
        theta0 = start_theta(orbit)
        if exact_level is level:
            path = reconstruct(level, [0.0, T], theta0=theta0, w_tau0=0.0)
        else:
            # near the north pole: integrate the mirror image, where the wall next to the pole
            # is resolved in theta; the same physical motion has psi + pi and theta -> pi - theta
            start = exact_orbit.theta_min if theta0 == orbit.theta_max else exact_orbit.theta_max
            path = reconstruct(exact_level, [0.0, T], theta0=start, w_tau0=0.0, psi0=math.pi)
    return dpsi, dpsi_err, theta0, complex(*path["position"][-1])
