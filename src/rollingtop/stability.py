"""Stability of vertical spins, for every contact model (issue 14, section 2).

A vertical spin -- a pole on the plane, the symmetry axis vertical, spin ``w3`` about it, the
centre of mass at rest -- is a steady motion of every model that allows the spin: the contact
velocity ``v + w x r`` vanishes because ``r`` and ``w`` are both vertical, and no force has a
torque. Rubber rolling forbids it (``(w, gamma) = w3 = 0`` there,
:attr:`~rollingtop.contact.ContactModel.has_vertical_spin`): it is refused with a
:class:`StabilityError`, except the rest at a pole (``omega3 = 0``). In
the body frame ``(v, w, gamma)`` is then constant, and for a model whose equations are regular at
the vertical these nine variables obey a closed system (they do not involve the frame's other
vectors or the position). Its linearisation on the constraint manifold -- ``|gamma| = 1`` and the
model's velocity constraints ``J(gamma) (v, w) = 0`` -- decides linear stability: the Jacobian of
the right-hand side (central differences of the compiled kernel, :mod:`rollingtop._numdiff`)
restricted to the null space of the constraints' Jacobian, whose eigenvalues are purely
imaginary or zero for a stable spin.

A model whose constraint is singular at the vertical supplies its own eigenvalues
(:attr:`~rollingtop.contact.Vertical.eigenvalues`), or declares that they come from
the reduction (:attr:`~rollingtop.contact.Vertical.through_reduction`: the meridian
model, whose eigenvalues are those of the reduced motion on the pole level,
:func:`rollingtop.stability.pole_eigenvalues`; computed here, so that the contact package
never imports the reduction). A model may also give a closed form of the threshold
(:attr:`~rollingtop.contact.Vertical.spin`), which is reported beside the one found
from the eigenvalues.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import RollingTopError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._numdiff import central_jacobian
from rollingtop._types import ComplexArray, FloatArray
from rollingtop.body import OVERFLOW_DECADES, SphericalTop, largest_input
from rollingtop.contact import ContactModel, get_model

__all__ = ["StabilityError", "VerticalSpin", "vertical_spin_eigenvalues", "vertical_spins"]

#: A spin counts as unstable when an eigenvalue's real part exceeds this, relative to the
#: eigenvalues' size (the differences' error is ~1e-10 of it).
UNSTABLE_TOLERANCE = 1e-6
#: Bisection steps for the critical spin (each halves the bracket).
BISECTIONS = 60
POLES = {"south": 1, "north": -1}


class StabilityError(RollingTopError):
    """A stability question this module cannot answer (a body the model's analysis needs to be
    symmetric, a spin that never stabilises)."""


def _frame(gamma: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``alpha, beta`` completing ``gamma`` to an orthonormal frame (valid near the vertical)."""
    a = np.array([1.0, 0.0, 0.0]) - gamma[0] * gamma
    a /= np.linalg.norm(a)
    return a, np.cross(gamma, a)


def _state(x: FloatArray) -> FloatArray:
    """The full state of ``x = (v, w, gamma)`` (frame completed, position and azimuth 0)."""
    y = np.zeros(N_STATE)
    y[0:6] = x[0:6]
    gamma = x[6:9]
    y[6:9], y[9:12] = _frame(gamma / np.linalg.norm(gamma))
    y[12:15] = gamma
    return y


_OVERFLOW = (
    "the linearisation at omega3 = {:.3g} overflows double precision (a spin this "
    "large has no finite Jacobian): choose a smaller omega3"
)


def _overflow(body: SphericalTop, omega3: float, x0: FloatArray) -> str:
    """The refusal of a linearisation that overflows: the body parameter to blame where one is
    far from 1 (``R = 1e150``), else the spin."""
    blamed, decades = largest_input(body, _state(x0))
    if decades >= OVERFLOW_DECADES and not blamed.startswith("|omega|"):
        return (
            f"the linearisation at omega3 = {omega3:.3g} overflows double precision: {blamed} "
            "is beyond the products of the equations; rescale the units of the scenario"
        )
    return _OVERFLOW.format(omega3)


