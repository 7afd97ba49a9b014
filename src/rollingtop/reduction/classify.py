"""The classification of every reduced model side by side: for one body and one initial state,
each integrable model's level, the orbit through the state, its steady motions, and the
critical values of its energy along one of its level's integrals (its bifurcation set).

The meridian model's bifurcation diagram (:mod:`rollingtop.reduction.bifurcation`) follows the
critical curves of its ``(C2, h)`` plane in closed form and names the regions between them. For
the other models the same set is found numerically, by the model's own reduction
(:mod:`rollingtop.reduction.models`): along a grid of one integral (:data:`AXES`: the one that
does not fix the spin), the critical points of ``U`` (:func:`~rollingtop.reduction.steady_motions`)
and their energies ``U``. A level between two critical values holds the same orbits; the number
of steady motions changes where two critical values meet (a fold).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._errors import RollingTopError, ScenarioError
from rollingtop._json import finite_or_none, json_ready
from rollingtop.body import SphericalTop
from rollingtop.contact import MODELS
from rollingtop.reduction.level import Level, LevelSetError
from rollingtop.reduction.models import REDUCTIONS, reduction_of
from rollingtop.reduction.orbits import Orbit, orbits
from rollingtop.reduction.steady import SteadyMotion, steady_motions

__all__ = [
    "AXES",
    "CriticalValues",
    "ModelClassification",
    "RotationGrid",
    "admissible_omega",
    "classify_models",
    "critical_values",
    "rotation_grid",
]

FloatArray = NDArray[np.float64]

#: The integral each model's critical values are drawn against: the one that does not fix the
#: spin (the meridian model's ``C2``, as in its bifurcation diagram; the smooth plane's area
#: integral; Routh's sphere's Jellett integral; rubber rolling's only one).
AXES: dict[str, str] = {r.model: r.axis for r in REDUCTIONS.values()}


@dataclass(frozen=True)
class CriticalValues:
    """The critical values of a model's reduced energy along one integral of its level.

    Attributes
    ----------
    model, axis : str
        The model and the integral varied (:data:`AXES`).
    fixed : dict of str to float
        The level's other integrals.
    x : ndarray, shape (n,)
        The grid of the varied integral.
    count : ndarray of int, shape (n,)
        Steady motions at each ``x`` (-1 where the level is refused, e.g. a pole level the
        model does not reduce).
    points : ndarray, shape (k, 4)
        Every steady motion found: ``x``, ``gamma3``, ``U`` (its energy ``h``) and 1 for a
        centre, -1 for a saddle, 0 degenerate.
    """

    model: str
    axis: str
    fixed: dict[str, float]
    x: FloatArray
    count: NDArray[np.int64]
    points: FloatArray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "model": self.model,
            "axis": self.axis,
            "fixed": json_ready(self.fixed),
            "x": _plain(self.x),
            "count": self.count.tolist(),
            "points": _plain(self.points),
        }


def _plain(a: NDArray[Any]) -> list[Any]:
    """``a`` as nested lists of floats, non-finite ones as ``None`` (JSON)."""
    if a.ndim == 1:
        return [finite_or_none(float(v)) for v in a]
    return [_plain(row) for row in a]


def critical_values(
    level: Level,
    *,
    axis: str | None = None,
    window: tuple[float, float] | None = None,
    n: int = 121,
) -> CriticalValues:
    """The critical values of ``level``'s model along the integral ``axis`` (default
    :data:`AXES`), the others held at ``level``'s values.

    Parameters
    ----------
    level : LevelSet
        Any model's level (:mod:`rollingtop.reduction.models`).
    axis : str, optional
        One of the level's integrals (:meth:`LevelSet.values`).
    window : (float, float), optional
        Range of ``axis``; default: its value at ``level`` +- ``max(1, |value|)``.
    n : int
        Grid points (3 to 2001).
    """
    reduction = reduction_of(level.model)
    values = level.values()
    axis = AXES[level.model] if axis is None else axis
    if axis not in values:
        raise ScenarioError(
            f"axis {axis!r} is not an integral of the {level.model} model's "
            f"level ({', '.join(values)})"
        )
    if not 3 <= int(n) <= 2001:
        raise ScenarioError(f"n = {n} must be between 3 and 2001")
    x0 = values[axis]
    lo, hi = window if window is not None else (x0 - max(1.0, abs(x0)), x0 + max(1.0, abs(x0)))
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ScenarioError(f"{axis} window ({lo:g}, {hi:g}) must be finite and increasing")
    x = np.linspace(lo, hi, int(n))
    count = np.full(x.size, -1, dtype=np.int64)
    points: list[tuple[float, float, float, float]] = []
    kinds = {"center": 1.0, "saddle": -1.0}
    for i, xi in enumerate(x):
        try:
            lv = reduction.level(level.body, {**values, axis: float(xi)})
            found = steady_motions(lv)
        except LevelSetError:
            continue
        count[i] = len(found)
        points += [(float(xi), m.gamma3, m.U, kinds.get(m.type, 0.0)) for m in found]
    fixed = {k: v for k, v in values.items() if k != axis}
    pts = np.array(points, dtype=float).reshape(-1, 4)
    return CriticalValues(level.model, axis, fixed, x, count, pts)


@dataclass(frozen=True)
class ModelClassification:
    """One model's view of a state: its level and energy, the orbit through the state, its
    steady motions and its critical values (:func:`critical_values`)."""

    model: str
    level: Level
    h: float
    state: FloatArray
    orbit: Orbit | None
    steady: list[SteadyMotion]
    critical: CriticalValues
    note: str = field(default="")

    @property
    def delta_psi(self) -> float | None:
        """The axis azimuth's advance over one period of the orbit through the state
        (:func:`rollingtop.reduction.rotation.rotation_number`); ``None`` without an orbit."""
        from rollingtop.reduction.rotation import rotation_number

        if self.orbit is None:
            return None
        return 2 * math.pi * rotation_number(self.level, self.h, self.orbit)[0]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: ``model``, ``level`` (its integrals, ``h`` and the full energy),
        ``orbit`` (``None`` on a steady motion or a separatrix), ``equilibria``, ``critical``."""
        return json_ready(
            {
                "model": self.model,
                "level": {
                    **self.level.values(),
                    "h": self.h,
                    "energy": self.level.full_energy(self.h),
                    "pole": self.level.pole,
                },
                "orbit": None
                if self.orbit is None
                else {**self.orbit.to_dict(), "delta_psi": self.delta_psi},
                "equilibria": [m.to_dict() for m in self.steady],
                "critical": self.critical.to_dict(),
                "note": self.note,
            }
        )


