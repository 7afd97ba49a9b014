"""Constraint-consistent initial states built from user inputs."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import before_projection, compiling, for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import InitialStateError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, get_model

__all__ = ["initial_state", "constraint_residuals", "project_state", "UNIT_TOLERANCE"]

#: Tolerance on the unit length and orthogonality of user-given vectors, and on the constraint
#: residuals of a user-given velocity.
UNIT_TOLERANCE = 1e-9


def _vector(name: str, value: object, length: int) -> FloatArray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InitialStateError(f"{name} = {value!r} must be a list of {length} numbers") from None
    if arr.shape != (length,) or isinstance(value, str):
        raise InitialStateError(f"{name} = {value!r} must be a list of {length} numbers")
    if not np.all(np.isfinite(arr)):
        raise InitialStateError(f"{name} = {value!r} must be finite")
    return arr


def _unit(name: str, value: object) -> FloatArray:
    x = _vector(name, value, 3)
    norm = float(np.linalg.norm(x))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise InitialStateError(
            f"{name} = {x.tolist()} is not a unit vector (|{name}| = {norm:.12g}, "
            f"tolerance {UNIT_TOLERANCE:g})"
        )
    return x / norm


def default_alpha(gamma: FloatArray) -> FloatArray:
    """Default fixed ``x`` axis: the horizontal projection of the symmetry axis ``e3``.

    In the body frame this is ``nu = (e3 - gamma3 gamma)/s``, so the azimuth of the axis starts at
    ``psi = atan2(beta3, alpha3) = 0`` (``docs/model.md``, "Motion in absolute space"). When the
    axis is vertical, the horizontal projection of ``e1`` is used instead.
    """
    for e in np.eye(3)[[2, 0, 1]]:
        h = e - (e @ gamma) * gamma
        norm = np.linalg.norm(h)
        if norm > 1e-6:
            unit: FloatArray = h / norm
            return unit
    raise AssertionError("unreachable: some body axis is not vertical")


def _vertical(model: ContactModel, gamma: FloatArray) -> FloatArray:
    """``gamma`` set exactly vertical, ``(0, 0, +-1)``, where the model counts it as vertical
    (``sqrt(gamma1^2 + gamma2^2)`` below :attr:`rollingtop.contact.Vertical.tolerance`)."""
    if math.hypot(gamma[0], gamma[1]) < model.vertical.tolerance:
        return np.array([0.0, 0.0, math.copysign(1.0, gamma[2])])
    return gamma


def _horizontal(alpha: FloatArray, gamma: FloatArray) -> FloatArray:
    """``alpha`` made exactly orthogonal to ``gamma`` and unit (at a vertical ``gamma`` its third
    component becomes exactly 0, which keeps the frame's zeros exact in the projection)."""
    alpha = alpha - float(alpha @ gamma) * gamma
    unit: FloatArray = alpha / np.linalg.norm(alpha)
    return unit


def _start_code(body: SphericalTop, model: ContactModel, y: FloatArray) -> int:
    """Kernel code used to project a new state: the model's own, except at a vertical axis, where
    a model's variant (:meth:`ContactModel.kernel`: the meridian model's pole variant, which
    carries ``nu``) is the only one defined. Away from the vertical the model's own code keeps the
    constructed states exactly as they were before vertical starts existed."""
    if y[12] == 0.0 and y[13] == 0.0:
        return model.kernel_code(body, y)
    return model.code


def _check_spin(model: ContactModel, gamma: FloatArray, omega: FloatArray) -> None:
    """Refuse an ``omega`` that violates a constraint of the model on the angular velocity alone
    (:attr:`ContactModel.spin_directions`, rubber rolling's ``(omega, gamma) = 0``): by more
    than :data:`UNIT_TOLERANCE` times ``|omega|``. Within it the projection enforces it exactly;
    beyond it the given ``omega`` is not the model's, and it is not silently changed."""
    if model.spin_directions is None:
        return
    largest = float(np.max(np.abs(omega)))
    if largest == 0.0:
        return
    # relative: np.linalg.norm squares (1e-300 has norm 0) and UNIT_TOLERANCE |omega| underflows
    unit = omega / largest
    unit = unit / float(np.linalg.norm(unit))
    for name, d in model.spin_directions(gamma).items():
        res = float(omega @ np.asarray(d, dtype=float))
        if abs(float(unit @ np.asarray(d, dtype=float))) > UNIT_TOLERANCE:
            raise InitialStateError(
                f"omega = {omega.tolist()} violates the constraint {name} of model "
                f"{model.name!r} (residual {res:.3g}, tolerance {UNIT_TOLERANCE:g} |omega|)"
            )


def constraint_residuals(body: SphericalTop, model: str | ContactModel, y: ArrayLike) -> FloatArray:
    """Residuals ``J_k u`` of the model's constraint rows at state ``y``, shape (rows,)."""
    model = get_model(model)
    state = np.asarray(y, dtype=float)
    J, bias, dirs, _, _ = workspace()
    nc = call(
        for_code(model.code).dynamics.constraint_rows,
        model.code,
        model.params(body),
        state,
        J,
        bias,
        dirs,
    )
    residuals: FloatArray = J[:nc] @ state[:6]
    return residuals


def initial_state(
    body: SphericalTop,
    model: str | ContactModel,
    *,
    gamma: ArrayLike,
    omega: ArrayLike,
    alpha: ArrayLike | None = None,
    position: ArrayLike = (0.0, 0.0),
    v: ArrayLike | None = None,
    free: Mapping[str, object] | None = None,
) -> FloatArray:
    """Build a constraint-consistent state vector.

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
        Contact model, or its name (a key of :data:`rollingtop.contact.MODELS`).
    gamma : array_like, shape (3,)
        Upward vertical in the body frame; unit within 1e-9 (then normalised exactly).
    omega : array_like, shape (3,)
        Angular velocity, body frame.
    alpha : array_like, shape (3,), optional
        Fixed ``x`` axis in the body frame, unit and orthogonal to ``gamma`` within 1e-9.
        Default: :func:`default_alpha` (fixed ``x`` along the horizontal projection of the axis).
    position : array_like, shape (2,)
        Horizontal CoM position ``(X, Y)`` in the fixed frame.
    v : array_like, shape (3,), optional
        Full body-frame CoM velocity; must satisfy every constraint of the model within 1e-9.
    free : mapping, optional
        The model's free velocity components (``meridian``: ``v_tau``; ``smooth``:
        ``v_horizontal = (vx, vy)`` along the fixed axes; ``rough``, ``rubber``: none). Missing
        ones are 0. Exclusive with ``v``.

    Returns
    -------
    y : ndarray, shape (18,)
        ``(v, w, alpha, beta, gamma, X, Y, psi_nu)`` with ``beta = gamma x alpha`` and
        ``psi_nu = atan2(beta3, alpha3)``, the azimuth of the axis in the fixed frame (see
        "Vertical axis" for its value there).

    Notes
    -----
    **Vertical axis.** A model with a :attr:`~rollingtop.contact.Vertical.tolerance` (the meridian
    model: ``1e-8``) takes an axis that close to the vertical as exactly vertical, ``gamma = (0, 0,
    +-1)`` (and ``alpha`` re-orthogonalised to it); the others keep ``gamma`` as given. At an
    exactly vertical axis ``psi_nu`` is the model's carried constraint direction, ``nu = cos(psi_nu)
    alpha + sin(psi_nu) beta``: for the meridian model
    (:func:`rollingtop.contact.meridian.vertical_direction`) the direction in which the axis leaves
    the vertical, ``(w x e3)/|w x e3|``, or ``nu = alpha`` (``psi_nu = 0``) when ``w1 = w2 = 0``;
    the state lies on a pole level ``C1 = +-M3`` and
    :func:`rollingtop.contact.meridian.select_variant` picks the pole variant that carries ``nu``.
    Other models: ``psi_nu = 0`` (unused).

    **Spin constraints.** A model that constrains the angular velocity alone
    (:attr:`~ContactModel.spin_directions`; rubber rolling: ``(omega, gamma) = 0``) refuses an
    ``omega`` that violates it by more than :data:`UNIT_TOLERANCE` times ``|omega|``, with an
    :class:`InitialStateError` naming the constraint and its residual; ``omega`` is not
    projected onto it.
    """
    model = get_model(model)
    free = dict(free or {})
    gamma = _unit("gamma", gamma)
    omega = _vector("omega", omega, 3)
    if alpha is not None:
        alpha = _unit("alpha", alpha)
        dot = float(alpha @ gamma)
        if abs(dot) > UNIT_TOLERANCE:
            raise InitialStateError(
                f"alpha = {alpha.tolist()} is not orthogonal to gamma ((alpha, gamma) = {dot:.3g}, "
                f"tolerance {UNIT_TOLERANCE:g})"
            )
    gamma = _vertical(model, gamma)
    if (
        model.vertical.singular is not None
        and (why := model.vertical.singular(body, gamma)) is not None
    ):
        raise InitialStateError(f"model {model.name!r}: {why}")
    _check_spin(model, gamma, omega)
    alpha = default_alpha(gamma) if alpha is None else _horizontal(alpha, gamma)
    beta = np.cross(gamma, alpha)
    position = _vector("position", position, 2)

    unknown = sorted(set(free) - set(model.free_velocity))
    if unknown:
        allowed = ", ".join(model.free_velocity) or "none; give omega only, or a full v"
        raise InitialStateError(
            f"{', '.join(unknown)} is not a free velocity component of model {model.name!r} "
            f"(it has: {allowed})"
        )
    y = np.empty(N_STATE)
    y[3:6] = omega
    y[6:9], y[9:12], y[12:15] = alpha, beta, gamma
    y[15:17] = position
    y[17] = _axis_azimuth(y)
    if gamma[0] == 0.0 and gamma[1] == 0.0 and model.vertical.direction is not None:
        y[17] = model.vertical.direction(omega, alpha, beta)
    if v is not None:
        if free:
            raise InitialStateError(
                f"give either v or the free velocity components ({', '.join(free)}), not both"
            )
        y[0:3] = _vector("v", v, 3)
        residuals = constraint_residuals(body, model, y)
        for name, res in zip(model.constraints, residuals, strict=True):
            if abs(res) > UNIT_TOLERANCE:
                raise InitialStateError(
                    f"v = {y[0:3].tolist()} violates the constraint {name} of model "
                    f"{model.name!r} (residual {res:.3g}, tolerance {UNIT_TOLERANCE:g})"
                )
    else:
        values: dict[str, float | FloatArray] = {}
        for name, length in model.free_velocity.items():
            raw = free.get(name, 0.0 if length == 1 else [0.0] * length)
            if length == 1:
                if isinstance(raw, bool) or not isinstance(raw, int | float):
                    raise InitialStateError(f"{name} = {raw!r} must be a number")
                if not math.isfinite(raw):
                    raise InitialStateError(f"{name} = {raw!r} must be finite")
                values[name] = float(raw)
            else:
                values[name] = _vector(name, raw, length)
        y[0:3] = model.velocity(body, gamma, omega, alpha, beta, values)
    if model.own is not None:
        y[17] = model.own.value(body, y)
    code = _start_code(body, model, y)
    kernels = for_code(code)  # the model's own package, or its variants'
    with compiling(kernels, "integrator"):  # the projection: a model's first compiled kernel
        before_projection(kernels)
        call(kernels.dynamics.project, code, model.params(body), y, workspace())
    return y


def _axis_azimuth(y: FloatArray) -> float:
    """The axis azimuth ``psi = atan2(beta3, alpha3)`` of the frame in ``y``; 0 at a vertical
    axis (where ``atan2`` of signed zeros could give ``pi``)."""
    a3, b3 = float(y[8]), float(y[11])
    return math.atan2(b3, a3) if math.hypot(a3, b3) > 0 else 0.0


def project_state(
    body: SphericalTop,
    model: str | ContactModel,
    y: ArrayLike,
    *,
    source: str | ContactModel | None = None,
) -> FloatArray:
    """The state nearest to ``y`` that satisfies ``model``'s constraints.

    Orientation, position and ``psi_nu`` are kept; the velocities ``u = (v, w)`` move to the
    nearest point of the constraint set in the kinetic-energy metric (the velocity projection of
    the integrator). Used to start several contact models from "the same" state.

    At a vertical axis the rule of :func:`initial_state` applies: an axis within the model's
    :attr:`~rollingtop.contact.Vertical.tolerance` is set exactly vertical, and ``psi_nu``
    becomes the model's carried direction there (meridian: the direction in which the axis
    leaves the vertical; kept when ``w1 = w2 = 0``, where it is free).

    ``source`` is the model ``y`` was made for, if another: where its last slot is its own
    (:attr:`~rollingtop.contact.OwnVelocity.value`; the shell-rotor pair's shell spin) and
    ``model``'s is a direction, the slot starts again from the axis azimuth, as in
    :func:`initial_state`.
    """
    model = get_model(model)
    y = np.array(y, dtype=float)
    if source is not None and get_model(source).own is not None and model.own is None:
        y[17] = _axis_azimuth(y)
    gamma = _vertical(model, y[12:15])
    if (
        model.vertical.singular is not None
        and (why := model.vertical.singular(body, gamma)) is not None
    ):
        raise InitialStateError(f"model {model.name!r}: {why}")
    if gamma is not y[12:15]:  # set vertical: the frame follows
        y[12:15] = gamma
        y[6:9] = _horizontal(y[6:9], gamma)
        y[9:12] = np.cross(gamma, y[6:9])
    if gamma[0] == 0.0 and gamma[1] == 0.0 and model.vertical.direction is not None:
        y[17] = model.vertical.direction(y[3:6], y[6:9], y[9:12], y[17])
    ws = workspace()
    code = _start_code(body, model, y)
    dynamics = for_code(code).dynamics
    with compiling(for_code(code), "integrator"):
        before_projection(for_code(code))
        if model.own is not None:  # the rows' projection of (v, w), then the model's slot
            call(dynamics.project_velocity_rows, code, model.params(body), y, ws)
            y[17] = model.own.value(body, y)
        call(dynamics.project, code, model.params(body), y, ws)
    return y
