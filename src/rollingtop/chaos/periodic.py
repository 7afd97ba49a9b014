"""Relative periodic orbits on a level set, found on the Poincare section (issue 38, item 1).

**The section map.** The section is :mod:`rollingtop.chaos.section`'s: ``w_tau = 0`` crossed
upward, the minima of ``gamma3``. For a dynamically symmetric body the motion does not see the
rotation about the vertical nor the one about the body's axis, so a crossing is fixed by its
*section coordinates* ``x = (gamma3, w_n, w3, u)``: the inclination, the angular velocity about
the horizontal axis ``n``, the spin ``w3`` and the model's free velocity component ``u`` (the
``parallel`` model's ``v_nu``, the meridian model's ``v_tau``). They are read in the geometric
basis of the axis's horizontal projection ``nu = (e3 - gamma3 gamma) / s``, ``s =
sqrt(1 - gamma3^2) > 0`` (so a carried direction's sign, which flips at a passage of the vertical,
does not enter), and a state is rebuilt from them (:func:`section_state`) with ``gamma = (0, s,
gamma3)`` in the body frame, ``w = (0, -w_n, w3)`` and the free component by
:func:`rollingtop.initial_state`. The map ``P`` takes ``x`` to the coordinates of the next
crossing; a *relative periodic orbit with K returns* is a fixed point of ``P^K``, periodic in
everything but the two symmetry angles.

**Newton's method** solves ``P^K(x) = x`` together with the level's integrals (energy and the
model's others held at the values of the scenario's state: ``I(x) = I_0``) in the least-squares
sense (Gauss-Newton), the Jacobian of ``P^K`` by central differences of the compiled flow (every
difference state of an iteration integrated in one parallel batch). On the level the map has two
*trivial* multipliers, 1 along the integrals' gradients ``G`` (``G DP = G``: ``I(P(x)) = I(x)``),
and its *multipliers* are those of ``DP`` restricted to the level's tangent plane: with ``T`` an
orthonormal basis of ``ker G`` and ``Q`` one of ``G``'s rows, ``DP`` is block triangular, the
multipliers are the eigenvalues of ``T^T DP T`` and the trivial ones those of ``Q^T DP Q``,
reported with their distance from 1 (and the block ``Q^T DP T``'s size, 0 in exact arithmetic):
the multipliers' quality figure. ``DP`` for the multipliers comes from the variational equations
(:mod:`rollingtop.chaos._variational`), checked against Newton's last differences
(``multiplier_spread``); for an orbit whose period passes through the vertical, where the flow
has no derivative (the ``parallel`` model continues by a regularised rule), from the
differences at two steps, flagged ``multipliers_from = "differences"``.

**Seeds** are the section's own iterates: trajectories sampled on the level
(:func:`rollingtop.chaos.level_states`) run ``settle`` crossings; where the last iterates of one
repeat after ``K`` returns (to ``SEED_MATCH``) Newton starts from them with ``K``. So the orbits
the trajectories settle onto are found. Then a grid of the section plane on the level
(:func:`_grid_seeds`): the grid points where ``|P^K(x) - x|`` is least among their neighbours
seed Newton too, which finds orbits no trajectory settles onto (elliptic, saddle, repelling
ones), as far as the grid resolves them. An orbit met again at another of its crossings, or as
a multiple of a shorter one, is reported once, with its least number of returns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._errors import IntegrationError, RollingTopError, ScenarioError
from rollingtop._figures import draw
from rollingtop._html import Num, block, count, row_table, table
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos._multipliers import UNIT_CIRCLE, classify, level_bases
from rollingtop.chaos._section_map import (
    SectionMap,
    check_model,
    free_key,
    grid_axes,
    integral_gradients,
    map_jacobian,
    on_level,
    section_coordinates,
    section_state,
)
from rollingtop.chaos._variational import variational_jacobian
from rollingtop.chaos.level import held_integrals, level_states, level_values
from rollingtop.chaos.section import poincare_section
from rollingtop.chaos.steady import (
    RelativeEquilibrium,
    reduced_relative_equilibria,
    relative_equilibria,
)
from rollingtop.contact import ContactModel, get_model

__all__ = [
    "PeriodicOrbit",
    "PeriodicOrbits",
    "periodic_orbits",
    "section_coordinates",
    "section_state",
]

#: Iterates of one trajectory that agree to this (max norm of the section coordinates) after
#: ``K`` returns seed Newton with ``K``.
SEED_MATCH = 1e-3
#: Newton has converged when the residual (max norm of ``P^K(x) - x`` and of the integrals'
#: mismatch) is below this; where it stalls (the flow's round-off: a few crossings and passages
#: of the vertical at ``rtol = 1e-11`` leave ~1e-9), its best iterate counts below ACCEPT_TOL.
NEWTON_TOL = 1e-10
#: See :data:`NEWTON_TOL`.
ACCEPT_TOL = 1e-8
#: A solution whose period is not above this is a start counted as its own crossing (seen with
#: the vertical rule's disk made 100 times smaller), not an orbit.
MIN_PERIOD = 1e-6
#: Newton's iterations at most.
NEWTON_ITERATIONS = 12
#: The multipliers are computed again with this step; their difference is reported
#: (``multiplier_spread``): the differences' error, large where the orbit passes close to the
#: vertical (the flow's derivative there is steep and its round-off amplified).
FD_CHECK_STEP = 1e-4
#: Two fixed points are the same orbit when a crossing of one is this close to one of the other.
SAME_ORBIT = 1e-6
#: The margin of the type (:data:`rollingtop.chaos._multipliers.UNIT_CIRCLE`), or this many
#: times the multipliers' spread (:attr:`PeriodicOrbit.multiplier_spread`),
#: or the trivial multipliers' distance from 1, where larger: the type is not decided inside
#: the differences' own error.
SPREAD_MARGIN = 3.0
#: An orbit whose axis comes within this tilt of the vertical (``sqrt(gamma1^2 + gamma2^2)``,
#: sampled along the orbit at :data:`VERTICAL_SAMPLES` points) is flagged ``through_vertical``:
#: there the ``parallel`` model continues by its regularised rule
#: (:mod:`rollingtop.contact.parallel`), a modelling choice that the orbit then depends on.
VERTICAL_DISTANCE = 1e-2
#: Samples along an orbit for :data:`VERTICAL_DISTANCE`.
VERTICAL_SAMPLES = 4001


@dataclass(frozen=True)
class PeriodicOrbit:
    """A relative periodic orbit: a fixed point of the section map's ``returns``-th iterate.

    Attributes
    ----------
    returns : int
        Crossings of the section per period (its least number).
    period : float
        Time of one period.
    x : ndarray, shape (4,)
        Section coordinates ``(gamma3, w_n, w3, u)`` of its crossing with the least ``gamma3``.
    state : ndarray, shape (18,)
        The state there (:func:`section_state`).
    points : ndarray, shape (returns, 4)
        Section coordinates of its crossings, in order from :attr:`x`.
    multipliers : ndarray of complex, shape (d,)
        The section map's multipliers on the level (module docstring), largest modulus first:
        ``d = 2`` with two independent integrals held (``parallel``), ``d = 0`` where the level
        meets the section in isolated points (the integrable meridian model: the orbit is
        ``neutral``).
    trivial : ndarray of complex, shape (4 - d,)
        ``DP``'s other eigenvalues, 1 in exact arithmetic (the integrals').
    type : str
        ``attracting``, ``repelling``, ``saddle``, ``elliptic`` or ``neutral``.
    closure : float
        ``max |P^K(x) - x|`` of the section coordinates after one period.
    min_tilt : float
        Least ``sqrt(gamma1^2 + gamma2^2)`` along the orbit (sampled).
    multiplier_spread : float
        Largest difference between the multipliers and a second estimate: the central
        differences of the flow (step :data:`FD_STEP`) for variational multipliers, the
        differences at step :data:`FD_CHECK_STEP` for multipliers from differences (large near
        the vertical).
    multipliers_from : str
        ``variational`` (the variational equations over one period,
        :mod:`rollingtop.chaos._variational`) or ``differences`` (central differences of the
        section map at step :data:`FD_STEP`: the period passes through the vertical, where the
        flow has no derivative; they depend on the model's rule there).
    """

    returns: int
    period: float
    x: FloatArray
    state: FloatArray
    points: FloatArray
    multipliers: NDArray[np.complex128]
    trivial: NDArray[np.complex128]
    type: str
    closure: float
    min_tilt: float
    multiplier_spread: float = 0.0
    multipliers_from: str = "variational"

    @property
    def through_vertical(self) -> bool:
        """Whether the axis passes within :data:`VERTICAL_DISTANCE` of the vertical."""
        return self.min_tilt < VERTICAL_DISTANCE

    def initial_table(self, model: str | ContactModel) -> dict[str, Any]:
        """A scenario's ``[initial]`` table that starts on this orbit (``gamma``, ``omega`` and
        the model's free velocity key)."""
        model = get_model(model)
        g3, w_n, w3, u = (float(v) for v in self.x)
        table: dict[str, Any] = {
            "gamma": [0.0, math.sqrt(1.0 - g3 * g3), g3],
            "omega": [0.0, -w_n, w3],
        }
        table[free_key(model)] = u
        return table

    def to_dict(self, model: str | ContactModel) -> dict[str, Any]:
        """JSON-ready (``rollingtop periodic --json``)."""
        return {
            "returns": self.returns,
            "period": self.period,
            "initial": self.initial_table(model),
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "trivial_multipliers_off_one": float(np.max(np.abs(self.trivial - 1.0))),
            "multiplier_spread": (
                self.multiplier_spread if math.isfinite(self.multiplier_spread) else None
            ),
            "multipliers_from": self.multipliers_from,
            "type": self.type,
            "through_vertical": self.through_vertical,
            "min_tilt": self.min_tilt,
            "closure": self.closure,
            "section": [float(v) for v in self.x[:2]],
        }


@dataclass
class PeriodicOrbits:
    """The orbits found on one level: a list of :class:`PeriodicOrbit` with the level."""

    model: str
    level: dict[str, float]
    orbits: list[PeriodicOrbit] = field(default_factory=list)
    seeds: int = 0
    #: The model's own parameters (its rule at the vertical: ``parallel``'s ``pole_disk``,
    #: ``relax``, ``pass_relax``), which an orbit ``through_vertical`` depends on.
    parameters: dict[str, float] = field(default_factory=dict)
    #: The relative equilibria on the level (:func:`rollingtop.chaos.steady.relative_equilibria`;
    #: a model with a reduction: its closed-form steady motions at the level's energy,
    #: :func:`~rollingtop.chaos.steady.reduced_relative_equilibria`; generically none, since the
    #: energy of a level taken at random is not a critical value).
    steady: list[RelativeEquilibrium] = field(default_factory=list)
    #: The seeding trajectories' crossings, ``(gamma3, w_n)``, shape (trajectories, settle, 2).
    iterates: FloatArray = field(default_factory=lambda: np.empty((0, 0, 2)))

    def __len__(self) -> int:
        return len(self.orbits)

    def __iter__(self) -> Any:
        return iter(self.orbits)

    def __getitem__(self, k: int) -> PeriodicOrbit:
        return self.orbits[k]

    def _repr_html_(self) -> str:
        """The level, then a row per orbit (returns, period, type, multipliers' moduli,
        closure, through the vertical)."""
        header = [
            "returns",
            "period",
            "type",
            "|mu_1|",
            "|mu_2|",
            "spread",
            "gamma3",
            "w_n",
            "closure",
            "through the vertical",
        ]
        rows = []
        for o in self.orbits:
            mods = [abs(m) for m in o.multipliers] + [None] * (2 - len(o.multipliers))
            rows.append(
                [
                    o.returns,
                    Num(o.period, 10),
                    o.type,
                    Num(mods[0], 4),
                    Num(mods[1], 4),
                    Num(o.multiplier_spread, 1),
                    Num(o.x[0], 6),
                    Num(o.x[1], 6),
                    Num(o.closure, 1),
                    o.through_vertical,
                ]
            )
        return block(
            "rollingtop.chaos.PeriodicOrbits",
            f"{count(len(self.orbits), 'periodic orbit')} and "
            f"{count(len(self.steady), 'relative equilibrium', 'relative equilibria')} of the "
            f"{self.model} model on its level ({self.seeds} seeds)",
            [("level", row_table(self.level)), ("", table(header, rows) if rows else "")],
        )

    def plot(self, ax: Any = None, **kw: Any) -> Any:
        """Draw the seeding trajectories' crossings and the orbits on the section plane
        ``(gamma3, w_n)`` on ``ax`` (default: a new figure's) and return ``ax``
        (:func:`rollingtop.plot.periodic.draw_periodic`, ``rollingtop periodic -o``'s figure)."""
        return draw("periodic", ax, self, **kw)

    def to_dict(self) -> dict[str, Any]:
        """``{"model", "level", "orbits", "steady", "seeds", "contact_parameters"}``
        (``rollingtop periodic --json``)."""
        return {
            "model": self.model,
            "level": dict(self.level),
            "orbits": [o.to_dict(self.model) for o in self.orbits],
            "steady": [e.to_dict(free_key(get_model(self.model))) for e in self.steady],
            "seeds": self.seeds,
            "contact_parameters": dict(self.parameters),
        }


def _newton(
    P: SectionMap, x0: FloatArray, K: int, target: FloatArray
) -> tuple[FloatArray, FloatArray, float] | None:
    """Gauss-Newton on ``P^K(x) = x``, ``I(x) = target``; ``(x, DP^K, period)`` or None."""
    x = x0.copy()
    best: tuple[float, FloatArray, FloatArray, float] | None = None
    for _ in range(NEWTON_ITERATIONS):
        try:
            F, J, period = map_jacobian(P, x, K)
            values, G = integral_gradients(P, x)
        except RollingTopError:
            break
        if not (np.all(np.isfinite(F)) and np.all(np.isfinite(J))):
            break
        res = np.concatenate([F - x, values - target])
        size = float(np.max(np.abs(res)))
        if best is None or size < best[0]:
            best = (size, x, J, period)
        if size < NEWTON_TOL:
            break
        A = np.vstack([J - np.eye(4), G])
        x = x + np.linalg.lstsq(A, -res, rcond=1e-12)[0]
        if not abs(x[0]) < 1.0:
            break
    if best is None or best[0] >= ACCEPT_TOL:
        return None
    return best[1], best[2], best[3]


def _seeds(iterates: FloatArray, returns: int) -> list[tuple[FloatArray, int]]:
    """Per trajectory (iterates (n, N, 4)), the least ``K <= returns`` after which its last
    iterates repeat, and the iterate with the least ``gamma3`` among its last ``K``."""
    out = []
    for traj in iterates:
        bad = np.flatnonzero(~np.all(np.isfinite(traj), axis=-1))
        traj = traj[: bad[0]] if bad.size else traj  # up to its first undefined crossing
        last = traj[-1] if len(traj) else None
        for K in range(1, returns + 1):
            if last is None or traj.shape[0] < 2 * K + 1:
                break
            if np.max(np.abs(traj[-1 - K] - last)) < SEED_MATCH:
                cycle = traj[-K:]
                out.append((cycle[int(np.argmin(cycle[:, 0]))], K))
                break
    return out


def _grid_seeds(
    P: SectionMap, target: FloatArray, iterates: FloatArray, returns: int, n: int
) -> list[tuple[FloatArray, int]]:
    """Seeds from an ``n`` x ``n`` grid of the section plane over the range of the iterates
    (each grid point on each sheet of the level, :func:`on_level`): for each ``K``, the points
    whose ``|P^K(x) - x|`` is least among their grid neighbours and below the grid's spacing
    (a fixed point of ``P^K`` nearby, whatever its stability)."""
    if len(P.names) != 2 or "energy" not in P.names:
        return []
    axes = grid_axes(iterates, n)
    if axes is None:
        return []
    g3s, wns = axes
    spacing = max(g3s[1] - g3s[0], wns[1] - wns[0]) if n > 1 else 1.0
    cells: list[tuple[int, int, int, FloatArray]] = []
    for i, g3 in enumerate(g3s):
        for j, w_n in enumerate(wns):
            for sheet, x in enumerate(on_level(P, target, float(g3), float(w_n))):
                cells.append((i, j, sheet, x))
    if not cells:
        return []
    X = np.array([c[3] for c in cells])
    try:
        out, _ = P(X, returns)
    except RollingTopError:
        return []
    seeds = []
    for K in range(1, returns + 1):
        res = np.max(np.abs(out[:, K - 1, :2] - X[:, :2]), axis=-1)
        res = np.where(np.isfinite(res), res, np.inf)
        by_cell = {(i, j, sheet): r for (i, j, sheet, _), r in zip(cells, res, strict=True)}
        for k, (i, j, sheet, x) in enumerate(cells):
            r = res[k]
            around = [
                by_cell.get((i + a, j + b, sheet), np.inf)
                for a in (-1, 0, 1)
                for b in (-1, 0, 1)
                if a or b
            ]
            if r < spacing and r <= min(around):
                seeds.append((x, K))
    return seeds


def _same(a: PeriodicOrbit, points: FloatArray) -> bool:
    """Whether a crossing of ``a`` is one of ``points`` (section coordinates, (n, 4))."""
    gaps = np.max(np.abs(a.points[:, None, :] - points[None, :, :]), axis=-1)
    return bool(np.min(gaps) < SAME_ORBIT)


def periodic_orbits(
    body: SphericalTop,
    model: str | ContactModel,
    state: ArrayLike,
    *,
    returns: int = 4,
    trajectories: int = 16,
    settle: int = 300,
    seed: int | None = 0,
    grid: int = 12,
    rtol: float = 1e-11,
) -> PeriodicOrbits:
    """The relative periodic orbits on the level of ``state`` that the section's trajectories
    settle onto, with 1 to ``returns`` crossings per period (module docstring).

    Parameters
    ----------
    body : SphericalTop
        Dynamically symmetric.
    model : str or ContactModel
        A model whose section state is fixed by ``(gamma3, w_n, w3)`` and at most one free
        velocity component (``meridian``, ``parallel``).
    state : array_like, shape (18,)
        A state of the level (its energy and the model's other integrals are held).
    returns : int
        Largest number of crossings per period sought (1 to 12).
    trajectories, settle, seed :
        The seeds: ``trajectories`` states sampled on the level (``seed``), each run
        ``settle`` crossings.
    grid : int
        Also seed from a ``grid`` x ``grid`` grid of the section plane on the level
        (:func:`_grid_seeds`: for orbits no trajectory settles onto, repelling and saddle
        ones); 0: none. Only on a level of the energy and one integral linear in the velocity
        (``parallel``).
    rtol : float
        Tolerance of every integration (``atol = rtol / 100``).

    Returns
    -------
    PeriodicOrbits
        In order of ``returns``, then of ``gamma3``.
    """
    model = get_model(model)
    check_model(body, model)
    if isinstance(returns, bool) or not isinstance(returns, int) or not 1 <= returns <= 12:
        raise ScenarioError(f"returns = {returns!r} must be an integer from 1 to 12")
    for name, value, lo in (
        ("trajectories", trajectories, 1),
        ("settle", settle, 2 * returns + 1),
        ("grid", grid, 0),
    ):
        if isinstance(value, bool) or not isinstance(value, int) or value < lo:
            raise ScenarioError(f"{name} = {value!r} must be an integer >= {lo}")
    y0 = np.asarray(state, dtype=float)
    names = held_integrals(body, model, None)
    target = level_values(body, model, y0, names)
    P = SectionMap(body, model, names, rtol)
    starts = level_states(body, model, y0, trajectories, seed=seed)
    ds = poincare_section(body, model, starts, crossings=settle, rtol=rtol, atol=rtol * 1e-2)
    iterates = section_coordinates(model, ds["crossing_state"].values)
    found = PeriodicOrbits(model.name, dict(zip(names, map(float, target), strict=True)))
    found.parameters = model.parameter_values
    found.iterates = iterates[..., :2]
    candidates = _seeds(iterates, returns)
    if grid:
        candidates += _grid_seeds(P, target, iterates, returns, grid)
    found.seeds = len(candidates)
    reduced = reduced_relative_equilibria(P, y0)
    axes = grid_axes(iterates, grid)
    if reduced is not None:
        found.steady = reduced
    elif axes is not None:
        found.steady = relative_equilibria(P, target, *axes)
    for x0, K in sorted(candidates, key=lambda c: c[1]):
        near = [o for o in found.orbits if K % o.returns == 0]
        if any(np.min(np.max(np.abs(o.points - x0), axis=-1)) < SEED_MATCH for o in near):
            continue  # a seed of an orbit found already
        orbit = _solve(P, x0, K, target)
        if orbit is None or any(_same(o, orbit.points) for o in found.orbits):
            continue
        found.orbits.append(orbit)
    found.orbits.sort(key=lambda o: (o.returns, float(o.x[0])))
    return found


def _solve(P: SectionMap, x0: FloatArray, K: int, target: FloatArray) -> PeriodicOrbit | None:
    """The orbit Newton finds from ``x0`` with ``K`` returns, with its least number of returns
    (a solution that recurs after ``d < K`` crossings is solved again with ``d``); ``None``
    where Newton fails or the orbit cannot be measured."""
    solved = _newton(P, x0, K, target)
    if solved is None:
        return None
    x, DP, period = solved
    if not (math.isfinite(period) and period > MIN_PERIOD):  # a crossing at the start itself
        return None
    try:
        pts, _ = P(x[None, :], K)
    except RollingTopError:
        return None
    points = np.vstack([x, pts[0, : K - 1]])
    if K > 1:
        gaps = np.max(np.abs(points[1:] - x), axis=-1)
        recur = np.flatnonzero(gaps < SAME_ORBIT)
        if recur.size:  # a shorter orbit: solved with its own number of returns
            return _solve(P, x, int(recur[0]) + 1, target)
    try:
        closure = float(np.max(np.abs(pts[0, K - 1] - x)))  # P^K(x) - x, from the same run
        return _orbit(P, x, DP, K, period, points, closure)
    except (RollingTopError, np.linalg.LinAlgError):
        return None


def _orbit(
    P: SectionMap,
    x: FloatArray,
    DP: FloatArray,
    K: int,
    period: float,
    points: FloatArray,
    closure: float,
) -> PeriodicOrbit:
    """The orbit through ``x``, its multipliers from the variational equations
    (:func:`~rollingtop.chaos._variational.variational_jacobian`), checked against ``DP``, the
    central differences Newton ended with; from the differences (at two steps) where one period
    passes through the vertical, where the flow has no derivative."""
    k = int(np.argmin(points[:, 0]))
    # G DP = G makes DP block triangular in (T, Q): the multipliers on the level are T^T DP T's
    # eigenvalues, the trivial ones Q^T DP Q's
    T, Q = level_bases(integral_gradients(P, x)[1])

    def on_level(D: FloatArray) -> NDArray[np.complex128]:
        mu = np.linalg.eigvals(T.T @ D @ T).astype(np.complex128)
        return mu[np.lexsort((mu.imag, -np.abs(mu)))]

    try:
        D = variational_jacobian(P, x, period, stop_at_vertical=True)
        source = "variational"
    except IntegrationError:  # ThroughVertical (the flow has no derivative there), or the
        D, source = DP, "differences"  # variational run failed: the map's difference quotients
    mu = on_level(D)
    trivial = np.linalg.eigvals(Q.T @ D @ Q).astype(np.complex128)
    # the trivial multipliers' distance from 1 and the leak of the level's tangent plane into
    # the gradients' directions (0 in exact arithmetic): the multipliers' own quality figure
    off_one = float(np.max(np.abs(trivial - 1.0))) if trivial.size else 0.0
    off_one = max(off_one, float(np.max(np.abs(Q.T @ D @ T), initial=0.0)))
    spread = 0.0
    if mu.size:
        # the other estimate: the differences Newton ended with (variational multipliers), or
        # the differences at a second step (multipliers from the differences)
        check = DP if source == "variational" else map_jacobian(P, x, K, FD_CHECK_STEP)[1]
        # a difference state that stopped (NaN): the spread is unknown
        good = bool(np.all(np.isfinite(check)))
        spread = float(np.max(np.abs(mu - on_level(check)))) if good else math.inf
    # the type is decided outside the multipliers' error: the trivial ones' distance from 1,
    # and, for multipliers from differences, their change with the step
    margin = max(UNIT_CIRCLE, SPREAD_MARGIN * off_one)
    if source == "differences":
        margin = max(margin, SPREAD_MARGIN * spread)
    return PeriodicOrbit(
        returns=K,
        period=period,
        x=points[k],
        state=section_state(P.body, P.model, points[k]),
        points=np.roll(points, -k, axis=0),
        multipliers=mu.astype(np.complex128),
        trivial=trivial,
        type=classify(mu, margin),
        closure=closure,
        min_tilt=_min_tilt(P, x, period),
        multiplier_spread=spread,
        multipliers_from=source,
    )


def _min_tilt(P: SectionMap, x: FloatArray, period: float) -> float:
    """Least ``sqrt(gamma1^2 + gamma2^2)`` along one period from ``x`` (sampled); 0 (counted
    as through the vertical) where the integration fails."""
    from rollingtop.integrate.driver import integrate

    y0 = section_state(P.body, P.model, x)
    code = P.model.kernel_code(P.body, y0)
    t = np.linspace(0.0, period, VERTICAL_SAMPLES)
    try:
        res = integrate(code, P.model.params(P.body), y0, t, rtol=P.rtol, atol=P.rtol * 1e-2)
    except RollingTopError:
        return 0.0
    return float(np.min(np.hypot(res.y[:, 12], res.y[:, 13])))
