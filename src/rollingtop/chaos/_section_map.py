"""The Poincare section's map in the coordinates that do not see the symmetries
(:mod:`rollingtop.chaos.periodic`, :mod:`rollingtop.chaos.steady`).

A crossing of the section ``w_tau = 0`` of a dynamically symmetric body is fixed by its *section
coordinates* ``x = (gamma3, w_n, w3, u)``: the inclination, the angular velocity about the
horizontal axis ``n``, the spin ``w3`` and the model's free velocity component ``u`` (the
``parallel`` model's ``v_nu``, the meridian model's ``v_tau``), read in the geometric basis of
the axis's horizontal projection ``nu = (e3 - gamma3 gamma) / s``, ``s = sqrt(1 - gamma3^2) > 0``
(so a carried direction's sign, which flips at a passage of the vertical, does not enter). A
state is rebuilt from them (:func:`section_state`) with ``gamma = (0, s, gamma3)`` in the body
frame, ``w = (-w_tau, -w_n, w3)`` and the free component by :func:`rollingtop.initial_state`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._errors import InitialStateError, ScenarioError
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos.section import poincare_section
from rollingtop.contact import ContactModel, get_model
from rollingtop.dynamics.integrals import evaluate
from rollingtop.dynamics.state import initial_state

__all__ = [
    "SectionMap",
    "grid_axes",
    "reduced_coordinates",
    "reduced_state",
    "check_model",
    "free_key",
    "integral_gradients",
    "map_jacobian",
    "on_level",
    "section_coordinates",
    "section_state",
]

#: A crossing at a time up to this after the start is the start itself (it lies on the section).
START_CROSSING = 1e-9
#: Relative step of the central differences of the section map.
FD_STEP = 1e-5


def free_key(model: ContactModel) -> str:
    """The model's one scalar free velocity component (``ScenarioError`` for another model)."""
    scalar = [k for k, n in model.free_velocity.items() if n == 1]
    if len(model.free_velocity) != 1 or len(scalar) != 1 or model.own is not None:
        raise ScenarioError(
            f"periodic orbits: the {model.name} model's state on the section is not fixed by "
            "(gamma3, w_n, w3) and one free velocity component (models: meridian, parallel)"
        )
    return scalar[0]


def check_model(body: SphericalTop, model: ContactModel) -> None:
    if not body.symmetric:
        raise ScenarioError(
            "periodic orbits need a dynamically symmetric body (I1 = I2): the section "
            "coordinates leave out the body's rotation about its axis"
        )
    free_key(model)


