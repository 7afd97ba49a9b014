"""The oblique family: no slip along a direction between the axis's horizontal projection and
the direction across it (issue 39).

Contact is kept, ``f1 = (vp, gamma) = 0``, and the contact point does not slip along

    ``d(phi) = cos(phi) nu + sin(phi) tau``,

``nu = (e3 - gamma3 gamma) / s`` the horizontal projection of the symmetry axis, ``tau = e3 x
gamma / s`` the horizontal direction across it (``s = sqrt(1 - gamma3^2)``, body frame). It
slips freely along ``d x gamma = -sin(phi) nu + cos(phi) tau``; the free velocity component is
the centre of mass's along it, ``v_slip`` (at ``phi = 0`` the meridian model's ``v_tau``, at
``phi = pi/2`` minus the ``parallel`` model's ``v_nu``). ``phi`` is the model's parameter
``angle`` (``[contact] angle`` in radians, any real, default ``pi/4``; ``phi`` and ``phi + pi``
are one constraint): ``phi = 0`` is the paper's constraint (:mod:`rollingtop.contact.meridian`),
``phi = pi/2`` the companion paper's (:mod:`rollingtop.contact.parallel`).

The constraint is ideal for every ``phi`` (its reaction, along ``gamma`` and ``d``, does no work
on the contact point's allowed velocity), so the energy is conserved; for a dynamically
symmetric body Jellett's integral is too (any force at the contact point keeps it). Both are
proved by ``rollingtop verify`` with ``phi`` a symbol (:mod:`rollingtop.symbolic.oblique`).

**The vertical.** ``d`` turns with ``nu`` and ``tau`` and is undefined where they are, at
``gamma3 = +-1``. It is carried as the ``parallel`` model carries ``tau``: the state's ``psi_nu``
is the azimuth of ``nu`` (``nu = cos(psi_nu) alpha + sin(psi_nu) beta``, so ``d = cos(psi_nu -
phi) alpha + sin(psi_nu - phi) beta``), and it turns by the same regularised rule
(:func:`rollingtop.contact.parallel.carried_rate`, with the same parameters ``pole_disk``,
``relax``, ``pass_relax``): a passage through the vertical is the regularised model's
continuation, as for ``parallel``, and the tools that flag it (``through_vertical``) do so here.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._jit import inline
from rollingtop._layout import CONTACT_PARAMS
from rollingtop._types import ComplexArray, Float3, Float6, FloatArray, Workspace
from rollingtop.contact._base import (
    ContactModel,
    FreeVelocity,
    RuleParameter,
    Symbolic,
    VelocityFunction,
    Vertical,
    contact_arm,
)
from rollingtop.contact._closed import project_contact, rhs_contact
from rollingtop.contact._rows import contact_row, normal_row
from rollingtop.contact.meridian import horizontal_basis, vertical_direction
from rollingtop.contact.parallel import PARAMETERS as PASSAGE
from rollingtop.contact.parallel import carried_rate, tau_rate

if TYPE_CHECKING:
    from types import ModuleType

    from rollingtop.body import SphericalTop

#: The slot of ``p`` (after the passage rule's three) that holds ``phi``.
ANGLE = CONTACT_PARAMS + 3
#: The angle of the registered model (``[contact] model = "oblique"`` without ``angle``): half
#: way between the paper's constraint and the companion paper's, so that the model's own name
#: is neither of them (``rollingtop compare`` runs it beside both).
DEFAULT_ANGLE = math.pi / 4

#: The model's own parameters: the passage rule's (:data:`rollingtop.contact.parallel.PARAMETERS`)
#: and the angle ``phi`` (default 0, the paper's constraint).
PARAMETERS = (
    *PASSAGE,
    RuleParameter(
        "angle",
        DEFAULT_ANGLE,
        "phi in radians: no slip along cos(phi) nu + sin(phi) tau (0: the paper's constraint, "
        "pi/2: the companion paper's)",
        positive=False,
    ),
)


@inline
def d_carried(p: FloatArray, y: FloatArray) -> Float3:
    """``d = cos(psi_nu - phi) alpha + sin(psi_nu - phi) beta``: the carried ``nu`` turned by
    ``-phi`` about the vertical, ``cos(phi) nu + sin(phi) tau``."""
    th = y[17] - (DEFAULT_ANGLE + p[ANGLE])  # the slot holds the offset from the default
    c, s = math.cos(th), math.sin(th)
    return c * y[6] + s * y[9], c * y[7] + s * y[10], c * y[8] + s * y[11]


@inline
def d_of(p: FloatArray, y: FloatArray) -> Float6:
    """The carried constraint direction and its rate: ``d' = psi_nu' (gamma x d) + d x w``
    (``d`` is horizontal and turns with ``nu``, :func:`rollingtop.contact.parallel.tau_rate`)."""
    d1, d2, d3 = d_carried(p, y)
    dd1, dd2, dd3 = tau_rate(y, d1, d2, d3, carried_rate(p, y))
    return d1, d2, d3, dd1, dd2, dd3


@inline
def rows(
    p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray, variant: int
) -> int:
    """Constraint rows ``f1`` (normal) and ``(vp, d) = 0``; returns 2."""
    normal_row(p, y, 0, J, bias, dirs)
    d1, d2, d3, dd1, dd2, dd3 = d_of(p, y)
    contact_row(p, y, 1, d1, d2, d3, dd1, dd2, dd3, J, bias, dirs)
    return 2


@inline
def accel(p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace, variant: int) -> int:
    """Closed form of the accelerations (:func:`.rhs_contact` with the row along ``d``)."""
    d1, d2, d3, dd1, dd2, dd3 = d_of(p, y)
    return rhs_contact(p, y, dy, ws, True, d1, d2, d3, dd1, dd2, dd3)


@inline
def project_velocity(p: FloatArray, y: FloatArray, variant: int) -> None:
    """Closed form of the velocity projection (:func:`.project_contact` along ``d``)."""
    d1, d2, d3 = d_carried(p, y)
    project_contact(p, y, True, d1, d2, d3)


@inline
def direction_rate(p: FloatArray, y: FloatArray, variant: int) -> float:
    """``psi_nu'``: :func:`rollingtop.contact.parallel.carried_rate`."""
    return carried_rate(p, y)