def _generic_eigenvalues(
    model: ContactModel, body: SphericalTop, omega3: float, pole: int
) -> ComplexArray:
    x0 = np.zeros(9)
    x0[5] = omega3
    x0[8] = float(pole)
    code = model.kernel_code(body, _state(x0))
    p = model.params(body)
    ws = workspace()
    dynamics = for_code(code).dynamics

    def rhs(x: FloatArray) -> FloatArray:
        dy = np.zeros(N_STATE)
        call(dynamics.rhs, code, p, _state(x), dy, ws)
        return np.concatenate([dy[0:6], dy[12:15]])

    def constraints(x: FloatArray) -> FloatArray:
        J, bias, dirs = np.zeros((4, 6)), np.zeros(4), np.zeros((4, 3))
        nc = call(dynamics.constraint_rows, code, p, _state(x), J, bias, dirs)
        return np.concatenate([[x[6:9] @ x[6:9] - 1.0], J[:nc] @ x[0:6]])

    with np.errstate(all="ignore"):  # an overflow is refused below, in one line
        G = central_jacobian(constraints, x0)
    if not np.all(np.isfinite(G)):
        raise StabilityError(_overflow(body, omega3, x0))
    _, sv, vt = np.linalg.svd(G)
    rank = int(np.sum(sv > 1e-9 * sv[0]))
    T = vt[rank:].T  # orthonormal basis of the tangent space of the constraint manifold
    with np.errstate(all="ignore"):
        A = T.T @ central_jacobian(rhs, x0) @ T
    if not np.all(np.isfinite(A)):
        raise StabilityError(_overflow(body, omega3, x0))
    out: ComplexArray = np.linalg.eigvals(A).astype(complex)
    return out


def _require_vertical_spin(model: ContactModel) -> None:
    """Refuse a model that forbids the spin about a vertical axis
    (:attr:`~rollingtop.contact.ContactModel.has_vertical_spin`)."""
    spins = model.spin_directions
    if spins is not None and not model.has_vertical_spin:
        names = ", ".join(spins(np.array([0.0, 0.0, 1.0])))
        raise StabilityError(
            f"model {model.name!r} has no vertical spin: its constraint {names} forbids a spin "
            "about the vertical axis (w3 = 0 with the axis vertical); only the rest at a pole "
            "(omega3 = 0) is an equilibrium"
        )


def vertical_spin_eigenvalues(
    body: SphericalTop, model: str | ContactModel, omega3: float, pole: str = "south"
) -> ComplexArray:
    """Eigenvalues of the linearisation at the vertical spin ``omega3`` on ``pole``.

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
    omega3 : float
        Spin rate about the vertical symmetry axis.
    pole : {"south", "north"}
        Which pole is on the plane: ``"south"``, ``gamma3 = 1`` (the body's ``-e3`` end down);
        ``"north"``, ``gamma3 = -1``.

    Returns
    -------
    ndarray of complex, shape (k,)
        ``k`` is the dimension of the constraint manifold in ``(v, w, gamma)`` (the model's own
        linearisation for a model singular at the vertical). Linearly stable when every real part
        is zero (to :data:`UNSTABLE_TOLERANCE`).

    Raises
    ------
    StabilityError
        For ``omega3 != 0`` under a model that forbids the spin about the vertical
        (:attr:`~rollingtop.contact.ContactModel.has_vertical_spin`: rubber rolling); its rest at
        a pole, ``omega3 = 0``, is still linearised.
    """
    model = get_model(model)
    if pole not in POLES:
        raise StabilityError(f"pole = {pole!r} must be 'south' or 'north'")
    if not math.isfinite(omega3):
        raise StabilityError(f"omega3 = {omega3!r} must be finite")
    if omega3 != 0.0:
        _require_vertical_spin(model)
    own = (
        partial(_reduced_eigenvalues, model)
        if model.vertical.through_reduction
        else model.vertical.eigenvalues
    )
    if own is not None:
        try:
            return own(body, float(omega3), POLES[pole])
        except ValueError as exc:
            raise StabilityError(str(exc)) from None
    return _generic_eigenvalues(model, body, float(omega3), POLES[pole])


