"""What the explore page shows, computed without Panel: the state of the page (model, body,
level, energy), its URL query, and the arrays of its plots (:mod:`rollingtop.explore.app`
draws them; a trajectory started by a click is :mod:`.path`'s, a section :mod:`.section`'s).
Every computation here is a function of an :class:`ExploreState`, so the page and the tests
see the same numbers as the command line (``rollingtop equilibria``, ``portrait``,
``bifurcation``, ``simulate`` from a ``[level]``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from rollingtop._errors import RollingTopError, ScenarioError, short_repr
from rollingtop._layout import GAMMA, W
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.contact import MODELS, get_model
from rollingtop.scenario import Scenario

__all__ = [
    "BODY_KEYS",
    "CONTACT_KEYS",
    "ExploreState",
    "LevelView",
    "DiagramView",
    "PAPER_FIG5",
    "default_scenario",
    "state_from_scenario",
    "parse_query",
    "level_view",
    "diagram_view",
    "cached_level_view",
    "cached_diagram_view",
]

#: The body's parameters on the page (sliders), in order.
BODY_KEYS = ("R", "m", "a3", "I1", "I3", "g")
#: Reduced energy's key in the URL.
H_KEY = "h"
#: The contact models' parameters the page offers as sliders (where the model has them): the
#: oblique family's constraint angle (rollingtop.contact.oblique).
CONTACT_KEYS = ("angle",)


def _contact_defaults(name: str) -> tuple[tuple[str, float], ...]:
    """The registered values of the model ``name``'s parameters among :data:`CONTACT_KEYS`."""
    return tuple((r.name, r.default) for r in get_model(name).parameters if r.name in CONTACT_KEYS)