@inline
def sync_direction(y: FloatArray, variant: int) -> None:
    """Nothing: the carried azimuth is never reset (it relaxes)."""
    return


def _velocity(
    angle: float,
    body: SphericalTop,
    gamma: FloatArray,
    omega: FloatArray,
    alpha: FloatArray,
    beta: FloatArray,
    free: FreeVelocity,
) -> FloatArray:
    """The initial velocity for ``phi = angle``: ``v = -w x r + (v_slip + (w x r, e)) e`` with
    ``e = d x gamma = -sin(phi) nu + cos(phi) tau`` (so ``vp = v + w x r`` is along ``e``)."""
    c, s = math.cos(angle), math.sin(angle)
    tau, nu = horizontal_basis(gamma, omega, alpha, beta)  # at the vertical: the carried ones
    e = -s * nu + c * tau
    wxr = np.cross(omega, contact_arm(body, gamma))
    slip = free["v_slip"] + wxr @ e
    out: FloatArray = -wxr + slip * e
    return out


def _velocity_for(angle: float) -> VelocityFunction:
    """:func:`_velocity` at ``angle`` (a ``partial`` of a module function: it pickles, for a
    model instance sent to a Dask worker)."""
    return functools.partial(_velocity, float(angle))


def _vertical_eigenvalues(body: SphericalTop, omega3: float, pole: int) -> ComplexArray:
    """No linearisation at the vertical (as for ``parallel``): refused (``ValueError``,
    reported by :mod:`rollingtop.stability`)."""
    raise ValueError(
        "the oblique model's constraint direction cos(phi) nu + sin(phi) tau is undefined at the "
        "vertical, where the model continues by its regularised rule (rollingtop.contact.oblique):"
        " its vertical spin has no linearisation; simulate it instead"
    )


def _bind(values: dict[str, float]) -> dict[str, Any]:
    """The fields that follow the parameters: the initial velocity for the angle."""
    return {"velocity": _velocity_for(values["angle"])}


#: Name of the sympy symbol ``t = tan(phi / 2)`` (real) of the symbolic forms below: the same
#: symbol as :data:`rollingtop.symbolic.equations.PHI_T` (sympy symbols of one name and
#: assumptions are one), named here because this package does not import the symbolic one.
ANGLE_SYMBOL = "t_phi"


def _cos_sin(sp: ModuleType) -> tuple[Any, Any]:
    t = sp.Symbol(ANGLE_SYMBOL, real=True)
    return (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2)


def _symbolic_directions(sp: ModuleType, gamma: Any) -> list[Any]:
    """``gamma`` and ``d`` unnormalised, ``phi`` by ``t = tan(phi / 2)`` (rational)."""
    c, s = _cos_sin(sp)
    e3 = sp.Matrix([0, 0, 1])
    return [gamma, c * (e3 - gamma[2] * gamma) + s * e3.cross(gamma)]


def _symbolic_velocity(gamma: Any, tau: Any, wxr: Any, free: Any) -> Any:
    import sympy

    c, s = _cos_sin(sympy)
    nu = gamma.cross(tau)  # tau unit: nu unit
    return -wxr + free[0] * (-s * nu + c * tau)  # the contact point slips along e only


MODEL = ContactModel(
    name="oblique",
    description="contact kept, no slip along cos(phi) nu + sin(phi) tau, between the axis "
    "projection (the paper, phi = 0) and across it (the companion paper, phi = pi/2)",
    constraints=(
        "contact (vp, gamma) = 0",
        "no slip along d = cos(phi) nu + sin(phi) tau, (vp, d) = 0",
    ),
    free_velocity={"v_slip": 1},
    integrals_symmetric=("energy", "jellett"),
    integrals_general=("energy",),
    velocity=_velocity_for(DEFAULT_ANGLE),
    symbolic=Symbolic(
        _symbolic_directions, _symbolic_velocity, claims="rollingtop.symbolic.oblique:claims"
    ),
    vertical=Vertical(
        direction=vertical_direction,
        eigenvalues=_vertical_eigenvalues,
        carries_direction=True,
        determined=False,
    ),
    colour="#e377c2",
    parameters=PARAMETERS,
    bind=_bind,
)


def oblique(angle: float) -> ContactModel:
    """The oblique model at ``phi = angle`` (radians)."""
    return MODEL.with_parameters(angle=angle)


__all__ = ["MODEL", "PARAMETERS", "oblique"]
