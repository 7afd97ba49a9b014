"""Continuation of a relative periodic orbit in a body parameter or the energy (issue 38,
item 3; ``rollingtop continue``).

The orbit is a fixed point of the section map's ``K``-th iterate on a level
(:mod:`rollingtop.chaos.periodic`); as the parameter ``lam`` changes, the level's integrals are
held at the orbit's values (the energy's set to ``lam`` when ``lam`` is the energy) and the
fixed point is followed by pseudo-arclength continuation with one unfolding parameter per
integral held (:mod:`rollingtop.chaos._arclength`, which says why they are there and why they
stay 0). Along the branch: the period, the multipliers on the level (central differences of the
section map, step :data:`MAP_STEP`) and the type; the folds (a multiplier through +1), period
doublings (through -1) and Neimark-Sacker points (a complex pair through modulus 1) are located,
and at the first period doubling the branch with twice the returns is followed too.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._errors import RollingTopError, ScenarioError
from rollingtop._figures import draw
from rollingtop._html import Num, block, row_table, table
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos import _arclength as arc
from rollingtop.chaos._multipliers import UNIT_CIRCLE, classify, level_bases
from rollingtop.chaos._section_map import (
    SectionMap,
    check_model,
    free_key,
    integral_gradients,
    section_state,
)
from rollingtop.chaos.level import held_integrals, level_values
from rollingtop.chaos.periodic import PeriodicOrbit
from rollingtop.contact import ContactModel, get_model

__all__ = ["PARAMETERS", "Bifurcation", "Branch", "BranchPoint", "continue_orbit"]

#: The parameters a branch may follow: the body's (``I1`` moves ``I2`` with it: the body stays
#: dynamically symmetric) and the level's energy.
PARAMETERS = ("R", "m", "g", "a3", "I1", "I3", "energy")
#: Relative difference step of the section map (a map computed by an integration at
#: ``rtol = 1e-11``: round-off over step ``~1e-6``, truncation ``~1e-10``).
MAP_STEP = 1e-5
#: Size of the first step onto the doubled branch (along the multiplier -1's eigenvector).
SWITCH_SIZE = 1e-3
#: A branch stops where its axis comes this close to the vertical at the crossing (``|gamma3|``).
GAMMA3_LIMIT = 0.999


@dataclass(frozen=True)
class BranchPoint:
    """One orbit of a branch.

    Attributes
    ----------
    param : float
    period : float
    x : ndarray, shape (4,)
        Section coordinates ``(gamma3, w_n, w3, u)`` of the orbit's crossing.
    multipliers : ndarray of complex, shape (d,)
        On the level, largest modulus first.
    type : str
        As :attr:`rollingtop.chaos.PeriodicOrbit.type`.
    unfolding : float
        Largest ``|beta|`` of the unfolding parameters (0 in exact arithmetic).
    """

    param: float
    period: float
    x: FloatArray
    multipliers: NDArray[np.complex128]
    type: str
    unfolding: float

    def to_dict(self, model: ContactModel) -> dict[str, Any]:
        g3, w_n, w3, u = (float(v) for v in self.x)
        initial = {"gamma": [0.0, math.sqrt(1.0 - g3 * g3), g3], "omega": [0.0, -w_n, w3]}
        initial[free_key(model)] = u  # type: ignore[assignment]
        return {
            "param": self.param,
            "period": self.period,
            "initial": initial,
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "moduli": [float(abs(m)) for m in self.multipliers],
            "type": self.type,
            "unfolding": self.unfolding,
        }


@dataclass(frozen=True)
class Bifurcation:
    """A located bifurcation: ``kind`` (``fold``, ``period-doubling``, ``neimark-sacker``),
    the orbit there, the parameter values of the two branch points it lies between, and
    whether its location converged (its test function ``1e-7`` of its values at those points;
    else :attr:`point` is the one of them with the smaller value)."""

    kind: str
    point: BranchPoint
    bracket: tuple[float, float]
    converged: bool = True

    @property
    def test(self) -> float:
        """The multipliers' test function of its kind at :attr:`point`
        (:func:`rollingtop.chaos._arclength.tests`; 0 at the exact bifurcation)."""
        return arc.tests(self.point.multipliers)[self.kind]

    def to_dict(self, model: ContactModel) -> dict[str, Any]:
        return {
            "kind": self.kind,
            **self.point.to_dict(model),
            "bracket": list(self.bracket),
            "converged": self.converged,
            "test": self.test,
        }


@dataclass
class Branch:
    """A branch of relative periodic orbits (``rollingtop continue``)."""

    model: str
    param: str
    returns: int
    level: dict[str, float]
    points: list[BranchPoint] = field(default_factory=list)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    #: Why each end stopped (towards smaller and towards larger ``param``).
    stopped: tuple[str, str] = ("", "")
    #: The branch with twice the returns started at the first period doubling.
    doubled: Branch | None = None
    #: The model's own parameters (its rule at the vertical), as in
    #: :attr:`rollingtop.chaos.PeriodicOrbits.parameters`.
    parameters: dict[str, float] = field(default_factory=dict)
    #: What became of the switch onto the doubled branch ("": none was tried).
    doubling: str = ""

    @property
    def max_unfolding(self) -> float:
        """The largest unfolding parameter along the branch (and its doubled one)."""
        own = max((p.unfolding for p in self.points), default=0.0)
        return max(own, self.doubled.max_unfolding if self.doubled is not None else 0.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (``rollingtop continue --json``)."""
        model = get_model(self.model)
        return {
            "model": self.model,
            "param": self.param,
            "returns": self.returns,
            "level": dict(self.level),
            "points": [p.to_dict(model) for p in self.points],
            "bifurcations": [b.to_dict(model) for b in self.bifurcations],
            "max_unfolding": self.max_unfolding,
            "stopped": list(self.stopped),
            "doubled": self.doubled.to_dict() if self.doubled is not None else None,
            "contact_parameters": dict(self.parameters),
            "doubling": self.doubling,
        }

    def _repr_html_(self) -> str:
        rows = [
            [
                b.kind,
                Num(b.point.param, 8),
                Num(b.point.period, 8),
                ", ".join(f"{abs(m):.4g}" for m in b.point.multipliers),
            ]
            for br in (self, self.doubled)
            if br is not None
            for b in br.bifurcations
        ]
        lo = min(p.param for p in self.points)
        hi = max(p.param for p in self.points)
        return block(
            "rollingtop.chaos.Branch",
            f"{len(self.points)} orbits with {self.returns} returns of the {self.model} model, "
            f"{self.param} from {lo:.6g} to {hi:.6g}"
            + (f"; a doubled branch of {len(self.doubled.points)}" if self.doubled else ""),
            [
                ("level", row_table(self.level)),
                ("", table(["bifurcation", self.param, "period", "|multipliers|"], rows)),
            ],
        )

    def plot(self, axes: Any = None, **kw: Any) -> Any:
        """The period and the multipliers' moduli along the branch, bifurcations marked
        (:func:`rollingtop.plot.continuation.draw_branch`); ``axes``: two axes or ``None``."""
        return draw("branch", axes, self, **kw)