@dataclass(frozen=True)
class ExploreState:
    """One view of the page: a model, a body, the model's level and the reduced energy ``h``.

    ``start`` is the reference state's ``(gamma, omega)`` (body frame): the scenario's initial
    state, or its start on the level; a model chosen on the page takes its level from it.
    ``level`` is empty for a model without a reduction (the page then shows a Poincare section
    of the reference state's level). ``contact`` holds the model's parameters among
    :data:`CONTACT_KEYS` (the oblique model's ``angle``), as ``(name, value)`` pairs.
    """

    model: str
    body: SphericalTop
    level: dict[str, float]
    h: float
    start: tuple[tuple[float, float, float], tuple[float, float, float]]
    #: The scenario's own model, body and full state (its free velocity components included):
    #: used as it is while the page shows that model and body.
    own: tuple[str, SphericalTop, tuple[float, ...]] | None = None
    contact: tuple[tuple[str, float], ...] = ()
    #: The scenario's own values of :attr:`contact` (its state is used as it is only with them).
    own_contact: tuple[tuple[str, float], ...] = ()
    #: The scenario's model's other parameters (the passage rule's ``pole_disk``, ...), kept
    #: while the page shows that model.
    own_rule: tuple[tuple[str, float], ...] = ()

    @property
    def contact_model(self) -> Any:
        """The :class:`~rollingtop.contact.ContactModel` of this view: the model with the
        values of :attr:`contact` (and, for the scenario's own model, its other parameters)."""
        model = get_model(self.model)
        values = dict(self.contact)
        if self.own is not None and self.own[0] == self.model:
            values = dict(self.own_rule) | values
        return model.with_parameters(**values) if values else model

    def reference_state(self) -> FloatArray:
        """The full state of the reference state under this view's model and body: the
        scenario's own where they are its own, else built from :attr:`start`
        (:func:`rollingtop.initial_state`, the free velocity components 0, rubber's ``omega``
        projected as ``compare-classification`` does)."""
        if (
            self.own is not None
            and self.own[:2] == (self.model, self.body)
            and self.contact == self.own_contact
        ):
            return np.array(self.own[2], dtype=float)
        from rollingtop.dynamics.state import initial_state
        from rollingtop.reduction.classify import admissible_omega

        gamma, omega = self.start
        w, _ = admissible_omega(self.model, gamma, omega)
        y: FloatArray = initial_state(self.body, self.contact_model, gamma=gamma, omega=w)
        return y

    def __hash__(self) -> int:
        """Equal views hash alike (the level's order does not matter, as in ``==``): the page
        caches its views on the state (:func:`cached_level_view`)."""
        level = tuple(sorted(self.level.items()))
        return hash((self.model, self.body, level, self.h, self.start, self.own, self.contact))

    @property
    def reduces(self) -> bool:
        """Whether the model reduces to one degree of freedom (a level and ``h``)."""
        from rollingtop.reduction.models import REDUCTIONS

        return self.model in REDUCTIONS

    def level_set(self) -> Any:
        """The :class:`~rollingtop.reduction.LevelSet` of :attr:`level`."""
        from rollingtop.reduction.models import reduction_of

        return reduction_of(self.model).level(self.body, self.level)

    def to_query(self) -> dict[str, str]:
        """The URL's query parameters: model, body, level and ``h`` (``repr`` of each float: a
        loaded URL restores the same doubles)."""
        query = {"model": self.model}
        query |= {k: repr(float(getattr(self.body, k))) for k in BODY_KEYS}
        query |= {k: repr(float(v)) for k, v in self.contact}
        query |= {k: repr(float(v)) for k, v in self.level.items()}
        if self.reduces:
            query[H_KEY] = repr(float(self.h))
        return query

    def with_model(self, name: str) -> ExploreState:
        """The same body and reference state under the model ``name``: its level and ``h`` read
        off the reference state built under that model (:func:`rollingtop.initial_state`,
        rubber's ``omega`` projected as ``compare-classification`` does)."""
        from rollingtop.reduction.models import REDUCTIONS

        model = get_model(name)
        own = self.own is not None and self.own[0] == model.name
        contact = self.own_contact if own else _contact_defaults(model.name)
        if model.name not in REDUCTIONS:
            return replace(self, model=model.name, level={}, h=math.nan, contact=contact)
        from rollingtop.reduction.models import reduction_of

        y = replace(self, model=model.name, contact=contact).reference_state()
        reduction = reduction_of(model.name)
        level = reduction.level_of_state(self.body, y)
        values = {k: float(v) for k, v in level.values().items()}
        return replace(
            self,
            model=model.name,
            level=values,
            h=float(reduction.reduced_energy(self.body, y)),
            contact=contact,
        )


#: The page without a scenario: the paper's body on the level of its Fig. 5 (``M3 = 1, C1 =
#: 0.5, C2 = -2``, ``h = 4``), as ``examples/fig5.toml``.
PAPER_FIG5: dict[str, Any] = {
    "body": {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5},
    "contact": {"model": "meridian"},
    "level": {"M3": 1.0, "C1": 0.5, "C2": -2.0, "h": 4.0},
}


def default_scenario() -> Scenario:
    """The scenario of :data:`PAPER_FIG5`."""
    return Scenario.from_dict(PAPER_FIG5, source="the paper's Fig. 5")


def state_from_scenario(sc: Scenario) -> ExploreState:
    """The page's first view: the scenario's model, body, level (its ``[level]``, else its
    initial state's) and ``h``."""
    body = sc.body
    if sc.initial is not None:
        y = sc.require_state()
    elif sc.model.reduction:
        from rollingtop.reduction.start import start_on_level

        y = start_on_level(sc.level_set(), sc.level_h())
    else:
        raise ScenarioError("explore needs an [initial] state for a model without a reduction")
    gamma = tuple(float(v) for v in y[GAMMA])
    omega = tuple(float(v) for v in y[W])
    start = (gamma, omega)
    own = (sc.model.name, body, tuple(float(v) for v in y))
    contact = tuple(
        (k, float(v)) for k, v in sc.model.parameter_values.items() if k in CONTACT_KEYS
    )
    rule = tuple(
        (k, float(v)) for k, v in sc.model.parameter_values.items() if k not in CONTACT_KEYS
    )
    if not sc.model.reduction:
        return ExploreState(
            sc.model.name,
            body,
            {},
            math.nan,
            start,  # type: ignore[arg-type]
            own,
            contact,
            contact,
            rule,
        )
    level = sc.level_set()
    values = {k: float(v) for k, v in level.values().items()}
    return ExploreState(
        sc.model.name,
        body,
        values,
        float(sc.level_h()),
        start,  # type: ignore[arg-type]
        own,
        contact,
        contact,
        rule,
    )