def _reduced_eigenvalues(
    model: ContactModel, body: SphericalTop, omega3: float, pole: int
) -> ComplexArray:
    """The eigenvalues of a model analysed through the reduction
    (:attr:`~rollingtop.contact.Vertical.through_reduction`): those of the reduced
    motion at the pole of the pole level. A ValueError for a body the reduction cannot take."""
    if not body.symmetric:
        raise ValueError(
            f"the {model.name} model's vertical spin is analysed through the "
            "reduction: it needs a dynamically symmetric body (I1 = I2)"
        )
    return pole_eigenvalues(body, omega3, pole)


def _unstable(eigenvalues: ComplexArray) -> bool:
    """A real part above :data:`UNSTABLE_TOLERANCE` of the eigenvalues' size (no absolute
    floor: the answer does not depend on the units)."""
    size = float(np.max(np.abs(eigenvalues)))
    return bool(np.max(eigenvalues.real) > UNSTABLE_TOLERANCE * size)


@dataclass(frozen=True)
class VerticalSpin:
    """The stability of the vertical spin on one pole.

    Attributes
    ----------
    pole : {"south", "north"}
    com_above_centre : bool
        Whether the centre of mass is above the sphere's centre (``pole a3 > 0``).
    omega3_critical : float
        Spin rate above which the spin is linearly stable (from the eigenvalues, by bisection to
        round-off); 0 when every spin rate is.
    omega3_closed_form : float or None
        The model's closed form of the same (``None``: none, or a body it does not cover).
    """

    pole: str
    com_above_centre: bool
    omega3_critical: float
    omega3_closed_form: float | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "pole": self.pole,
            "com_above_centre": self.com_above_centre,
            "omega3_critical": self.omega3_critical,
            "omega3_closed_form": self.omega3_closed_form,
        }


def _critical(body: SphericalTop, model: ContactModel, pole: str) -> float:
    def unstable(w: float) -> bool:
        return _unstable(vertical_spin_eigenvalues(body, model, w, pole))

    if not unstable(0.0):
        return 0.0
    scale = math.sqrt(body.m * body.g * body.R / max(body.I3, 1e-300)) + 1.0
    hi = scale
    for _ in range(60):
        if not unstable(hi):
            break
        hi *= 2.0
    else:
        raise StabilityError(
            f"the vertical spin on the {pole} pole is unstable up to omega3 = {hi:g}"
        )
    lo = 0.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if unstable(mid):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def vertical_spins(body: SphericalTop, model: str | ContactModel) -> list[VerticalSpin]:
    """The vertical spins of ``body`` under ``model`` on both poles, with their thresholds.

    Returns
    -------
    list of VerticalSpin
        South, then north.

    Raises
    ------
    StabilityError
        Under a model that forbids the spin about the vertical
        (:attr:`~rollingtop.contact.ContactModel.has_vertical_spin`).
    """
    model = get_model(model)
    _require_vertical_spin(model)
    out = []
    for pole, sign in POLES.items():
        closed = None
        if model.vertical.spin is not None and body.symmetric:
            closed = float(model.vertical.spin(body, sign))
        out.append(VerticalSpin(pole, sign * body.a3 > 0.0, _critical(body, model, pole), closed))
    return out


def pole_eigenvalues(body: SphericalTop, omega3: float, pole: int) -> ComplexArray:
    """Eigenvalues of the reduced linearisation at the vertical spin ``omega3`` on the pole
    ``pole`` (+1 south, ``gamma3 = 1``; -1 north): ``+-sqrt(-U''/rho)`` at the pole of the pole
    level ``(M3 = I3 omega3, C1 = pole M3, C2)`` (``C2 = 0`` south, ``-pi M3 a3`` north, the value
    of ``F6`` at the vertical spin); the other directions are integrals (0). The meridian model's
    vertical spin (:attr:`~rollingtop.contact.Vertical.through_reduction`,
    :mod:`rollingtop.stability`); ``body`` must be dynamically symmetric."""
    M3 = body.I3 * omega3
    C2 = 0.0 if pole > 0 else -math.pi * M3 * body.a3
    from rollingtop.reduction.level import LevelSet

    level = LevelSet(body, M3, pole * M3, C2)
    theta = 0.0 if pole > 0 else math.pi
    lam2 = -float(level.d2U(theta)) / float(level.rho(theta))
    root = np.sqrt(complex(lam2))
    return np.array([root, -root, 0.0, 0.0], dtype=complex)