class _TopFamily:
    """The section map of the body with ``param = lam`` (:class:`rollingtop.chaos._arclength
    .FamilyMap`)."""

    n = 4
    fd_step = MAP_STEP

    def __init__(
        self,
        body: SphericalTop,
        model: ContactModel,
        names: tuple[str, ...],
        param: str,
        level: FloatArray,
        rtol: float,
    ) -> None:
        self.body, self.model, self.names, self.param = body, model, names, param
        self.level, self.rtol, self.m = level, rtol, len(names)
        self._maps: dict[float, SectionMap | None] = {}

    def section_map(self, lam: float) -> SectionMap | None:
        if lam not in self._maps:
            if len(self._maps) > 64:
                self._maps.clear()
            try:
                self._maps[lam] = SectionMap(
                    body_with(self.body, self.param, lam), self.model, self.names, self.rtol
                )
            except RollingTopError:  # not an admissible body
                self._maps[lam] = None
        return self._maps[lam]

    def iterate(self, X: FloatArray, lam: float, K: int) -> tuple[FloatArray, FloatArray]:
        P = self.section_map(lam)
        if P is None:
            return np.full(X.shape, np.nan), np.full(len(X), np.nan)
        try:
            out, t = P(X, K)
        except RollingTopError:
            return np.full(X.shape, np.nan), np.full(len(X), np.nan)
        return out[:, K - 1], t[:, K - 1]

    def integrals(self, X: FloatArray, lam: float) -> FloatArray:
        P = self.section_map(lam)
        if P is None:
            return np.full((len(X), self.m), np.nan)
        return P.integrals(X)

    def target(self, lam: float) -> FloatArray:
        out = self.level.copy()
        if self.param == "energy":
            out[self.names.index("energy")] = lam
        return out


