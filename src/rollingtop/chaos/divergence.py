"""Phase volume along a motion: the divergence of the vector field on the constraint manifold.

A model with an invariant measure of smooth density ``mu`` (the paper's model: ``rho(gamma3)`` in
the reduced variables, paper Sec. 3) has ``div f = -d ln mu / dt`` along every motion, whose time
average tends to 0 like ``1/t`` on a bounded motion. Where the time average tends to a nonzero
value, phase volume drifts along that motion and no smooth invariant density exists (Kozlov's
criterion); the companion model (``parallel``) is expected to be such a model (its paper's
abstract).

The divergence is the Riemannian one of the manifold ``M`` of constraint-consistent states in
the coordinates ``(v, w, alpha, beta, gamma)`` (Euclidean metric of ``R^15``, induced on ``M``):
``div_M f = sum_j (b_j, Df b_j)`` over an orthonormal basis ``b_j`` of the tangent space
``T_y M``. The basis comes from the linearised projection of the integrator
(the model's compiled ``project``) applied to the unit vectors, ``Df b`` from central
differences of the compiled right-hand side. Another metric changes ``div_M f`` by a total
time derivative, not its time average. The horizontal position does not act on the motion and is
left out; the carried azimuth ``psi_nu`` follows the axis azimuth in every perturbation (it is
not a coordinate of ``M``).

Written with NumPy around the compiled kernels (a few dozen kernel calls per sample): the
divergence is sampled along a trajectory of the plain integrator, not integrated with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import InitialStateError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos.lyapunov import check_options, check_state
from rollingtop.contact import ContactModel, get_model
from rollingtop.integrate.driver import integrate

__all__ = ["PhaseVolume", "manifold_divergence", "phase_volume"]

#: Coordinates of ``M``'s ambient space: ``v, w, alpha, beta, gamma``.
NCOORD = 15
#: Relative step of the central differences (cube root of the machine epsilon).
FD_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))
#: Singular values of the linearised projection above this count as tangent directions (a
#: projection's are 0 or 1; the differences' error is ~1e-10).
TANGENT_SV = 0.5


def _refuse_own_inertia(model: ContactModel) -> None:
    """The manifold's coordinates here are ``v, w`` and the frame; a model with a velocity of
    its own in the state's last slot (``shell-rotor``) has one more."""
    if model.own_inertia:
        raise InitialStateError(
            f"the phase volume of model {model.name!r} is not computed: its state has a "
            "velocity beyond v, w and the frame (the shell's spin)"
        )


def _azimuth(y: FloatArray) -> float:
    return math.atan2(float(y[11]), float(y[8]))


def _moved(y: FloatArray, d: FloatArray, e: float) -> FloatArray:
    """``y + e d`` in the 15 coordinates, the carried azimuth turned with the axis azimuth."""
    out = y.copy()
    out[:NCOORD] += e * d
    turn = _azimuth(out) - _azimuth(y)
    out[17] += turn - 2.0 * math.pi * round(turn / (2.0 * math.pi))
    return out


def _project(code: int, p: FloatArray, y: FloatArray, psi_offset: float, ws: Any) -> None:
    """Project ``y`` onto ``M`` in place, the carried azimuth kept at ``psi_offset`` from the
    axis azimuth of the projected frame (the integrator's projection orthonormalises the frame
    but, for a model that carries its direction always, leaves ``psi_nu`` as it is)."""
    call(for_code(code).dynamics.project, code, p, y, ws)
    y[17] = _azimuth(y) + psi_offset
    call(for_code(code).dynamics.project, code, p, y, ws)


def _offset(y: FloatArray) -> float:
    return float(y[17]) - _azimuth(y)


def _tangent_basis(code: int, p: FloatArray, y: FloatArray, ws: Any) -> FloatArray:
    """Orthonormal basis of ``T_y M`` (columns, shape (15, dim M)): the range of the linearised
    projection."""
    e = FD_STEP * max(1.0, float(np.max(np.abs(y[:NCOORD]))))
    P = np.empty((NCOORD, NCOORD))
    for i in range(NCOORD):
        unit = np.zeros(NCOORD)
        unit[i] = 1.0
        plus, minus = _moved(y, unit, e), _moved(y, unit, -e)
        _project(code, p, plus, _offset(y), ws)
        _project(code, p, minus, _offset(y), ws)
        P[:, i] = (plus[:NCOORD] - minus[:NCOORD]) / (2.0 * e)
    U, sv, _ = np.linalg.svd(P)
    basis: FloatArray = U[:, sv > TANGENT_SV]
    return basis