def parse_query(query: Mapping[str, Any], base: ExploreState) -> ExploreState:
    """The view a URL asks for, from ``base`` (the page's current view): ``model`` first (its
    level read off the reference state), then the body's and the level's numbers.

    Raises
    ------
    ScenarioError
        One line naming the parameter: an unknown key, a value that is not a finite number, a
        body the model refuses.
    """
    flat = dict(query)
    state = base
    if "model" in flat and flat["model"] != base.model:
        name = flat["model"]
        if name not in MODELS:
            raise ScenarioError(f"model = {name!r} is not a contact model ({', '.join(MODELS)})")
        state = base.with_model(name)
    allowed = (
        "model",
        *BODY_KEYS,
        *dict(state.contact),
        *state.level,
        *((H_KEY,) if state.reduces else ()),
    )
    numbers: dict[str, float] = {}
    for key, text in flat.items():
        if key == "model":
            continue
        if key not in allowed:
            raise ScenarioError(
                f"unknown parameter {key!r} for the {state.model} model "
                f"(allowed: {', '.join(allowed)})"
            )
        if isinstance(text, bool | list | dict | tuple):  # Panel reads JSON and true/false
            raise ScenarioError(f"{key} = {short_repr(text)} is not a number")
        try:
            value = float(text)
        except OverflowError:  # an integer beyond double precision (Panel reads digits as int)
            raise ScenarioError(f"{key} = {short_repr(text)} is beyond double precision") from None
        except (TypeError, ValueError):
            raise ScenarioError(f"{key} = {short_repr(text)} is not a number") from None
        if not math.isfinite(value):
            raise ScenarioError(f"{key} = {short_repr(text)} must be finite")
        numbers[key] = value
    body_changes = {k: v for k, v in numbers.items() if k in BODY_KEYS}
    if body_changes:
        changes = dict(body_changes)
        if "I1" in changes and state.body.I2 == state.body.I1:
            changes["I2"] = changes["I1"]  # the page's bodies are symmetric
        try:
            body = replace(state.body, **changes)
        except RollingTopError as err:
            raise ScenarioError(f"body: {err}") from None
        state = replace(state, body=body)
    contact = tuple((k, numbers.get(k, v)) for k, v in state.contact)
    if contact != state.contact:
        try:
            get_model(state.model).with_parameters(**dict(contact))
        except RollingTopError as err:
            raise ScenarioError(f"contact: {err}") from None
        state = replace(state, contact=contact)
    level = {k: numbers.get(k, v) for k, v in state.level.items()}
    h = numbers.get(H_KEY, state.h)
    state = replace(state, level=level, h=h)
    if state.reduces:
        try:
            state.level_set()
        except RollingTopError as err:
            raise ScenarioError(f"level: {err}") from None
    return state


# ---- the reduced system's plots ------------------------------------------------------------


@dataclass(frozen=True)
class LevelView:
    """What the level's plots and readout show (:func:`level_view`).

    ``U_x, U_y``: the effective potential over ``gamma3`` (shape ``(n,)``); ``curves``: the
    portrait's orbits as ``(x, w_tau)`` arrays, NaN-separated, one pair for the background
    energies and one for the current ``h``; ``steady``: the steady motions' ``(gamma3, U,
    type)``; ``readout``: the line above the plots (it ends in ``steady motions: N``).
    """

    readout: str
    count: int
    U_x: FloatArray
    U_y: FloatArray
    background: tuple[FloatArray, FloatArray]
    current: tuple[FloatArray, FloatArray]
    steady: list[tuple[float, float, str]]
    x_label: str
    note: str = field(default="")