class _Scaled:
    """A family in ``mu = (lam - lam0) scale``: the arclength's norm weighs the parameter by
    ``scale`` (chosen so that the branch leaves its start at 45 degrees between ``x`` and
    ``mu``: unweighted, ``x`` moved 50-80 times faster than ``a3`` and the steps crept in it).
    The parameter's difference step stays the family's own, in ``lam``."""

    def __init__(self, family: _TopFamily, lam0: float, scale: float) -> None:
        self.family, self.lam0, self.scale = family, lam0, scale
        self.n, self.m, self.fd_step = family.n, family.m, family.fd_step

    def lam(self, mu: float) -> float:
        return self.lam0 + mu / self.scale

    def lam_step(self, mu: float) -> float:
        return MAP_STEP * max(1.0, abs(self.lam(mu))) * self.scale

    def iterate(self, X: FloatArray, mu: float, K: int) -> tuple[FloatArray, FloatArray]:
        return self.family.iterate(X, self.lam(mu), K)

    def integrals(self, X: FloatArray, mu: float) -> FloatArray:
        return self.family.integrals(X, self.lam(mu))

    def target(self, mu: float) -> FloatArray:
        return self.family.target(self.lam(mu))


#: Bounds of the parameter's weight in the arclength (:class:`_Scaled`).
SCALE_RANGE = (1.0, 1e4)


def _check_range(body: SphericalTop, param: str, lo: float, hi: float) -> None:
    """``ScenarioError`` where an end of the range (with the difference step beyond it) is not
    an admissible body."""
    if param == "energy":
        return
    for value in (lo - MAP_STEP * max(1.0, abs(lo)), hi + MAP_STEP * max(1.0, abs(hi))):
        try:
            body_with(body, param, value)
        except RollingTopError as err:
            end = lo if value < lo else hi
            raise ScenarioError(
                f"the range's end {param} = {end:g} is not inside the admissible bodies ({err})"
            ) from None


def body_with(body: SphericalTop, param: str, value: float) -> SphericalTop:
    """``body`` with ``param`` set to ``value`` (``I1`` sets ``I2`` too); the energy leaves it."""
    if param == "energy":
        return body
    changes = {param: value, **({"I2": value} if param == "I1" else {})}
    return dataclasses.replace(body, **changes)


def _public(p: arc.BranchPoint, param: float) -> BranchPoint:
    return BranchPoint(
        param=param,
        period=p.period,
        x=p.x,
        multipliers=p.multipliers,
        type=classify(p.multipliers, UNIT_CIRCLE),
        unfolding=float(np.max(np.abs(p.beta), initial=0.0)),
    )


