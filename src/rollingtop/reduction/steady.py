"""Steady motions: critical points of the effective potential (``gamma3`` constant).

At a critical point ``theta*`` of ``U`` the reduced motion rests: ``w_tau = 0``, so the CoM has
``v_n = v3 = 0`` and moves with speed ``|v_tau|`` along ``tau``, the axis precesses at
``psi' = -w_n / s`` and spins at ``w3 = M3 / I3``; the CoM runs on a circle of radius
``|v_tau / psi'|``. Small oscillations about a centre have ``omega^2 = U''(theta*) / rho``
(``h = rho theta'^2/2 + U``, a particle of mass ``rho`` in the potential ``U``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._figures import draw
from rollingtop._html import html_view
from rollingtop._json import json_ready
from rollingtop.reduction._roots import brentq
from rollingtop.reduction.level import Level, LevelSetError, near_north

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["SteadyMotion", "SteadyMotions", "steady_motions", "critical_points"]

#: Points of the theta grid on which sign changes of dU/dtheta are looked for.
GRID_POINTS = 20_001
#: A curvature below this (relative to the potential's scale) counts as degenerate.
DEGENERATE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class SteadyMotion:
    """A steady motion (a critical point of ``U``) and what the body does there.

    Attributes
    ----------
    gamma3, theta : float
        Where (``gamma3 = cos theta``).
    U : float
        Effective potential there (``docs/model.md`` definition): the reduced energy ``h``.
    type : {"center", "saddle", "degenerate"}
        From the sign of ``U''``.
    U2 : float
        ``d^2 U / dgamma3^2`` (the paper's variable; ``= U''_theta / s^2``; NaN at a pole).
    U2_theta : float
        ``d^2 U / dtheta^2``.
    frequency : float
        Angular frequency of small oscillations ``sqrt(U''_theta / rho)`` (NaN unless centre).
    period : float
        ``2 pi / frequency`` (NaN unless centre).
    growth_rate : float
        ``sqrt(-U''_theta / rho)`` at a saddle (NaN otherwise).
    w_n, v_tau, spin, precession_rate, com_speed, com_radius : float
        ``w_n``, ``v_tau``, ``w3 = M3/I3``, ``psi'``, ``|v_tau|`` and ``|v_tau / psi'|`` (inf when
        the axis does not precess).
    eigenvalues : tuple of (float, float)
        ``(real, imaginary)`` parts of the eigenvalues of the full equations linearised at this
        steady rolling (:func:`linearised_eigenvalues`); empty at a pole (or within round-off of
        one, where the reduced variables cannot be differenced).
    linearly_stable : bool or None
        Whether every eigenvalue has a zero real part (``None`` at a pole).
    """

    gamma3: float
    theta: float
    U: float
    type: str
    U2: float
    U2_theta: float
    frequency: float
    period: float
    growth_rate: float
    w_n: float
    v_tau: float
    spin: float
    precession_rate: float
    com_speed: float
    com_radius: float
    eigenvalues: tuple[tuple[float, float], ...] = ()
    linearly_stable: bool | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite values become ``None``)."""
        return json_ready(asdict(self))


class SteadyMotions(list[SteadyMotion]):
    """The steady motions of a level set (:func:`steady_motions`): a list, which also knows its
    :attr:`level`, shows itself as a table in a notebook and draws itself (:meth:`plot`).

    Attributes
    ----------
    level : LevelSet
    """

    def __init__(self, motions: Iterable[SteadyMotion], level: Level) -> None:
        super().__init__(motions)
        self.level = level

    def _repr_html_(self) -> str:
        """The notebook's view: the count by type and a row per motion (``rollingtop
        equilibria``'s table)."""
        return html_view(self)

    def plot(self, ax: Axes | None = None, **kw: Any) -> Axes:
        """Draw ``U`` with each steady motion at its energy on ``ax`` (default: a new figure's)
        and return ``ax``: the lower panel of ``rollingtop portrait``
        (:func:`rollingtop.plot.portrait.draw_potential`, which takes ``kw``: ``h_levels``,
        ``window``)."""
        axes: Axes = draw("potential", ax, self.level, **kw)
        return axes


def _grid(level: Level, points: int = GRID_POINTS) -> NDArray[np.float64]:
    lo, hi = level.theta_domain
    # Chebyshev-like spacing clusters points near the barriers, where U varies fastest.
    x = np.cos(np.linspace(math.pi, 0.0, points))
    grid = lo + (hi - lo) * (x + 1) / 2
    if level.pole is None:
        # near a pole level the wall of U, and a steady motion beside it, can sit as close to
        # the pole as |C1 -+ M3|: add points at geometrically shrinking distances from the ends
        d = (hi - lo) * np.logspace(-18.0, -3.0, 301)
        # at theta = 0 a distance keeps its precision down to the smallest doubles (a mirrored
        # level's wall at 1e-20, say); at pi it is lost below 1e-16
        near_zero = lo + (hi - lo) * np.logspace(-300.0, -18.0, 283) if lo == 0.0 else d[:0]
        grid = np.unique(np.concatenate([grid, near_zero, lo + d, hi - d]))
    return grid


def critical_points(level: Level, points: int = GRID_POINTS) -> NDArray[np.float64]:
    """All zeros of ``dU/dtheta`` inside the theta domain, increasing (read-only: the last
    levels' are kept, as every orbit of a level asks for them again; a level is a frozen value).

    Sign changes of ``dU/dtheta`` on a grid of ``points`` points (clustered at the ends, plus
    points at the walls next to the poles), each refined by Brent's method to machine
    precision; a zero of even multiplicity that does not change sign is found when the grid
    lands on it exactly only. Fewer points serve the classification of many levels
    (:mod:`rollingtop.reduction.bifurcation`). A potential constant on the whole domain
    (:func:`flat_potential`) has none that is isolated: empty.
    """
    return _critical_points(level, int(points))


@functools.lru_cache(maxsize=128)
def _critical_points(level: Level, points: int) -> NDArray[np.float64]:
    grid = _grid(level, points)[1:-1]
    with np.errstate(all="ignore"):
        d = level.dU(grid)
    if np.all(d == 0.0):  # U constant (flat_potential): no critical point is isolated
        d = np.empty(0)
        d.flags.writeable = False
        return d
    roots = []
    sign = np.sign(d)  # not d[:-1] * d[1:], which can overflow
    for i in np.flatnonzero(np.isfinite(d[:-1]) & np.isfinite(d[1:]) & (sign[:-1] * sign[1:] <= 0)):
        if d[i] == 0.0:
            roots.append(grid[i])
        elif d[i + 1] != 0.0:
            a, b = grid[i], grid[i + 1]  # xtol relative near theta = 0, where roots can be tiny
            xtol = 1e-15 * min(1.0, max(abs(a), abs(b)))
            roots.append(brentq(level.dU, a, b, xtol=xtol, rtol=8.9e-16, maxiter=200))
    found = np.unique(np.array(roots, dtype=float))
    found.flags.writeable = False
    return found


#: Real parts below this times the eigenvalues' size count as zero.
STABLE_TOLERANCE = 1e-6


def linearised_eigenvalues(level: Level, gamma3: float) -> NDArray[np.complex128]:
    """Eigenvalues of the full equations linearised at the steady rolling at ``gamma3``.

    A steady rolling of the symmetric body is a relative equilibrium: in the body frame ``gamma``
    turns about the axis, so the full equations have no fixed point there, but the reduced
    system (paper eq. 3.3, :func:`rollingtop.reduction.reduced_rhs`) is the full dynamics up to
    the symmetries (rotation about the vertical, translation) and the Lagrange integral, and has
    one at ``(gamma3, v_tau, w_n, 0)``. Its 4x4 Jacobian (central differences) has two zero
    eigenvalues (the integrals ``C1, C2``) and ``+-sqrt(-U''_theta / rho)``, which the tests
    compare with the potential's curvature.
    """
    return level.linearised_eigenvalues(gamma3)


def steady_motion(level: Level, theta: float) -> SteadyMotion:
    """Describe the steady motion at the critical point ``theta``."""
    U2t = float(level.d2U(theta))
    rho = float(level.rho(theta))
    U = float(level.U(theta))
    if abs(U2t) <= DEGENERATE_TOLERANCE * max(abs(U), 1.0):
        kind = "degenerate"
    else:
        kind = "center" if U2t > 0 else "saddle"
    s = math.sin(theta)
    omega = math.sqrt(U2t / rho) if kind == "center" else math.nan
    v_tau = float(level.v_tau(theta))
    psi_dot = float(level.psi_dot(theta))
    drift = level.uniform_drift()  # a model whose centre of mass drifts uniformly (smooth)
    eig: tuple[tuple[float, float], ...] = ()
    stable = None
    if abs(s) > 1e-8 and 0.0 < theta < math.pi:
        ev = level.linearised_eigenvalues(math.cos(theta))
        if np.all(np.isfinite(ev)):
            eig = tuple((float(z.real), float(z.imag)) for z in ev)
            size = max(1.0, float(np.max(np.abs(ev))))
            stable = bool(np.max(np.abs(ev.real)) <= STABLE_TOLERANCE * size)
    return SteadyMotion(
        gamma3=math.cos(theta),
        theta=theta,
        U=U,
        type=kind,
        U2=U2t / s**2 if abs(s) > 1e-12 else math.nan,
        U2_theta=U2t,
        frequency=omega,
        period=2 * math.pi / omega if kind == "center" else math.nan,
        growth_rate=math.sqrt(-U2t / rho) if kind == "saddle" else math.nan,
        w_n=float(level.w_n(theta)) if abs(s) > 1e-12 else 0.0,
        v_tau=v_tau if drift is None else math.nan,  # a drift's (v, tau) is not the level's
        spin=float(level.spin(theta)),
        precession_rate=psi_dot,
        com_speed=abs(v_tau) if drift is None else drift,
        com_radius=(abs(v_tau / psi_dot) if psi_dot != 0 else math.inf)
        if drift is None
        else (math.inf if drift else 0.0),
        eigenvalues=eig,
        linearly_stable=stable,
    )


def flat_potential(level: Level) -> bool:
    """Whether ``U`` is constant on the level: ``dU/dtheta`` exactly 0 on the grid of
    :func:`critical_points`, as on a no-spin level of a balanced body (``a3 = 0``) or without
    gravity (``g = 0``), where ``U`` reduces to a constant term."""
    with np.errstate(all="ignore"):
        d = level.dU(_grid(level, 64)[1:-1])
    return bool(np.all(d == 0.0))


def steady_motions(level: Level) -> SteadyMotions:
    """Every steady motion on the level set, sorted by ``gamma3`` (a list that knows
    ``level``: :class:`SteadyMotions`).

    In a pole case the list may include motions on the negative-``s`` branch (after a pole
    passage); their ``theta`` lies outside ``(0, pi)``.

    Raises
    ------
    LevelSetError
        When ``U`` is constant (:func:`flat_potential`): every ``gamma3`` is then a steady
        motion, a continuum with no isolated member to list.
    """
    if flat_potential(level):
        raise LevelSetError(
            f"U is constant (U = {float(level.U(math.pi / 2)):.6g}) on {level.describe()}: "
            "every gamma3 is a neutral steady motion, none is isolated (a balanced body or no "
            "gravity, without spin)"
        )
    if near_north(level):  # computed on the mirror image, where theta ~ 0 keeps its precision
        motions = [_mirror(m) for m in steady_motions(level.mirrored())]
    else:
        motions = [steady_motion(level, float(t)) for t in critical_points(level)]
    return SteadyMotions(sorted(motions, key=lambda m: (m.gamma3, m.theta)), level)


def _mirror(m: SteadyMotion) -> SteadyMotion:
    """A steady motion of the mirrored level (:meth:`LevelSet.mirrored`) seen on the original:
    ``gamma3 -> -gamma3``, ``theta -> pi - theta``, ``v_tau`` and the spin change sign."""
    from dataclasses import replace

    return replace(m, gamma3=-m.gamma3, theta=math.pi - m.theta, v_tau=-m.v_tau, spin=-m.spin)
