"""Bifurcation diagrams of the reduced system: the classification the paper leaves open (Sec. 3.3).

Fix the body and the integrals ``(M3, C1)``. On the level set ``(M3, C1, C2)`` the effective
potential (eq. 3.11, :class:`~rollingtop.reduction.LevelSet`) is, in the nutation angle ``theta``
(``gamma3 = cos theta``),

    U(theta; C2) = U0(theta) + m ((P0 + C2)^2 - P0^2) / (2 I1^2),    P = P0(theta) + C2 = I1 v_tau,

where ``U0, P0`` are ``U, P`` at ``C2 = 0``. So ``dU/dtheta = U0'(theta) + m C2 P'(theta) / I1^2``
is affine in ``C2`` (``P' = dP/dtheta`` does not depend on ``C2``), and ``theta`` is a steady
motion of the level ``C2`` exactly when

    C2 = C2*(theta) = -I1^2 U0'(theta) / (m P'(theta)).

In ``gamma3``, ``dP/dgamma3 = (M3 gamma3 - C1)(R + a3 gamma3) / s^3`` (``s = sin theta``): ``C2*``
has a pole at ``gamma3 = C1/M3`` (and at ``gamma3 = -R/a3`` for a centre of mass outside the
sphere), where ``U0'`` stays ``-m g a3 s != 0``; between the poles it is smooth. With the centre
of mass at the centre (``a3 = 0``) ``U0'`` vanishes there too: the pole is removable, and
``gamma3 = C1/M3`` is a steady motion for every ``C2`` -- a family drawn as a curve of its own,
which the other curve crosses (a pitchfork there, not a fold). The critical
values form the curves ``theta -> (C2*(theta), h*(theta))``, ``h* = U(theta; C2*(theta))``, in the
plane ``(C2, h)``. Along a curve ``U'' = -m P' C2*' / I1^2``: the critical point is a centre where
``P' C2*' < 0``, a saddle where ``> 0``, and the two meet at the **folds**, the extrema of ``C2*``
(cusps of the curves in the ``(C2, h)`` plane, where a centre and a saddle are born or die).

The **regions** of the plane between the curves (above ``min U``) are classified by what the level
``h`` holds: ``U -> +inf`` at both poles when ``|C1| != |M3|``, so ``{U < h}`` is a union of
intervals, each one periodic orbit of ``gamma3`` around the centres (minima of ``U``) it contains.
In the plane ``(C1, C2)`` at fixed ``M3`` the number of steady motions changes across the fold
curves ``C1 -> C2*(fold)``.

On a pole level (``C1 = +-M3``) the signed nutation angle covers both sides of the pole, where
``U`` is finite and smooth (:mod:`rollingtop.reduction.level`): an orbit whose interval of
``{U < h}`` contains the pole passes through it, and the regions say which do. The level without
spin (``M3 = C1 = 0``, ``U`` periodic) is refused.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._figures import draw
from rollingtop._html import count, html_view
from rollingtop._json import json_ready
from rollingtop.body import SphericalTop
from rollingtop.reduction._critical_curves import (
    Branch,
    Fold,
    _base_level,
    _branches,
    _critical,
    _family,
    _family_branch,
    _pitchfork_c2,
    critical_c2,
    critical_energy,
    folds,
)
from rollingtop.reduction._regions import (
    POLE_CUT,
    THROUGH_POLE,
    Region,
    _centres,
    _orbits_at,
    _pole,
    describe_signature,
    region_orbits,
    region_signature,
)
from rollingtop.reduction._steady_map import SteadyCountMap, steady_count_map
from rollingtop.reduction.level import Level, LevelSet, LevelSetError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "BifurcationDiagram",
    "Branch",
    "Fold",
    "Region",
    "SteadyCountMap",
    "bifurcation_diagram",
    "critical_c2",
    "critical_energy",
    "describe_signature",
    "folds",
    "region_orbits",
    "region_signature",
    "steady_count_map",
]

FloatArray = NDArray[np.float64]

#: Critical values closer than this (relative) are one value: no region between them.
EQUAL_VALUES = 1e-9


@dataclass(frozen=True)
class BifurcationDiagram:
    """The bifurcation diagram of ``(M3, C1)`` in the plane ``(C2, h)``.

    Attributes
    ----------
    body : SphericalTop
    M3, C1 : float
    branches : list of Branch
        The curves of critical values.
    folds : list of Fold
    regions : list of Region
    C2_grid, h_grid : ndarray, shapes (nc,), (nh,)
        The grid the regions were found on.
    region_index : ndarray of int, shape (nh, nc)
        Index into ``regions`` of each grid cell, for drawing (-1: no motion).
    min_U : ndarray, shape (nc,)
        ``min U`` over ``gamma3`` at each ``C2`` of the grid (below it: no motion).
    pole_energy : ndarray, shape (nc,)
        On a pole level, ``U`` at the pole for each ``C2`` of the grid: above it the orbits pass
        through the pole (NaN off the pole levels).
    """

    body: SphericalTop
    M3: float
    C1: float
    branches: list[Branch]
    folds: list[Fold]
    regions: list[Region]
    C2_grid: FloatArray
    h_grid: FloatArray
    region_index: NDArray[np.int64]
    min_U: FloatArray
    pole_energy: FloatArray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: the folds, the regions and the grid's extent."""
        return json_ready(
            {
                "M3": self.M3,
                "C1": self.C1,
                "folds": [f.to_dict() for f in self.folds],
                "regions": [r.to_dict() for r in self.regions],
                "C2_range": [float(self.C2_grid[0]), float(self.C2_grid[-1])],
                "h_range": [float(self.h_grid[0]), float(self.h_grid[-1])],
                "grid": [len(self.C2_grid), len(self.h_grid)],
            }
        )

    def __repr__(self) -> str:
        return (
            f"<BifurcationDiagram: M3 = {self.M3:g}, C1 = {self.C1:g}; "
            f"{count(len(self.folds), 'fold')}, {count(len(self.regions), 'region')} in C2 = "
            f"{self.C2_grid[0]:g} .. {self.C2_grid[-1]:g}, h = {self.h_grid[0]:g} .. "
            f"{self.h_grid[-1]:g}>"
        )

    def _repr_html_(self) -> str:
        """The notebook's view: body, window, the folds and the regions (their orbits)."""
        return html_view(self)

    def plot(self, ax: Axes | None = None, **kw: Any) -> Axes:
        """Draw the diagram of ``rollingtop bifurcation`` (its main panel, without the
        thumbnails) on ``ax`` (default: a new figure's) and return ``ax``; ``kw`` go to
        :func:`rollingtop.plot.bifurcation.draw_bifurcation` (``mark_C2``)."""
        axes: Axes = draw("bifurcation", ax, self, **kw)
        return axes