def continue_orbit(
    body: SphericalTop,
    model: str | ContactModel,
    orbit: PeriodicOrbit,
    *,
    param: str,
    bounds: tuple[float, float],
    step: float | None = None,
    max_points: int = 40,
    doubling: bool = True,
    rtol: float = 1e-11,
) -> Branch:
    """Follow ``orbit`` (found by :func:`rollingtop.chaos.periodic_orbits` on ``body``) as
    ``param`` goes over ``bounds`` (module docstring).

    Parameters
    ----------
    param : str
        One of :data:`PARAMETERS`.
    bounds : (float, float)
        The range; it holds the orbit's own value of ``param``. The branch is followed both
        ways from it until it leaves the range, turns too close to the vertical, or the
        corrector fails.
    step : float, optional
        First arclength step (default 1/20 of the range); it adapts.
    max_points : int
        Points at most each way.
    doubling : bool
        Follow the doubled branch from the first period doubling.

    Returns
    -------
    Branch
        Points in order of the arclength, from ``bounds``' first end to its second.
    """
    model = get_model(model)
    check_model(body, model)
    if param not in PARAMETERS:
        raise ScenarioError(f"param = {param!r} must be one of {', '.join(PARAMETERS)}")
    lo, hi = (float(v) for v in bounds)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ScenarioError(f"range {lo!r},{hi!r} must be two finite numbers, the first smaller")
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
        raise ScenarioError(f"max_points = {max_points!r} must be an integer >= 2")
    names = held_integrals(body, model, None)
    G = integral_gradients(SectionMap(body, model, names, rtol), orbit.x)[1]
    if not level_bases(G)[0].shape[1]:
        raise ScenarioError(
            f"the {model.name} model's level meets the section in isolated points (an integrable "
            "level): its orbits move with the integrals' values, there is no branch to follow "
            "(rollingtop orbits and bifurcation give them)"
        )
    y0 = section_state(body, model, orbit.x)
    level = level_values(body, model, y0, names)
    lam0 = float(level[names.index("energy")]) if param == "energy" else float(getattr(body, param))
    if not lo <= lam0 <= hi:
        raise ScenarioError(
            f"the range {lo:g},{hi:g} must hold the orbit's own {param} = {lam0:.6g}"
        )
    _check_range(body, param, lo, hi)
    family = _TopFamily(body, model, tuple(names), param, np.asarray(level, float), rtol)
    e = np.zeros(4 + len(names) + 1)
    e[-1] = 1.0
    u0 = np.concatenate([orbit.x, np.zeros(len(names)), [lam0]])
    plain = arc.correct(family, u0, e, orbit.returns)
    if plain is None:
        raise ScenarioError("the orbit does not solve the continuation's system at its start")
    tx, tl = float(np.linalg.norm(plain.tangent[:4])), abs(float(plain.tangent[-1]))
    scale = float(np.clip(tx / tl if tl > 0 else SCALE_RANGE[1], *SCALE_RANGE))
    scaled = _Scaled(family, lam0, scale)
    u0[-1] = 0.0
    start = arc.correct(scaled, u0, e, orbit.returns)
    if start is None:
        raise ScenarioError("the orbit does not solve the continuation's system at its start")
    ds = float(step) * scale if step is not None else (hi - lo) * scale / 20
    if not (math.isfinite(ds) and ds > 0):
        raise ScenarioError(f"step = {step!r} must be a positive number")

    def keep(p: arc.BranchPoint) -> str:
        if not abs(p.x[0]) < GAMMA3_LIMIT:
            return "the orbit's crossing reached the vertical"
        return ""

    def follow(s: arc.BranchPoint, K: int, orient: FloatArray) -> arc.RawBranch:
        return arc.continue_branch(
            scaled,
            s,
            K,
            ((lo - lam0) * scale, (hi - lam0) * scale),
            orient=orient,
            ds=ds,
            ds_max=(hi - lo) * scale / 8,
            max_points=max_points,
            keep=keep,
        )

    def public(raw: arc.RawBranch) -> tuple[list[BranchPoint], list[Bifurcation]]:
        points = [_public(p, scaled.lam(p.lam)) for p in raw.points]
        found = [
            Bifurcation(
                d.kind,
                _public(d.point, scaled.lam(d.point.lam)),
                (scaled.lam(d.bracket[0]), scaled.lam(d.bracket[1])),
                d.converged,
            )
            for d in raw.detected
        ]
        return points, found

    down = follow(start, orbit.returns, -e)
    up = follow(start, orbit.returns, e)
    down_points, down_found = public(down)
    up_points, up_found = public(up)
    out = Branch(
        model.name,
        param,
        orbit.returns,
        dict(zip(names, map(float, level), strict=True)),
        down_points[::-1] + up_points[1:],
        sorted(down_found + up_found, key=lambda b: b.point.param),
        (down.stopped, up.stopped),
    )
    out.parameters = model.parameter_values
    doublings = [
        d
        for d in sorted(down.detected + up.detected, key=lambda d: abs(d.point.lam))
        if d.kind == "period-doubling"
    ]
    if not doubling or not doublings:
        return out
    at = doublings[0]
    if not at.converged:
        out.doubling = "not tried: the period doubling's location did not converge"
        return out
    first = arc.switch_to_doubled(scaled, at.point, orbit.returns, SWITCH_SIZE)
    if first is None:
        out.doubling = (
            "failed: from the multiplier -1's eigenvector the corrector returned to the "
            f"{orbit.returns}-return branch or did not converge"
        )
        return out
    raw2 = follow(first, 2 * orbit.returns, first.u - at.point.u)
    points2, found2 = public(raw2)
    out.doubled = Branch(
        model.name, param, 2 * orbit.returns, out.level, points2, found2, ("", raw2.stopped)
    )
    out.doubled.parameters = out.parameters
    out.doubling = f"followed from {param} = {scaled.lam(at.point.lam):.8g}"
    return out