def classify_models(
    body: SphericalTop,
    gamma: ArrayLike,
    omega: ArrayLike,
    *,
    models: Sequence[str] | None = None,
    n: int = 121,
    own: tuple[str, ArrayLike] | None = None,
    refused: dict[str, str] | None = None,
) -> list[ModelClassification]:
    """Each integrable model's classification of the motion from ``(gamma, omega)``.

    The state is built under each model (:func:`rollingtop.initial_state`: the same attitude
    and angular velocity, the centre of mass's velocity from that model's constraints, its free
    components 0), so the models see the same body started the same way.

    Parameters
    ----------
    body : SphericalTop
        Dynamically symmetric.
    gamma, omega : array_like, shape (3,)
        Upward vertical and angular velocity, body frame.
    models : sequence of str, optional
        Default: every model with a reduction that takes this body, in registry order (a body
        with a shell: the shell-rotor pair alone; without: the others).
    n : int
        Grid points of each model's critical values.
    own : (str, array_like), optional
        A model's name and a full state of it (shape (18,)) used as it is for that model (a
        scenario's own model and state, with its free velocity components).
    refused : dict, optional
        Filled with the models whose level of the state is refused (a pole level a model does
        not reduce yet) and why; the other models are classified all the same.
    """
    refused = {} if refused is None else refused
    from rollingtop.dynamics.state import initial_state
    from rollingtop.reduction.variables import reduce_state

    # the models of this body: a shell-rotor pair's under the pair's model, a bare body's under
    # the others (ContactModel.own_inertia)
    names = (
        [m for m, c in MODELS.items() if m in REDUCTIONS and c.own_inertia == body.has_shell]
        if models is None
        else list(models)
    )
    out = []
    for name in names:
        reduction = reduction_of(name)
        projected = ""
        if own is not None and own[0] == name:
            y = np.asarray(own[1], dtype=float)
        else:
            w, projected = admissible_omega(name, gamma, omega)
        try:
            if own is None or own[0] != name:
                y = initial_state(body, name, gamma=gamma, omega=w)
            level = reduction.level_of_state(body, y)
            h = reduction.reduced_energy(body, y)
            theta = float(reduce_state(y, model=name)["theta"])
            found = [
                o for o in orbits(level, h) if o.theta_min - 1e-9 <= theta <= o.theta_max + 1e-9
            ]
            steady = steady_motions(level)
        except RollingTopError as err:  # a level the model does not reduce, a flat U: others go on
            refused[name] = str(err)
            continue
        orbit = found[0] if found and found[0].kind == "periodic" else None
        note = "" if orbit is not None else "the state lies on a steady motion or a separatrix"
        note = "; ".join(x for x in (projected, note) if x)
        out.append(
            ModelClassification(name, level, h, y, orbit, steady, critical_values(level, n=n), note)
        )
    return out


