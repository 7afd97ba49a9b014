"""First integrals, evaluated on arrays of states (``docs/model.md``, "Energy and first integrals").

Each function takes the body and states ``Y`` of shape ``(..., 18)`` and returns shape ``(...)``
(a numpy scalar for a single state, as numpy's own reductions do).
Which integrals hold for which model and body is declared by the contact models
(:meth:`rollingtop.contact.ContactModel.integrals`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._layout import ALPHA, BETA, GAMMA, PSI_NU, V, W
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, get_model

__all__ = ["HELD_TOLERANCE", "INTEGRALS", "F6_reduced", "evaluate", "natural_scales"]

FloatArray: TypeAlias = NDArray[np.float64]
#: An integral: ``(body, Y)`` with states ``Y`` of shape ``(..., 18)`` -> values, shape ``(...)``.
Integral: TypeAlias = Callable[[SphericalTop, FloatArray], FloatArray]


def _lone(body: SphericalTop, name: str) -> None:
    """Refuse a body with a shell: its integral ``name`` is the model's
    (:attr:`rollingtop.contact.ContactModel.integral_forms`), not the lone body's."""
    if body.has_shell:
        raise ValueError(
            f"the {name} integral of a body with a shell is the shell-rotor pair's: evaluate it "
            "with model='shell-rotor' (rollingtop.dynamics.integrals.evaluate)"
        )