def joined(curves: list[tuple[FloatArray, FloatArray]]) -> tuple[FloatArray, FloatArray]:
    """Curves joined into one pair of arrays, separated by NaN (one Bokeh line)."""
    if not curves:
        return np.array([]), np.array([])
    xs = np.concatenate([np.append(x, np.nan) for x, _ in curves])
    ys = np.concatenate([np.append(y, np.nan) for _, y in curves])
    return xs, ys


def orbit_curves(level: Any, h: float) -> list[tuple[FloatArray, FloatArray]]:
    """The closed curves of the orbits of ``(level, h)`` in ``(gamma3, w_tau)``: the portrait's
    own (:func:`rollingtop.reduction.curves.level_curves`, 200 points a branch); none below
    ``min U``."""
    from rollingtop.reduction.curves import level_curves

    return level_curves(level, h, n=200)


def level_view(state: ExploreState) -> LevelView:
    """The readout, ``U(gamma3)``, the phase portrait and the steady motions of ``state``.

    The steady motions are :func:`rollingtop.reduction.steady_motions` of the level: the count
    ``rollingtop equilibria`` prints. The background orbits are at the portrait's energies
    (:func:`rollingtop.reduction.curves.default_h_levels`), the current one at ``h``.
    """
    from rollingtop.reduction import LevelSetError, steady_motions
    from rollingtop.reduction.curves import default_h_levels

    level = state.level_set()
    steady = steady_motions(level)
    pole = level.pole is not None
    lo, hi = level.theta_domain
    theta = np.linspace(lo, hi, 801)[1:-1]
    with np.errstate(all="ignore"):
        U = np.asarray(level.U(theta), dtype=float)
    x = theta if pole else np.cos(theta)
    try:
        energies = default_h_levels(level, count=8) if steady else []
    except LevelSetError:
        energies = []
    back = [c for e in energies for c in orbit_curves(level, e)]
    current = orbit_curves(level, state.h)
    note = "" if current else f"no motion at h = {state.h:.6g}: h is below the minimum of U"
    values = ", ".join(f"{k} = {v:.6g}" for k, v in state.level.items())
    readout = f"{state.model} model: {values}, h = {state.h:.6g} | steady motions: {len(steady)}"
    motions = [(float(m.theta if pole else m.gamma3), float(m.U), m.type) for m in steady]
    return LevelView(
        readout,
        len(steady),
        x,
        U,
        joined(back),
        joined(current),
        motions,
        "theta" if pole else "gamma3",
        note,
    )


@dataclass(frozen=True)
class DiagramView:
    """The bifurcation diagram's curves (:func:`diagram_view`): the critical values as points
    ``(axis value, h)`` split into centres and saddles, the lower bound ``min U`` for the paper's
    model, the folds, and the current level's point."""

    axis: str
    centres: tuple[FloatArray, FloatArray]
    saddles: tuple[FloatArray, FloatArray]
    folds: tuple[FloatArray, FloatArray]
    floor: tuple[FloatArray, FloatArray]
    mark: tuple[float, float]
    x_range: tuple[float, float]
    y_range: tuple[float, float]


