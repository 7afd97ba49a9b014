"""Initial states on a level set of the first integrals, for any contact model.

The level is that of a given state: the values there of the integrals the model conserves
(:meth:`rollingtop.contact.ContactModel.integrals`; energy always among them), or of a chosen
subset ``hold``. A sample is drawn in two steps:

1. **Orientation**: the upward vertical ``gamma`` uniform on the sphere (rejected where the model
   is singular, and, for models with a vertical tolerance, within ``1e-3`` of the vertical), and
   the fixed frame's ``alpha`` uniform among the horizontal directions.
2. **Velocities**: ``u = (v, w)`` in the model's constraint subspace at that orientation
   (``J u = 0``, the model's compiled ``constraint_rows``), with coordinates ``c`` in
   an orthonormal basis of it. Every integral but the energy is linear in ``u`` for the models
   of the registry; their values fix ``c`` up to the null space ``N`` of their (numerical)
   Jacobian: ``c = c_p + x n`` with ``c_p`` the least-squares solution and ``n`` a random unit
   direction of ``N``, orthogonal to ``c_p`` in the kinetic-energy metric. The energy, quadratic
   in ``x``, then fixes ``x`` (one of its two roots at random); an orientation where the level's
   energy is out of reach is drawn again. A model with its own velocity in the state's last
   slot (:attr:`~rollingtop.contact.OwnVelocity.value`: the shell-rotor pair's shell
   spin) has it set from ``u`` at every evaluation, so its integrals are the pair's. Newton
   iterations on all held integrals (least-squares steps) polish the result, so an integral that
   is not linear in ``u`` is held as well, and each sample is checked: every held integral within
   :data:`LEVEL_RTOL` of its value (relative to ``1 +`` its size).

The orientations are uniform; the velocities are not uniform in the level's invariant measure
(there is none in general for a nonholonomic model), which a Poincare section does not need.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._checks import short_repr
from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import workspace
from rollingtop._errors import InitialStateError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, get_model
from rollingtop.dynamics.integrals import evaluate
from rollingtop.dynamics.state import initial_state

__all__ = ["LEVEL_RTOL", "held_integrals", "level_states", "level_values"]

#: Largest deviation of a held integral at a sample from its level value, relative to ``1 +``
#: that value's size.
LEVEL_RTOL = 1e-9
#: Newton iterations stop at this relative residual (a few units of round-off).
NEWTON_RTOL = 1e-14
#: Orientations drawn per sample at most before giving up.
MAX_TRIES = 400
#: Smallest distance of a sampled axis from the vertical, for models with a vertical tolerance.
VERTICAL_MARGIN = 1e-3
#: Step of the central differences of the integrals in the velocity coordinates (exact for
#: linear and quadratic integrals up to round-off).
FD_STEP = 1e-4


def held_integrals(
    body: SphericalTop, model: str | ContactModel, hold: Sequence[str] | None = None
) -> tuple[str, ...]:
    """The integrals held on the level: ``hold`` (checked against the model's), else all of the
    model's for this body; the energy is always held."""
    model = get_model(model)
    own = model.integrals_for(body)
    if hold is None:
        return tuple(own)
    names = tuple(dict.fromkeys(["energy", *hold]))
    unknown = [n for n in names if n not in own]
    if unknown:
        raise InitialStateError(
            f"{short_repr(', '.join(unknown))} is not an integral of model {model.name!r} for "
            f"this body (it has: {', '.join(own)})"
        )
    return names


def level_values(
    body: SphericalTop, model: str | ContactModel, state: ArrayLike, names: Sequence[str]
) -> FloatArray:
    """The integrals ``names`` at ``state``, shape (len(names),)."""
    model = get_model(model)
    y = np.asarray(state, dtype=float)
    pole = model.kernel(body, y).variant
    values = evaluate(body, y, names, pole=pole, model=model)
    return np.array([float(values[n]) for n in names])


def _values(
    body: SphericalTop, model: ContactModel, Y: FloatArray, names: Sequence[str]
) -> FloatArray:
    values = evaluate(body, Y, names, model=model)
    return np.stack([np.asarray(values[n], dtype=float) for n in names], axis=-1)


def _orientation(
    rng: np.random.Generator, model: ContactModel, body: SphericalTop
) -> tuple[FloatArray, FloatArray]:
    while True:
        gamma = rng.normal(size=3)
        gamma /= np.linalg.norm(gamma)
        if model.vertical.tolerance > 0 and math.hypot(gamma[0], gamma[1]) < VERTICAL_MARGIN:
            continue
        if model.vertical.singular is not None and model.vertical.singular(body, gamma) is not None:
            continue
        alpha = np.cross(gamma, rng.normal(size=3))
        return gamma, alpha / np.linalg.norm(alpha)


def _velocity_basis(body: SphericalTop, model: ContactModel, y: FloatArray) -> FloatArray:
    """Orthonormal basis of the constraint subspace ``J u = 0`` at ``y``, shape (d, 6)."""
    J, bias, dirs, _, _ = workspace()
    code = model.kernel_code(body, y)
    nc = call(for_code(code).dynamics.constraint_rows, code, model.params(body), y, J, bias, dirs)
    if nc == 0:
        return np.eye(6)
    _, sv, vt = np.linalg.svd(J[:nc])
    rank = int(np.sum(sv > 1e-12 * sv[0]))
    basis: FloatArray = vt[rank:]
    return basis


def _sample(
    body: SphericalTop,
    model: ContactModel,
    names: Sequence[str],
    target: FloatArray,
    rng: np.random.Generator,
) -> FloatArray | None:
    """One state on the level, or ``None`` where this orientation cannot carry it."""
    gamma, alpha = _orientation(rng, model, body)
    y = initial_state(body, model, gamma=gamma, omega=np.zeros(3), alpha=alpha)
    basis = _velocity_basis(body, model, y)
    d = basis.shape[0]
    mass = np.array([body.m] * 3 + list(body.inertia))

    def states(c: FloatArray) -> FloatArray:
        Y = np.repeat(y[None, :], len(c), axis=0)
        Y[:, :6] = c @ basis
        if model.own is not None:  # the model's own velocity (the pair's shell spin)
            for row in Y:
                row[17] = model.own.value(body, row)
        return Y

    def jacobian(c: FloatArray) -> tuple[FloatArray, FloatArray]:
        steps = np.vstack([c, c + FD_STEP * np.eye(d), c - FD_STEP * np.eye(d)])
        F = _values(body, model, states(steps), names)
        return F[0], (F[1 : d + 1] - F[d + 1 :]).T / (2 * FD_STEP)

    energy_row = list(names).index("energy")
    linear = [k for k in range(len(names)) if k != energy_row]
    F0, Jac = jacobian(np.zeros(d))
    c: FloatArray = np.zeros(d)
    if linear:
        A = Jac[linear]
        c = np.linalg.lstsq(A, target[linear] - F0[linear], rcond=1e-12)[0].astype(float)
        _, sv, vt = np.linalg.svd(A)
        rank = int(np.sum(sv > 1e-10 * max(sv[0], 1.0)))
        free = vt[rank:]
    else:
        free = np.eye(d)
    if free.shape[0] == 0:
        return None
    Mb = basis @ np.diag(mass) @ basis.T  # kinetic metric in the coordinates
    n = free.T @ rng.normal(size=free.shape[0])
    n -= c * (n @ Mb @ c) / (c @ Mb @ c) if c @ Mb @ c > 0 else 0.0
    if not np.linalg.norm(n) > 1e-12:
        return None
    # the energy along c + x n is quadratic in x (the kinetic energy is a quadratic form in the
    # velocities, the model's own slot included): E(x) = e0 + b x + a x^2 from three values
    e_m, e0, e_p = _values(body, model, states(np.array([c - n, c, c + n])), ["energy"])[:, 0]
    a, b = 0.5 * (e_p + e_m) - e0, 0.5 * (e_p - e_m)
    disc = b * b - 4.0 * a * (e0 - target[energy_row])
    if not (a > 0.0 and disc >= 0.0):
        return None
    x = (-b + rng.choice((-1.0, 1.0)) * math.sqrt(disc)) / (2.0 * a)
    c = c + x * n
    for _ in range(20):  # Newton, least-squares steps
        F, Jac = jacobian(c)
        res = target - F
        if np.all(np.abs(res) <= NEWTON_RTOL * (1 + np.abs(target))):
            break
        dc, *_ = np.linalg.lstsq(Jac, res, rcond=1e-12)
        c = c + dc
    Y = states(c[None, :])[0]
    try:
        out = initial_state(body, model, gamma=gamma, omega=Y[3:6], alpha=alpha, v=Y[:3])
    except InitialStateError:  # pragma: no cover - the velocity is on the constraints
        return None
    got = level_values(body, model, out, names)
    if np.all(np.abs(got - target) <= LEVEL_RTOL * (1 + np.abs(target))):
        return out
    return None


def level_states(
    body: SphericalTop,
    model: str | ContactModel,
    state: ArrayLike,
    n: int,
    *,
    hold: Sequence[str] | None = None,
    seed: int | None = 0,
) -> FloatArray:
    """``n`` states on the level set of ``state`` (module docstring: how they are drawn).

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
    state : array_like, shape (18,)
        A constraint-consistent state; the level is its values of the held integrals.
    n : int
        Number of states, ``n >= 1``.
    hold : sequence of str, optional
        Integrals held (default: all of the model's for this body; the energy always).
    seed : int or None
        Seed of the random draws (``None``: fresh entropy).

    Returns
    -------
    states : ndarray, shape (n, 18)
        The first is ``state`` itself; each other one holds every held integral to
        :data:`LEVEL_RTOL`, at position ``(0, 0)``.

    Raises
    ------
    InitialStateError
        For a bad ``hold`` or ``n``, or when :data:`MAX_TRIES` orientations per state do not
        carry the level (a level reachable only near one orientation: give the states yourself).
    """
    model = get_model(model)
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise InitialStateError(f"n = {n!r} must be an integer >= 1")
    y0 = np.array(state, dtype=float)
    if y0.shape != (N_STATE,) or not np.all(np.isfinite(y0)):
        raise InitialStateError(f"state must be {N_STATE} finite numbers, got shape {y0.shape}")
    names = held_integrals(body, model, hold)
    target = level_values(body, model, y0, names)
    rng = np.random.default_rng(seed)
    out = [y0]
    tries = 0
    while len(out) < n:
        tries += 1
        if tries > MAX_TRIES * n:
            raise InitialStateError(
                f"only {len(out)} of {n} states found on the level ({', '.join(names)}) after "
                f"{tries - 1} orientations: the level is reachable from few orientations"
            )
        y = _sample(body, model, names, target, rng)
        if y is not None:
            out.append(y)
    return np.array(out)