def section_coordinates(model: str | ContactModel, Y: ArrayLike) -> FloatArray:
    """The section coordinates ``(gamma3, w_n, w3, u)`` of states ``Y`` (shape ``(..., 18)``),
    shape ``(..., 4)``, in the geometric basis of the module docstring (NaN at a vertical
    axis)."""
    model = get_model(model)
    Y = np.asarray(Y, dtype=float)
    g = Y[..., 12:15]
    s = np.hypot(g[..., 0], g[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        nu = (np.array([0.0, 0.0, 1.0]) - g[..., 2:3] * g) / s[..., None]
    tau = np.cross(nu, g)
    n = np.stack([-tau[..., 1], tau[..., 0], np.zeros_like(s)], axis=-1)
    w = Y[..., 3:6]
    key = free_key(model)
    u = np.sum(Y[..., 0:3] * (nu if key == "v_nu" else tau), axis=-1)
    return np.stack([g[..., 2], np.sum(w * n, axis=-1), w[..., 2], u], axis=-1)


def section_state(body: SphericalTop, model: str | ContactModel, x: ArrayLike) -> FloatArray:
    """The state on the section with coordinates ``x = (gamma3, w_n, w3, u)`` (shape (4,)):
    ``gamma = (0, s, gamma3)``, ``w = (0, -w_n, w3)`` (so ``w_tau = 0``), the free velocity
    ``u`` (:func:`rollingtop.initial_state`). ``InitialStateError`` where ``|gamma3| >= 1``."""
    model = get_model(model)
    g3, w_n, w3, u = (float(v) for v in np.asarray(x, dtype=float))
    return reduced_state(body, model, [g3, 0.0, w_n, w3, u])


def reduced_state(body: SphericalTop, model: str | ContactModel, z: ArrayLike) -> FloatArray:
    """The state with reduced coordinates ``z = (gamma3, w_tau, w_n, w3, u)`` (shape (5,)):
    ``gamma = (0, s, gamma3)``, ``w = (-w_tau, -w_n, w3)``, the free velocity ``u``
    (:func:`rollingtop.initial_state`). ``InitialStateError`` where ``|gamma3| >= 1``."""
    model = get_model(model)
    g3, w_tau, w_n, w3, u = (float(v) for v in np.asarray(z, dtype=float))
    if not abs(g3) < 1.0:
        raise InitialStateError(f"gamma3 = {g3!r}: the section needs a tilted axis")
    s = math.sqrt(1.0 - g3 * g3)
    free = {free_key(model): u}
    return initial_state(body, model, gamma=[0.0, s, g3], omega=[-w_tau, -w_n, w3], free=free)


def reduced_coordinates(model: str | ContactModel, Y: ArrayLike) -> FloatArray:
    """``(gamma3, w_tau, w_n, w3, u)`` of states ``Y`` (shape ``(..., 18)``), shape ``(..., 5)``:
    :func:`section_coordinates` with ``w_tau``."""
    Y = np.asarray(Y, dtype=float)
    x = section_coordinates(model, Y)
    g = Y[..., 12:15]
    s = np.hypot(g[..., 0], g[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        tau = np.stack([-g[..., 1], g[..., 0], np.zeros_like(s)], axis=-1) / s[..., None]
    w_tau = np.sum(Y[..., 3:6] * tau, axis=-1)
    return np.concatenate([x[..., :1], w_tau[..., None], x[..., 1:]], axis=-1)


class SectionMap:
    """``P^K`` of batches of section coordinates, on the compiled section."""

    def __init__(
        self, body: SphericalTop, model: ContactModel, names: Sequence[str], rtol: float
    ) -> None:
        self.body, self.model, self.names, self.rtol = body, model, tuple(names), rtol

    def states(self, X: FloatArray) -> FloatArray:
        return np.array([section_state(self.body, self.model, x) for x in X])

    def integrals(self, X: FloatArray) -> FloatArray:
        """The held integrals at section coordinates ``X`` (n, 4): shape (n, len(names))."""
        Y = self.states(X)
        values = evaluate(self.body, Y, self.names, model=self.model)
        return np.stack([np.asarray(values[k], dtype=float) for k in self.names], axis=-1)

    def __call__(self, X: FloatArray, K: int) -> tuple[FloatArray, FloatArray]:
        """``(P^1..K(X), t)``: the coordinates of the first ``K`` crossings, shape (n, K, 4),
        and their times (n, K); NaN where a trajectory stopped before."""
        ds = poincare_section(
            self.body,
            self.model,
            self.states(X),
            crossings=K + 1,
            hold=self.names,
            rtol=self.rtol,
            atol=self.rtol * 1e-2,
            max_gap_steps=20_000,
            threads=None,
        )
        # a start on the section may count as its first crossing (w_tau = 0 at t = 0): skipped
        t = ds["t"].values
        first = (t[:, 0] <= START_CROSSING).astype(int)
        rows = np.arange(t.shape[0])[:, None]
        cols = first[:, None] + np.arange(K)[None, :]
        coords = section_coordinates(self.model, ds["crossing_state"].values)
        return coords[rows, cols], t[rows, cols]


def map_jacobian(
    P: SectionMap, x: FloatArray, K: int, step: float = FD_STEP
) -> tuple[FloatArray, FloatArray, float]:
    """``P^K(x)``, its Jacobian (4, 4) by central differences, and the period."""
    h = step * np.maximum(1.0, np.abs(x))
    X = np.vstack([x, x + np.diag(h), x - np.diag(h)])
    out, t = P(X, K)
    F = out[:, K - 1]
    J = (F[1:5] - F[5:9]).T / (2 * h)
    return F[0], J, float(t[0, K - 1])


def integral_gradients(P: SectionMap, x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The held integrals at ``x`` and their gradients (len(names), 4), central differences."""
    h = FD_STEP * np.maximum(1.0, np.abs(x))
    X = np.vstack([x, x + np.diag(h), x - np.diag(h)])
    V = P.integrals(X)
    return V[0], ((V[1:5] - V[5:9]) / (2 * h[:, None])).T


def on_level(P: SectionMap, target: FloatArray, g3: float, w_n: float) -> list[FloatArray]:
    """The section coordinates ``(g3, w_n, w3, u)`` on the level: 0, 1 or 2 of them, in order
    of ``u`` (the level's sheets).

    Written for a level of the energy (quadratic in the velocities) and one integral linear in
    them (``parallel``'s energy and Jellett integral): both are fitted exactly in ``(w3, u)``
    from six states, the linear one fixes a line, the energy a quadratic along it."""
    base = np.array([g3, w_n, 0.0, 0.0])
    probe = np.array([[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [1, 1]], dtype=float)
    X = np.repeat(base[None], len(probe), axis=0)
    X[:, 2:] = probe
    V = P.integrals(X)
    e = P.names.index("energy")
    lin = 1 - e
    design = np.column_stack(
        [np.ones(6), probe[:, 0], probe[:, 1], probe[:, 0] ** 2, probe[:, 1] ** 2, probe.prod(1)]
    )
    c0, c1, c2, c11, c22, c12 = np.linalg.solve(design, V[:, e])
    j0, j1, j2 = V[0, lin], V[1, lin] - V[0, lin], V[2, lin] - V[0, lin]
    # the line j0 + j1 w3 + j2 u = target: (w3, u) = p + t d
    norm = math.hypot(j1, j2)
    if not norm > 1e-12 * max(1.0, abs(j0)):  # the linear integral does not see (w3, u) here
        return []
    d = np.array([-j2, j1]) / norm
    p = np.array([j1, j2]) * (target[lin] - j0) / (j1 * j1 + j2 * j2)
    qa = c11 * d[0] ** 2 + c22 * d[1] ** 2 + c12 * d[0] * d[1]
    qb = c1 * d[0] + c2 * d[1] + 2 * c11 * p[0] * d[0] + 2 * c22 * p[1] * d[1]
    qb += c12 * (p[0] * d[1] + p[1] * d[0])
    qc = c0 + c1 * p[0] + c2 * p[1] + c11 * p[0] ** 2 + c22 * p[1] ** 2 + c12 * p[0] * p[1]
    qc -= target[e]
    disc = qb * qb - 4 * qa * qc
    if not (qa > 0 and disc >= 0):
        return []
    roots = {(-qb + sign * math.sqrt(disc)) / (2 * qa) for sign in (-1.0, 1.0)}
    states = [np.array([g3, w_n, *(p + t * d)]) for t in roots]
    # in order of u: the sheets keep their order across the grid (the line's direction d
    # turns with the sign of the linear integral's coefficients)
    return sorted(states, key=lambda x: float(x[3]))


def grid_axes(iterates: FloatArray, n: int) -> tuple[FloatArray, FloatArray] | None:
    """The ``gamma3`` and ``w_n`` of an ``n`` x ``n`` grid over the iterates' range (padded by a
    tenth); ``None`` without iterates."""
    pts = iterates[np.all(np.isfinite(iterates), axis=-1)]
    if not len(pts) or n < 1:
        return None
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    pad = 0.1 * (hi - lo) + 1e-3
    g3s = np.linspace(max(lo[0] - pad[0], -0.999), min(hi[0] + pad[0], 0.999), n)
    wns = np.linspace(lo[1] - pad[1], hi[1] + pad[1], n)
    return g3s, wns