def _default_c2_range(level: Level, fs: Sequence[Fold]) -> tuple[float, float]:
    if fs:
        lo, hi = min(f.C2 for f in fs), max(f.C2 for f in fs)
    else:
        lo = hi = 0.0
    pad = max(1.0, 0.6 * (hi - lo))
    return lo - pad, hi + pad


def _default_h_range(
    branches: Sequence[Branch], c2: tuple[float, float], min_u: float
) -> tuple[float, float]:
    """From just below ``min_u`` to above the highest saddle with ``C2`` in ``c2`` (above the
    highest centre when there is no saddle)."""
    saddles, centres = [min_u], [min_u]
    for br in branches:
        inside = (br.C2 >= c2[0]) & (br.C2 <= c2[1]) & np.isfinite(br.h)
        saddles += br.h[inside & ~br.centre].tolist()
        centres += br.h[inside & br.centre].tolist()
    top = max(saddles) if len(saddles) > 1 else max(centres)
    span = max(top - min_u, 1e-3 * max(1.0, abs(min_u)))
    return min_u - 0.05 * span, top + 0.35 * span


def bifurcation_diagram(
    body: SphericalTop,
    M3: float,
    C1: float,
    *,
    C2_range: tuple[float, float] | None = None,
    h_range: tuple[float, float] | None = None,
    resolution: tuple[int, int] = (161, 161),
) -> BifurcationDiagram:
    """The bifurcation diagram of the reduced system at ``(M3, C1)`` in the plane ``(C2, h)``.

    Parameters
    ----------
    body : SphericalTop
        Dynamically symmetric body.
    M3, C1 : float
        Lagrange and area integrals; pole levels ``C1 = +-M3`` are refused.
    C2_range, h_range : (float, float), optional
        Window of the diagram. Default: the folds' ``C2`` widened by 60 % (at least 1 on each
        side); ``h`` from just below ``min U`` to above the highest saddle in that window.
    resolution : (int, int)
        ``nc`` values of ``C2`` (columns) and ``nh`` of ``h`` (for drawing). In each column the
        critical values cut the ``h`` axis into intervals with one set of orbits each
        (exact: :func:`region_signature`). Intervals of neighbouring columns belong to one
        region when they hold the same orbits around the same centres and share a bounding
        critical point or,
        across a fold (the number of critical points changes), when their orbits are of the
        same kind and they overlap. A region narrower than the column spacing in ``C2`` can be
        missed.

    Returns
    -------
    BifurcationDiagram
    """
    level = _base_level(body, M3, C1)
    nc, nh = (int(x) for x in resolution)
    if nc < 3 or nh < 3:
        raise LevelSetError(f"resolution = {resolution} must be at least (3, 3)")
    fs = folds(body, M3, C1)
    lost = [f for f in fs if not (math.isfinite(f.C2) and math.isfinite(f.h))]
    if lost:  # a spin so small that the folds (which move away like 1/M3) leave double precision
        raise LevelSetError(
            f"M3 = {M3:g}: the diagram's fold lies at C2 = {lost[0].C2:.3g}, h = {lost[0].h:g}, "
            "beyond double precision (the folds move away like 1/M3 as the spin vanishes): the "
            "spin is too small for a diagram; without spin see rollingtop.reduction.no_spin"
        )
    branches = _branches(level)
    marks = list(fs)
    t0 = _family(level)
    if t0 is not None:  # a3 = 0: the pitchfork where the family changes type belongs in view
        marks.append(Fold(_pitchfork_c2(level, t0), math.cos(t0), math.nan, "pitchfork", t0))
    c2_lo, c2_hi = C2_range if C2_range is not None else _default_c2_range(level, marks)
    if not (math.isfinite(c2_hi - c2_lo) and c2_lo < c2_hi):  # its width too: a grid's spacing
        raise LevelSetError(
            f"C2 range ({c2_lo:g}, {c2_hi:g}) must be finite and increasing, and its width finite"
        )
    C2_grid = np.linspace(c2_lo, c2_hi, nc)
    if t0 is not None:
        branches.append(_family_branch(level, t0, (c2_lo, c2_hi)))
    # per column: the critical values cut the h axis into intervals, each with one set of
    # orbits; a node is (column, lo, hi, orbits, its bounding critical points' indices, count)
    nodes: list[tuple[int, float, float, tuple[tuple[int, ...], ...], tuple[int, int, int]]] = []
    columns: list[list[int]] = []
    gammas: list[FloatArray] = []
    min_U = np.empty(nc)
    pole_energy = np.full(nc, np.nan)
    for j, c2 in enumerate(C2_grid):
        lv = LevelSet(body, level.M3, level.C1, float(c2))
        th, U, u2 = _critical(lv)
        gammas.append(np.cos(th))
        pole = _pole(lv)
        centre = u2 > 0
        min_U[j] = float(np.min(U[centre])) if centre.any() else math.nan
        # the h axis is cut at the critical values and, on a pole level, at the pole's energy
        # (above it orbits pass through the pole); POLE_CUT stands for the pole in the ids
        cut_values = [(float(u), k) for k, u in enumerate(U)]
        if pole is not None:
            cut_values.append((pole[1], POLE_CUT))
            pole_energy[j] = pole[1]
        cut_values.sort()
        column = []
        for pos, (lo, k) in enumerate(cut_values):
            upper = cut_values[pos + 1][1] if pos + 1 < len(cut_values) else -1
            hi = cut_values[pos + 1][0] if pos + 1 < len(cut_values) else math.inf
            if math.isfinite(hi) and not hi - lo > EQUAL_VALUES * max(1.0, abs(lo), abs(hi)):
                continue  # equal critical values (a symmetric body's twin wells), to round-off
            mid = 0.5 * (lo + hi) if math.isfinite(hi) else lo + 1.0 + abs(lo)
            column.append(len(nodes))
            nodes.append((j, lo, hi, _orbits_at(U, centre, mid, th, pole), (k, upper, len(U))))
        columns.append(column)
    if h_range is None:
        h_range = _default_h_range(branches, (c2_lo, c2_hi), float(np.nanmin(min_U)))
    h_lo, h_hi = h_range
    if not (math.isfinite(h_hi - h_lo) and h_lo < h_hi):
        raise LevelSetError(
            f"h range ({h_lo:g}, {h_hi:g}) must be finite and increasing, and its width finite"
        )
    h_grid = np.linspace(h_lo, h_hi, nh)
    # regions: nodes of neighbouring columns with the same orbits and overlapping h intervals
    parent = list(range(len(nodes)))

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def same_region(a: int, b: int) -> bool:
        (_, lo1, hi1, o1, id1), (_, lo2, hi2, o2, id2) = nodes[a], nodes[b]
        if id1[2] == id2[2]:
            # no fold between the columns: the same orbits (around the same centres) above the
            # same critical value or below the same one (where two curves cross, a region
            # keeps one of its two bounding curves; a strip between the crossing curves keeps
            # neither)
            return o1 == o2 and (id1[0] == id2[0] or id1[1] == id2[1])
        # a fold between them: the same kind of orbits, overlapping in h
        return _kinds(o1) == _kinds(o2) and lo1 < hi2 and lo2 < hi1

    for j in range(nc - 1):
        for a in columns[j]:
            for b in columns[j + 1]:
                if same_region(a, b):
                    parent[find(a)] = find(b)
    members: dict[int, list[int]] = {}
    for a in range(len(nodes)):
        if nodes[a][3] and nodes[a][2] > h_lo and nodes[a][1] < h_hi:  # motion, in the window
            members.setdefault(find(a), []).append(a)
    reps = []
    for group in members.values():
        cols = sorted(nodes[a][0] for a in group)
        middle = cols[len(cols) // 2]
        a = next(a for a in group if nodes[a][0] == middle)
        j, lo, hi, orbits, _ = nodes[a]
        lo_c, hi_c = max(lo, h_lo), min(hi, h_hi)
        los = [max(nodes[b][1], h_lo) for b in group]
        his = [min(nodes[b][2], h_hi) for b in group]
        where = tuple(tuple(float(gammas[j][k]) for k in _centres(orbit)) for orbit in orbits)
        reps.append(
            (float(C2_grid[j]), 0.5 * (lo_c + hi_c), orbits, group, min(los), max(his), where)
        )
    reps.sort(key=lambda r: (r[0], r[1]))
    region_index = np.full((nh, nc), -1, dtype=np.int64)
    regions = []
    for n_reg, (c2, h, orbits, group, lo, hi, where) in enumerate(reps):
        cols = [nodes[a][0] for a in group]
        for a in group:
            j, lo_a, hi_a, _, _ = nodes[a]
            region_index[(h_grid > lo_a) & (h_grid <= hi_a), j] = n_reg
        sig = tuple(len(_centres(o)) for o in orbits)
        passing = tuple(THROUGH_POLE in o for o in orbits)
        regions.append(
            Region(
                name=_region_name(n_reg),
                signature=sig,
                label=describe_signature(sig, passing),
                C2=c2,
                h=h,
                centre_gamma3=where,
                through_pole=passing,
                C2_range=(float(C2_grid[min(cols)]), float(C2_grid[max(cols)])),
                h_range=(lo, hi),
                cells=len(group),
            )
        )
    return BifurcationDiagram(
        body,
        float(level.M3),
        float(level.C1),
        branches,
        fs,
        regions,
        C2_grid,
        h_grid,
        region_index,
        min_U,
        pole_energy,
    )


def _kinds(orbits: tuple[tuple[int, ...], ...]) -> list[tuple[int, bool]]:
    return [(len(_centres(o)), THROUGH_POLE in o) for o in orbits]


def _region_name(k: int) -> str:
    letters = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
    return letters[k] if k < 26 else f"{letters[k // 26 - 1]}{letters[k % 26]}"