def diagram_view(state: ExploreState) -> DiagramView:
    """The bifurcation diagram of ``state``'s level: for the paper's model the curves of
    critical values in ``(C2, h)`` at its ``(M3, C1)``
    (:func:`rollingtop.reduction.bifurcation.bifurcation_diagram`, the window widened to take
    the current ``C2``); for another reduced model its critical values along its axis integral
    (:func:`rollingtop.reduction.classify.critical_values`)."""
    from rollingtop.reduction.classify import AXES, critical_values

    level = state.level_set()
    axis = AXES[state.model]
    x0 = float(state.level[axis])
    from rollingtop.reduction.models import closed_form_diagram

    if closed_form_diagram(state.model):  # the paper's whole reduction: its (C2, h) plane
        from rollingtop.reduction.bifurcation import bifurcation_diagram

        d = bifurcation_diagram(state.body, level.M3, level.C1, resolution=(161, 3))
        lo, hi = float(d.C2_grid[0]), float(d.C2_grid[-1])
        if not lo <= x0 <= hi:  # widened to take the current C2
            pad = 0.1 * (max(hi, x0) - min(lo, x0))
            d = bifurcation_diagram(
                state.body,
                level.M3,
                level.C1,
                resolution=(161, 3),
                C2_range=(min(lo, x0) - pad, max(hi, x0) + pad),
            )
        cx, cy, sx, sy = [], [], [], []
        for br in d.branches:
            cx.append(np.where(br.centre, br.C2, np.nan))
            cy.append(br.h)
            sx.append(np.where(br.centre, np.nan, br.C2))
            sy.append(br.h)
        centres = joined(list(zip(cx, cy, strict=True)))
        saddles = joined(list(zip(sx, sy, strict=True)))
        folds = (np.array([f.C2 for f in d.folds]), np.array([f.h for f in d.folds]))
        floor = (np.asarray(d.C2_grid, dtype=float), np.asarray(d.min_U, dtype=float))
        x_range = (float(d.C2_grid[0]), float(d.C2_grid[-1]))
        y_range = (min(float(d.h_grid[0]), state.h), max(float(d.h_grid[-1]), state.h))
        return DiagramView(
            axis, centres, saddles, folds, floor, (x0, state.h), x_range, _padded(y_range)
        )
    cv = critical_values(level, window=(x0 - max(1.0, abs(x0)), x0 + max(1.0, abs(x0))), n=161)
    pts = cv.points
    centre = pts[:, 3] > 0
    saddle = pts[:, 3] < 0
    empty = (np.array([]), np.array([]))
    hs = np.append(pts[:, 2], state.h)
    y_range = (float(np.min(hs)), float(np.max(hs)))
    return DiagramView(
        axis,
        (pts[centre, 0], pts[centre, 2]),
        (pts[saddle, 0], pts[saddle, 2]),
        empty,
        empty,
        (x0, state.h),
        (float(cv.x[0]), float(cv.x[-1])),
        _padded(y_range),
    )


def _padded(lim: tuple[float, float]) -> tuple[float, float]:
    """``lim`` widened by 5 % on each side (by 1 if it is a point)."""
    pad = 0.05 * (lim[1] - lim[0]) or 1.0
    return lim[0] - pad, lim[1] + pad


#: Views kept per server (every session of one scenario opens on the same state, and a slider
#: moved back returns to one): about 100 KB each.
VIEW_CACHE_SIZE = 64


def _frozen(view: Any) -> Any:
    """``view`` with its arrays read-only: a cached view is shared by every session."""
    for value in vars(view).values():
        for a in value if isinstance(value, tuple) else (value,):
            if isinstance(a, np.ndarray):
                a.flags.writeable = False
    return view


@functools.lru_cache(maxsize=VIEW_CACHE_SIZE)
def cached_level_view(state: ExploreState) -> LevelView:
    """:func:`level_view`, computed once per state for the whole server (its arrays
    read-only)."""
    return _frozen(level_view(state))  # type: ignore[no-any-return]


@functools.lru_cache(maxsize=VIEW_CACHE_SIZE)
def cached_diagram_view(state: ExploreState) -> DiagramView:
    """:func:`diagram_view`, computed once per state for the whole server (its arrays
    read-only)."""
    return _frozen(diagram_view(state))  # type: ignore[no-any-return]