def manifold_divergence(body: SphericalTop, model: str | ContactModel, y: ArrayLike) -> float:
    """``div_M f`` at the constraint-consistent state ``y`` (module docstring).

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
    y : array_like, shape (18,)
        A state on the model's constraints (:func:`rollingtop.initial_state`).

    Returns
    -------
    float
        The divergence: the rate of change of ``ln`` of the volume of a small set of states
        carried by the flow.
    """
    model = get_model(model)
    _refuse_own_inertia(model)
    y = check_state(body, model, y)
    code = model.kernel_code(body, y)
    return _divergence(code, model.params(body), y, workspace())


def _divergence(code: int, p: FloatArray, y: FloatArray, ws: Any) -> float:
    basis = _tangent_basis(code, p, y, ws)
    e = FD_STEP * max(1.0, float(np.max(np.abs(y[:NCOORD]))))
    f1, f2 = np.empty(N_STATE), np.empty(N_STATE)
    total = 0.0
    for b in basis.T:
        rhs = for_code(code).dynamics.rhs
        call(rhs, code, p, _moved(y, b, e), f1, ws)
        call(rhs, code, p, _moved(y, b, -e), f2, ws)
        total += float(b @ (f1[:NCOORD] - f2[:NCOORD])) / (2.0 * e)
    return total


@dataclass(frozen=True)
class PhaseVolume:
    """The divergence along a motion (:func:`phase_volume`).

    Attributes
    ----------
    t : ndarray, shape (n,)
    divergence : ndarray, shape (n,)
        ``div_M f`` at the samples.
    mean : ndarray, shape (n,)
        Its running time average ``(1/t) int_0^t div_M f``, by the trapezoidal rule (``NaN`` at
        ``t = 0``): the rate of the phase-volume drift.
    dimension : int
        ``dim M``.
    """

    t: FloatArray
    divergence: FloatArray
    mean: FloatArray
    dimension: int

    def summary(self) -> dict[str, float | int]:
        """The final running mean and the extremes of the divergence."""
        return {
            "mean_divergence": float(self.mean[-1]),
            "dimension": self.dimension,
            "min_divergence": float(np.min(self.divergence)),
            "max_divergence": float(np.max(self.divergence)),
        }


def phase_volume(
    body: SphericalTop,
    model: str | ContactModel,
    state: ArrayLike,
    *,
    t_end: float,
    samples: int = 2001,
    rtol: float = 1e-10,
    atol: float | None = None,
    max_steps: int | None = None,
) -> PhaseVolume:
    """The divergence of the vector field along the motion from ``state`` and its running time
    average (module docstring).

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
    state : array_like, shape (18,)
        Constraint-consistent initial state.
    t_end : float
        End time (> 0).
    samples : int
        Equally spaced sample times in ``[0, t_end]`` (at least 2): the time average is the
        trapezoidal rule over them, so they must resolve the motion.
    rtol, atol : float
        Tolerances of the integration.
    max_steps : int, optional
        Bound on accepted steps (default: the integrator's): a motion drawn into the vertical
        of a model that carries its direction there (``parallel``, ``oblique``) crawls through
        the regularised passage in tiny steps; this bounds the wait.

    Returns
    -------
    PhaseVolume

    Raises
    ------
    IntegrationError
        When the integration cannot reach ``t_end`` (``max_steps`` reached: one line).
    """
    model = get_model(model)
    _refuse_own_inertia(model)
    y0 = check_state(body, model, state)
    atol_ = check_options(t_end, samples, rtol, atol)
    code = model.kernel_code(body, y0)
    t = np.linspace(0.0, float(t_end), int(samples))
    traj = integrate(code, model.params(body), y0, t, rtol=rtol, atol=atol_, max_steps=max_steps)
    ws = workspace()
    div = np.array([_divergence(code, model.params(body), y, ws) for y in traj.y])
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (div[1:] + div[:-1]) * np.diff(t))])
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(t > 0.0, integral / t, np.nan)
    dim = _tangent_basis(code, model.params(body), y0, ws).shape[1]
    return PhaseVolume(t, div, mean, dim)
