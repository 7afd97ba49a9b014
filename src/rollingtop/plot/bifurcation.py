"""Figures of the classification: the bifurcation diagram in ``(C2, h)`` with a thumbnail of each
region's phase portrait, and the number of steady motions over ``(C1, C2)``
(:mod:`rollingtop.reduction.bifurcation`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from rollingtop.plot._axes import axes_for
from rollingtop.reduction.bifurcation import BifurcationDiagram, SteadyCountMap
from rollingtop.reduction.curves import level_curves
from rollingtop.reduction.level import LevelSet

__all__ = ["bifurcation_figure", "draw_bifurcation"]

CENTRE_COLOUR = "#1f4e9c"
SADDLE_COLOUR = "#c0392b"


#: Margin around a thumbnail's orbits, as a fraction of their extent along each axis.
THUMB_MARGIN = 0.08


def _thumbnail(ax: Axes, diagram: BifurcationDiagram, k: int, colour: Any) -> None:
    """The level curve ``h`` of region ``k``'s representative level in ``(gamma3, w_tau)``,
    each orbit closed, the axes fitted to the orbits, on the region's colour."""
    region = diagram.regions[k]
    level = LevelSet(diagram.body, diagram.M3, diagram.C1, region.C2)
    curves = level_curves(level, region.h)
    for x, w in curves:
        ax.plot(x, w, color=CENTRE_COLOUR, lw=1.3)
    ax.axhline(0.0, color="0.6", lw=0.5, zorder=0)
    ax.set_facecolor(colour)
    if curves:
        lo = min(float(np.nanmin(x)) for x, _ in curves)
        hi = max(float(np.nanmax(x)) for x, _ in curves)
        top = max(float(np.nanmax(w)) for _, w in curves) or 1.0
        pad = THUMB_MARGIN * max(hi - lo, 1e-9)
        if level.pole is None:
            ax.set_xlim(max(lo - pad, -1.0), min(hi + pad, 1.0))
        else:
            ax.set_xlim(lo - pad, hi + pad)
        ax.set_ylim(-(1.0 + 2 * THUMB_MARGIN) * top, (1.0 + 2 * THUMB_MARGIN) * top)
    else:  # the reduction found no orbit to draw (a wall too thin for doubles, say): said
        ax.text(0.5, 0.5, "no orbit drawn", transform=ax.transAxes, ha="center", fontsize=7)
    ax.xaxis.set_major_locator(MaxNLocator(3))
    ax.yaxis.set_major_locator(MaxNLocator(3, symmetric=True))
    ax.tick_params(labelsize=7, length=2, pad=1)
    ax.set_title(
        f"{region.name}: {region.label}\nC2 = {region.C2:.3g}, h = {region.h:.3g}",
        fontsize=8,
        pad=3,
    )


def _on_pole_level(diagram: BifurcationDiagram) -> bool:
    return LevelSet(diagram.body, diagram.M3, diagram.C1, 0.0).pole is not None


def _region_colours(diagram: BifurcationDiagram) -> ListedColormap:
    """One pastel colour per region, in the order of :attr:`BifurcationDiagram.regions`."""
    n = max(len(diagram.regions), 1)
    return ListedColormap([colormaps["Pastel1"](i % 9) for i in range(n)])