def admissible_omega(name: str, gamma: ArrayLike, omega: ArrayLike) -> tuple[FloatArray, str]:
    """``omega`` under the model ``name``'s constraints on the angular velocity alone
    (:attr:`~rollingtop.contact.ContactModel.spin_directions`; rubber rolling's
    ``(omega, gamma) = 0``): its parts along them dropped, and a note saying so (empty when
    nothing is dropped). The models side by side start from the same attitude and, as far as
    each allows, the same angular velocity."""
    from rollingtop.contact import get_model

    w = np.asarray(omega, dtype=float).copy()
    directions = get_model(name).spin_directions
    if directions is None:
        return w, ""
    g = np.asarray(gamma, dtype=float)
    g = g / np.linalg.norm(g)
    dropped = []
    size = float(np.linalg.norm(w))
    for label, d in directions(g).items():
        d = np.asarray(d, dtype=float)
        part = float(w @ d) / float(d @ d)
        w = w - part * d  # always: what is left is round-off of w's size
        w = w - float(w @ d) / float(d @ d) * d  # again: round-off of what is left
        if abs(part) * float(np.linalg.norm(d)) > 1e-12 * size:
            dropped.append(label)
    note = f"omega projected onto {', '.join(dropped)}" if dropped else ""
    return w, note


@dataclass(frozen=True)
class RotationGrid:
    """Rotation numbers ``N = Delta psi / 2 pi`` of a reduced model over a grid of its axis
    integral and the reduced energy (:func:`rotation_grid`).

    Attributes
    ----------
    model, axis : str
    fixed : dict of str to float
        The level's other integrals.
    x : ndarray, shape (nx,)
    h : ndarray, shape (nh,)
    N : ndarray, shape (nh, nx, 2)
        ``N`` of the first two periodic orbits of each level (by ``gamma3``); NaN where there
        is none (below the minimum of ``U``, a refused pole level).
    """

    model: str
    axis: str
    fixed: dict[str, float]
    x: FloatArray
    h: FloatArray
    N: FloatArray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict, with ``N_range`` (``None`` without a periodic orbit)."""
        finite = self.N[np.isfinite(self.N)]
        span = None if finite.size == 0 else [float(finite.min()), float(finite.max())]
        return {
            "model": self.model,
            "axis": self.axis,
            "fixed": json_ready(self.fixed),
            "x": _plain(self.x),
            "h": _plain(self.h),
            "N": [[_plain(cell) for cell in row] for row in self.N],
            "N_range": span,
        }


def rotation_grid(
    level: Level,
    *,
    window: tuple[float, float] | None = None,
    h_range: tuple[float, float] | None = None,
    resolution: int = 41,
    progress: Callable[[int, int], None] | None = None,
) -> RotationGrid:
    """Rotation numbers of ``level``'s model over its axis integral (:data:`AXES`, ``window``
    as in :func:`critical_values`) and ``h`` (default: from the lowest critical value to
    above the highest in the window), by the quadrature of ``psi'`` over a period
    (:func:`rollingtop.reduction.rotation.rotation_number`).

    ``progress(done, total)`` after each column of the axis.
    """
    from rollingtop.reduction.rotation import rotation_number

    if not 3 <= int(resolution) <= 1000:
        raise ScenarioError(f"resolution = {resolution} must be between 3 and 1000")
    cv = critical_values(level, window=window, n=int(resolution))
    reduction = reduction_of(level.model)
    values = level.values()
    if h_range is None:
        if cv.points.size == 0:
            raise ScenarioError(
                f"no steady motion of the {level.model} model in the window: give the h range"
            )
        lo, hi = float(cv.points[:, 2].min()), float(cv.points[:, 2].max())
        h_range = (lo + 1e-6 * max(1.0, abs(lo)), hi + 0.5 * (hi - lo) + 1e-3)
    h_lo, h_hi = h_range
    if not (math.isfinite(h_lo) and math.isfinite(h_hi) and h_lo < h_hi):
        raise ScenarioError(f"h range ({h_lo:g}, {h_hi:g}) must be finite and increasing")
    h = np.linspace(h_lo, h_hi, int(resolution))
    N = np.full((h.size, cv.x.size, 2), np.nan)
    for j, xj in enumerate(cv.x):
        try:
            lv = reduction.level(level.body, {**values, cv.axis: float(xj)})
        except LevelSetError:
            continue
        for i, hi_ in enumerate(h):
            try:
                found = [o for o in orbits(lv, float(hi_)) if o.kind == "periodic"]
            except LevelSetError:
                continue  # below the minimum of U
            for k, o in enumerate(found[:2]):
                N[i, j, k] = rotation_number(lv, float(hi_), o)[0]
        if progress is not None:
            progress(j + 1, cv.x.size)
    return RotationGrid(level.model, cv.axis, cv.fixed, cv.x, h, N)