def _arm(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Contact point seen from the CoM, ``r = -R gamma - a``, shape ``(..., 3)``."""
    r: FloatArray = -body.R * Y[..., GAMMA]
    r[..., 2] -= body.a3
    return r


def _Iw(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Angular momentum about the CoM, ``I w``, shape ``(..., 3)``."""
    Iw: FloatArray = Y[..., W] * body.inertia
    return Iw


def energy(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """``E = m (v, v)/2 + (w, I w)/2 - m g (r, gamma)``; zero with the CoM on the plane.

    A lone body's. A model whose kinetic energy is more than the body's declares its own
    (:attr:`rollingtop.contact.ContactModel.integral_forms`: the ``shell-rotor`` pair's
    :func:`rollingtop.contact._shell_pair.pair_energy`), which :func:`evaluate` uses for it;
    a body with a shell is refused here (``ValueError``).
    """
    _lone(body, "energy")
    v, w, gamma = Y[..., V], Y[..., W], Y[..., GAMMA]
    kinetic = 0.5 * body.m * np.sum(v * v, axis=-1) + 0.5 * np.sum(w * _Iw(body, Y), axis=-1)
    E: FloatArray = kinetic - body.m * body.g * np.sum(_arm(body, Y) * gamma, axis=-1)
    return E


def lagrange(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Lagrange's integral ``F3 = I3 w3 = M3`` (symmetric body)."""
    F3: FloatArray = body.I3 * Y[..., 5]
    return F3


def jellett(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Jellett's integral ``F4 = (I w, r)`` of a lone body (the ``shell-rotor`` pair's:
    :func:`rollingtop.contact._shell_pair.pair_jellett`, see :func:`energy`)."""
    _lone(body, "jellett")
    F4: FloatArray = np.sum(_Iw(body, Y) * _arm(body, Y), axis=-1)
    return F4


def area(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Area integral ``F5 = (I w, gamma)``: vertical angular momentum about the CoM."""
    F5: FloatArray = np.sum(_Iw(body, Y) * Y[..., GAMMA], axis=-1)
    return F5


def reduced_components(
    Y: ArrayLike, pole: str | None = None, *, model: str | ContactModel | None = None
) -> dict[str, FloatArray]:
    """Reduced variables of states ``Y`` (paper Sec. 3.1), each of shape ``(...)``.

    Returns ``gamma3, s, theta, v_tau, w_tau, w_n, v_n, v3, w3``. The basis is the one of the
    constraint direction ``nu`` carried in the state (``psi_nu``, see
    :mod:`rollingtop._layout`): ``nu = cos(psi_nu) alpha + sin(psi_nu) beta``,
    ``tau = nu x gamma``, ``n = e3 x tau`` and the signed ``s = (nu, e3)``. Away from a pole
    passage this is exactly the paper's ``tau = e3 x gamma / s``, ``n = -(gamma1, gamma2, 0) / s``
    with ``s = sqrt(1 - gamma3^2) > 0``; after a passage of the pole in a pole case ``s, tau, n``
    and the components along them change sign (the signed convention of
    :mod:`rollingtop.reduction.level`), and ``theta = atan2(s, gamma3)`` is the signed nutation
    angle (taken in ``(0, 2 pi)`` for ``pole="north"``). States of 17 components (no
    ``psi_nu``), and the states of a ``model`` that keeps a velocity of its own in the last slot
    (:attr:`rollingtop.contact.ContactModel.own`, the shell-rotor pair), use the geometric
    ``nu``.
    """
    Y = np.asarray(Y, dtype=float)
    carried = Y.shape[-1] > 17 and (model is None or get_model(model).own is None)
    g1, g2, g3 = Y[..., 12], Y[..., 13], Y[..., 14]
    nu: FloatArray
    if carried:
        c, sn = np.cos(Y[..., 17]), np.sin(Y[..., 17])
        nu = c[..., None] * Y[..., ALPHA] + sn[..., None] * Y[..., BETA]
    else:
        h = np.hypot(g1, g2)
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.stack([-g3 * g1 / h, -g3 * g2 / h, h], axis=-1)
    tau = np.cross(nu, Y[..., GAMMA])
    n = np.stack([-tau[..., 1], tau[..., 0], np.zeros_like(tau[..., 0])], axis=-1)  # e3 x tau
    s = nu[..., 2]
    theta = np.arctan2(s, g3)
    if pole == "north":
        theta = np.mod(theta, 2 * np.pi)
    v, w = Y[..., V], Y[..., W]
    return {
        "gamma3": g3,
        "s": s,
        "theta": theta,
        "v_tau": np.sum(v * tau, axis=-1),
        "w_tau": np.sum(w * tau, axis=-1),
        "w_n": np.sum(w * n, axis=-1),
        "v_n": np.sum(v * n, axis=-1),
        "v3": Y[..., 2],
        "w3": Y[..., 5],
    }


def F6_reduced(
    body: SphericalTop,
    M3: float | FloatArray,
    gamma3: FloatArray,
    s: FloatArray,
    theta: FloatArray,
    v_tau: FloatArray,
    w_n: FloatArray,
) -> FloatArray:
    """The paper's new linear integral in the reduced variables (eq. 3.9), the one definition:

    ``F6 = I1 (v_tau - (R gamma3 + a3) w_n) - M3 (R s + a3 theta)``,

    with ``s = sqrt(1 - gamma3^2)`` and ``theta = arccos(gamma3)`` in the paper's unsigned
    variables, or the signed ``s`` and ``theta`` of a pole case (:func:`F6`). The arrays of
    reduced components broadcast together (numpy scalars for one state); the result has their
    common shape. Its inverse on a level set (``I1 v_tau`` from ``C2``) is
    :meth:`rollingtop.reduction.LevelSet.P`.
    """
    F6: FloatArray = body.I1 * (v_tau - (body.R * gamma3 + body.a3) * w_n) - M3 * (
        body.R * s + body.a3 * theta
    )
    return F6


def F6(body: SphericalTop, Y: FloatArray, pole: str | None = None) -> FloatArray:
    """The paper's new linear integral (symmetric body, meridian model, eq. 3.9) of states ``Y``:
    :func:`F6_reduced` of the reduced variables of :func:`reduced_components`, where
    ``sqrt(1 - gamma3^2)`` and ``arccos(gamma3)`` are the signed ``s`` and ``theta``, so that it
    stays constant through the pole passages of a pole case, where the paper's unsigned
    expression changes sign. A lone body's (the ``shell-rotor`` pair's:
    :func:`rollingtop.contact._shell_pair.pair_F6`, see :func:`energy`).
    """
    _lone(body, "F6")
    c = reduced_components(Y, pole)
    M3: FloatArray = body.I3 * Y[..., 5]
    return F6_reduced(body, M3, c["gamma3"], c["s"], c["theta"], c["v_tau"], c["w_n"])


def momentum_x(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Horizontal momentum along the fixed axis of ``alpha``: ``m (v, alpha)``."""
    p: FloatArray = body.m * np.sum(Y[..., V] * Y[..., ALPHA], axis=-1)
    return p


def momentum_y(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Horizontal momentum along the fixed axis of ``beta``: ``m (v, beta)``."""
    p: FloatArray = body.m * np.sum(Y[..., V] * Y[..., BETA], axis=-1)
    return p


def routh(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """Routh's integral ``w3 sqrt(I1 I3 + m I1 (r1^2 + r2^2) + m I3 r3^2)`` (rough plane)."""
    r = _arm(body, Y)
    q = body.I1 * body.I3 + body.m * body.I1 * (r[..., 0] ** 2 + r[..., 1] ** 2)
    q = q + body.m * body.I3 * r[..., 2] ** 2
    routh_: FloatArray = Y[..., 5] * np.sqrt(q)
    return routh_


def rubber_spin(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The rubber model's integral ``w3 sqrt(I3 J)``, ``J = (I nu, nu) + m (r, gamma)^2`` with
    ``nu`` the axis's horizontal projection, ``(I nu, nu) = I1 + I3 - (I gamma, gamma)`` for a
    symmetric body (rolling without slipping or spinning, :mod:`rollingtop.reduction.rubber`)."""
    gamma = Y[..., GAMMA]
    Ig = np.sum(body.inertia * gamma * gamma, axis=-1)
    rg = np.sum(_arm(body, Y) * gamma, axis=-1)
    J = body.I1 + body.I3 - Ig + body.m * rg * rg
    value: FloatArray = Y[..., 5] * np.sqrt(body.I3 * J)
    return value


def slip_nu(body: SphericalTop, Y: FloatArray) -> FloatArray:
    """The contact point's slip along the carried direction ``nu``: ``(v_P, nu)``.

    An integral of the ``parallel`` model when ``a3 = 0`` and ``I3 = I1``
    (:mod:`rollingtop.symbolic.parallel`). That model keeps ``v_P`` along ``nu``, whose sign
    flips with the axis's horizontal projection at a pole passage; the value is therefore
    ``|v_P|`` with the sign of ``(v_P, nu_c)``, ``nu_c = cos(psi_nu) alpha + sin(psi_nu) beta``
    the direction the state carries continuously through the vertical
    (:mod:`rollingtop.contact.parallel`).
    """
    vp = Y[..., V] + np.cross(Y[..., W], _arm(body, Y))
    psi = Y[..., PSI_NU]
    nu_c = np.cos(psi)[..., None] * Y[..., ALPHA] + np.sin(psi)[..., None] * Y[..., BETA]
    sign = np.where(np.sum(vp * nu_c, axis=-1) < 0.0, -1.0, 1.0)
    u: FloatArray = sign * np.sqrt(np.sum(vp * vp, axis=-1))
    return u


#: Every integral by name.
INTEGRALS: dict[str, Integral] = {
    f.__name__: f
    for f in (
        energy,
        lagrange,
        jellett,
        area,
        F6,
        momentum_x,
        momentum_y,
        routh,
        rubber_spin,
        slip_nu,
    )
}


def evaluate(
    body: SphericalTop,
    Y: ArrayLike,
    names: Iterable[str],
    pole: str | None = None,
    *,
    model: str | ContactModel | None = None,
) -> dict[str, FloatArray]:
    """Evaluate the integrals ``names`` on states ``Y`` (shape ``(..., 18)``).

    ``pole`` is the meridian pole case the states belong to, if any (see :func:`F6`);
    ``model`` the contact model of the states, whose own forms of an integral
    (:attr:`rollingtop.contact.ContactModel.integral_forms`, the ``shell-rotor`` pair's energy,
    Jellett integral and ``F6``) replace the lone body's. Without a model, the lone body's
    (a body with a shell is then refused, ``ValueError``).
    """
    Y = np.asarray(Y, dtype=float)
    forms = {} if model is None else get_model(model).integral_forms
    out: dict[str, FloatArray] = {}
    for name in names:
        if name in forms:
            out[name] = forms[name](body, Y)
        else:
            out[name] = F6(body, Y, pole) if name == "F6" else INTEGRALS[name](body, Y)
    return out


#: Largest drift of a held integral (:func:`rollingtop.simulate`'s ``project_integrals``), as a
#: fraction of its natural size (:func:`natural_scales`), that a run may report as held.
HELD_TOLERANCE = 1e-12


def natural_scales(
    body: SphericalTop,
    Y: ArrayLike,
    names: Iterable[str],
    pole: str | None = None,
    *,
    model: str | ContactModel | None = None,
) -> dict[str, float]:
    """The natural size of each integral ``names`` along the states ``Y`` (shape ``(n, 18)``):
    the largest, over the states, of the size the integral can take at the state's speed, so
    that a drift divided by it is a drift relative to the round-off of the motion, whatever the
    integral's own value (which may be zero, with every term of it: the spin of a body that
    rolls over).

    The integrals are ``model``'s (:func:`evaluate`). Every integral but the energy is
    homogeneous of degree one in the velocity ``u`` (``v``, ``w`` and, for a model with its own
    inertia, :attr:`rollingtop.contact.ContactModel.own_inertia`, the state's last slot: the
    shell's spin): by
    Cauchy-Schwarz ``|I| <= |grad I|_(M^-1) |u|_M`` in the kinetic-energy metric ``M =
    diag(m, m, m, I1, I2, I3[, shell_inertia])``, with ``grad I`` read off the integral at each
    unit velocity component (for ``slip_nu``, a norm, a bound of it). The energy's size is the
    kinetic energy plus the magnitude of the potential, ``(E - E|u=0) + |E|u=0|``.
    """
    Y = np.atleast_2d(np.asarray(Y, dtype=float))
    slot_is_velocity = model is not None and get_model(model).own_inertia
    velocity = [*range(6), *([PSI_NU] if slot_is_velocity else [])]
    still = Y.copy()
    still[:, velocity] = 0.0
    metric = [body.m] * 3 + [float(x) for x in body.inertia]
    metric += [body.shell_inertia] * slot_is_velocity
    root = np.sqrt(np.asarray(metric))
    speed = _norms(root[:, None] * Y[:, velocity].T)  # |u|_M
    out = {}
    for name in names:
        if name == "energy":
            e0 = evaluate(body, still, (name,), model=model)[name]
            size = evaluate(body, Y, (name,), model=model)[name] - e0 + np.abs(e0)
        else:
            grad = np.empty((len(velocity), Y.shape[0]))  # grad I in the metric M^-1
            for row, (j, r) in enumerate(zip(velocity, root, strict=True)):
                unit = still.copy()
                unit[:, j] = 1.0
                grad[row] = evaluate(body, unit, (name,), pole, model=model)[name] / r
            with np.errstate(over="ignore"):  # a product beyond doubles: inf, said by the caller
                size = _norms(grad) * speed
        out[name] = float(np.max(size)) if size.size else 0.0
    return out


def _norms(parts: FloatArray) -> FloatArray:
    """The Euclidean norm of each column of ``parts`` (shape ``(k, n)``), scaled by the column's
    largest magnitude: no square overflows (an inertia of 1e300 has a gradient of that size)."""
    scale = np.max(np.abs(parts), axis=0)
    unit = np.where(scale > 0, scale, 1.0)
    norms: FloatArray = scale * np.sqrt(np.sum((parts / unit) ** 2, axis=0))
    return norms