def draw_bifurcation(
    ax: Axes | None, diagram: BifurcationDiagram, mark_C2: float | None = None
) -> Axes:
    """The diagram in ``(C2, h)`` on ``ax``: the regions shaded and named, ``min U``, the
    curves of critical values (centres solid, saddles dashed), the folds as dots, on a pole
    level the pole's energy, and a vertical line at ``mark_C2`` if given. Returns ``ax``
    (``None``: a new figure's, :func:`~rollingtop.plot._axes.axes_for`)."""
    ax = axes_for(ax, (6.4, 5.6))
    regions = diagram.regions
    cmap = _region_colours(diagram)
    shade = np.ma.masked_less(diagram.region_index, 0)
    ax.pcolormesh(
        diagram.C2_grid,
        diagram.h_grid,
        shade,
        cmap=cmap,
        shading="nearest",
        vmin=-0.5,
        vmax=len(regions) - 0.5,
        alpha=0.8,
        rasterized=True,
    )
    ax.plot(diagram.C2_grid, diagram.min_U, color="0.3", lw=0.8, ls=":", label="min U")
    if np.isfinite(diagram.pole_energy).any():
        ax.plot(
            diagram.C2_grid,
            diagram.pole_energy,
            color="#7b3294",
            lw=1.2,
            ls="-.",
            label="U at the pole (above: through the pole)",
        )
    for br in diagram.branches:
        for is_centre, style, colour in ((True, "-", CENTRE_COLOUR), (False, "--", SADDLE_COLOUR)):
            c2 = np.where(br.centre == is_centre, br.C2, np.nan)
            ax.plot(c2, br.h, style, color=colour, lw=1.4)
    ax.plot([], [], "-", color=CENTRE_COLOUR, label="centres")
    ax.plot([], [], "--", color=SADDLE_COLOUR, label="saddles")
    if diagram.folds:
        ax.plot(
            [f.C2 for f in diagram.folds],
            [f.h for f in diagram.folds],
            "o",
            color="k",
            ms=4,
            label="folds",
        )
    box = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "0.6", "lw": 0.5}
    for r in regions:
        ax.annotate(
            r.name, (r.C2, r.h), ha="center", va="center", fontsize=10, weight="bold", bbox=box
        )
    if mark_C2 is not None:
        ax.axvline(mark_C2, color="0.4", lw=0.8, ls="-.", label=f"C2 = {mark_C2:g}")
    ax.set_xlim(diagram.C2_grid[0], diagram.C2_grid[-1])
    ax.set_ylim(diagram.h_grid[0], diagram.h_grid[-1])
    ax.set_xlabel("C2")
    ax.set_ylabel("h")
    b = diagram.body
    ax.set_title(
        f"critical values, M3 = {diagram.M3:g}, C1 = {diagram.C1:g}\n(R = {b.R:g}, "
        f"a3 = {b.a3:g}, I1 = {b.I1:g}, I3 = {b.I3:g}, m = {b.m:g}, g = {b.g:g})",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper left", framealpha=0.9)
    return ax


def bifurcation_figure(
    diagram: BifurcationDiagram,
    count_map: SteadyCountMap | None = None,
    mark_C2: float | None = None,
) -> Figure:
    """The diagram (:func:`draw_bifurcation`) with a thumbnail of each region's level curve in
    ``(gamma3, w_tau)`` beside it, and, if given, the steady-motion count over ``(C1, C2)``."""
    regions = diagram.regions
    n_thumb = max(len(regions), 1)
    cols = 1 if n_thumb <= 2 else 2
    rows_t = math.ceil(n_thumb / cols)
    extra = 1 if count_map is not None else 0
    fig = Figure(
        figsize=(5.6 + 2.7 * cols + 4.4 * extra, max(5.6, 2.8 * rows_t)), layout="constrained"
    )
    outer = fig.add_gridspec(1, 2 + extra, width_ratios=[5.6, 2.7 * cols] + [4.4] * extra)
    draw_bifurcation(fig.add_subplot(outer[0, 0]), diagram, mark_C2)
    cmap = _region_colours(diagram)
    thumbs = outer[0, 1].subgridspec(rows_t, cols)
    axis = "theta" if _on_pole_level(diagram) else "gamma3"
    for k in range(len(regions)):
        sub = fig.add_subplot(thumbs[k // cols, k % cols])
        _thumbnail(sub, diagram, k, (*cmap(k)[:3], 0.35))
        if k + cols >= len(regions):  # the lowest in its column
            sub.set_xlabel(axis, fontsize=8, labelpad=1)
        if k % cols == 0:
            sub.set_ylabel("w_tau", fontsize=8, labelpad=1)
    if count_map is not None:
        axc = fig.add_subplot(outer[0, 2])
        counts = np.ma.masked_less(count_map.count, 0)
        top = max(int(np.max(count_map.count)), 1)
        cm = ListedColormap(
            [colormaps["Blues"](0.15 + 0.7 * i / max(top, 1)) for i in range(top + 1)]
        )
        mesh = axc.pcolormesh(
            count_map.C1_grid,
            count_map.C2_grid,
            counts,
            cmap=cm,
            shading="nearest",
            vmin=-0.5,
            vmax=top + 0.5,
            rasterized=True,
        )
        axc.plot(count_map.fold_C1, count_map.fold_C2, ".", color="k", ms=1.5, label="folds")
        for pole in (count_map.M3, -count_map.M3):
            axc.axvline(pole, color="0.5", lw=0.8, ls=":")
        axc.plot(
            [diagram.C1],
            [mark_C2 if mark_C2 is not None else np.nan],
            "*",
            color="w",
            mec="k",
            ms=9,
        )
        axc.set_xlim(count_map.C1_grid[0], count_map.C1_grid[-1])
        axc.set_ylim(count_map.C2_grid[0], count_map.C2_grid[-1])
        axc.set_xlabel("C1")
        axc.set_ylabel("C2")
        axc.set_title(
            f"number of steady motions, M3 = {count_map.M3:g}\n(dotted: pole lines C1 = +-M3)",
            fontsize=9,
        )
        cbar = fig.colorbar(mesh, ax=axc, ticks=range(top + 1), fraction=0.05)
        cbar.ax.tick_params(labelsize=7)
    return fig
