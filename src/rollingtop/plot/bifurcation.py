"""Figures of the classification: the bifurcation diagram in ``(C2, h)`` with a thumbnail of each
region's phase portrait, and the number of steady motions over ``(C1, C2)``
(:mod:`rollingtop.reduction.bifurcation`)."""

from __future__ import annotations

import math

import numpy as np
from matplotlib import colormaps
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure

from rollingtop.reduction.bifurcation import BifurcationDiagram, SteadyCountMap
from rollingtop.reduction.level import LevelSet

__all__ = ["bifurcation_figure"]

CENTRE_COLOUR = "#1f4e9c"
SADDLE_COLOUR = "#c0392b"


def _thumbnail(ax, diagram: BifurcationDiagram, k: int) -> None:  # type: ignore[no-untyped-def]
    """The level curve ``h`` of region ``k``'s representative level in ``(gamma3, w_tau)``."""
    region = diagram.regions[k]
    level = LevelSet(diagram.body, diagram.M3, diagram.C1, region.C2)
    if level.pole is None:
        g = np.linspace(-1.0, 1.0, 2001)[1:-1]
        theta = LevelSet.theta_of(g)
    else:  # a pole level: the signed angle, in which orbits pass the pole regularly
        lo, hi = level.theta_domain
        theta = np.linspace(lo, hi, 2001)[1:-1]
        g = theta
    with np.errstate(over="ignore", invalid="ignore"):
        gap = 2.0 * (region.h - level.U(theta)) / level.rho(theta)
    w = np.where(gap >= 0.0, np.sqrt(np.clip(gap, 0.0, None)), np.nan)
    ax.plot(g, w, color=CENTRE_COLOUR, lw=1.2)
    ax.plot(g, -w, color=CENTRE_COLOUR, lw=1.2)
    ax.axhline(0.0, color="0.8", lw=0.5, zorder=0)
    ax.set_xlim(g[0], g[-1])
    top = np.nanmax(w) if np.isfinite(w).any() else 1.0
    ax.set_ylim(-1.15 * top, 1.15 * top)
    if level.pole is None:
        ax.set_xticks([-1, 0, 1])
    ax.set_yticks([])
    ax.tick_params(labelsize=6, length=2, pad=1)
    ax.set_title(f"{region.name}: {region.label}", fontsize=7, pad=2)


def _on_pole_level(diagram: BifurcationDiagram) -> bool:
    return LevelSet(diagram.body, diagram.M3, diagram.C1, 0.0).pole is not None


def bifurcation_figure(
    diagram: BifurcationDiagram,
    count_map: SteadyCountMap | None = None,
    mark_C2: float | None = None,
) -> Figure:
    """The diagram (curves of critical values: centres solid, saddles dashed; folds as dots;
    regions shaded and named) with a thumbnail of each region's level curve in
    ``(gamma3, w_tau)`` beside it, and, if given, the steady-motion count over ``(C1, C2)``."""
    regions = diagram.regions
    n_thumb = max(len(regions), 1)
    cols = 2 if n_thumb > 4 else 1
    rows_t = math.ceil(n_thumb / cols)
    extra = 1 if count_map is not None else 0
    fig = Figure(figsize=(7.0 + 2.2 * cols + 5.0 * extra, max(5.2, 1.5 * rows_t)))
    grid = fig.add_gridspec(rows_t, 3 + cols + 2 * extra, wspace=0.9, hspace=0.8)
    ax = fig.add_subplot(grid[:, :3])
    cmap = ListedColormap([colormaps["Pastel1"](i % 9) for i in range(max(len(regions), 1))])
    shade = np.ma.masked_less(diagram.region_index, 0)
    ax.pcolormesh(diagram.C2_grid, diagram.h_grid, shade, cmap=cmap, shading="nearest",
                  vmin=-0.5, vmax=len(regions) - 0.5, alpha=0.8, rasterized=True)  # fmt: skip
    ax.plot(diagram.C2_grid, diagram.min_U, color="0.3", lw=0.8, ls=":", label="min U")
    if np.isfinite(diagram.pole_energy).any():
        ax.plot(diagram.C2_grid, diagram.pole_energy, color="#7b3294", lw=1.2, ls="-.",
                label="U at the pole (above: through the pole)")  # fmt: skip
    for br in diagram.branches:
        for is_centre, style, colour in ((True, "-", CENTRE_COLOUR), (False, "--", SADDLE_COLOUR)):
            c2 = np.where(br.centre == is_centre, br.C2, np.nan)
            ax.plot(c2, br.h, style, color=colour, lw=1.4)
    ax.plot([], [], "-", color=CENTRE_COLOUR, label="centres")
    ax.plot([], [], "--", color=SADDLE_COLOUR, label="saddles")
    if diagram.folds:
        ax.plot([f.C2 for f in diagram.folds], [f.h for f in diagram.folds], "o", color="k",
                ms=4, label="folds")  # fmt: skip
    box = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "0.6", "lw": 0.5}
    for r in regions:
        ax.annotate(r.name, (r.C2, r.h), ha="center", va="center", fontsize=10, weight="bold",
                    bbox=box)  # fmt: skip
    if mark_C2 is not None:
        ax.axvline(mark_C2, color="0.4", lw=0.8, ls="-.", label=f"C2 = {mark_C2:g}")
    ax.set_xlim(diagram.C2_grid[0], diagram.C2_grid[-1])
    ax.set_ylim(diagram.h_grid[0], diagram.h_grid[-1])
    ax.set_xlabel("C2")
    ax.set_ylabel("h")
    b = diagram.body
    ax.set_title(f"critical values, M3 = {diagram.M3:g}, C1 = {diagram.C1:g}\n(R = {b.R:g}, "
                 f"a3 = {b.a3:g}, I1 = {b.I1:g}, I3 = {b.I3:g}, m = {b.m:g}, g = {b.g:g})",
                 fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, loc="upper left", framealpha=0.9)
    for k in range(len(regions)):
        sub = fig.add_subplot(grid[k % rows_t, 3 + k // rows_t])
        _thumbnail(sub, diagram, k)
        if k % rows_t == rows_t - 1 or k == len(regions) - 1:
            axis = "gamma3" if diagram.regions and _on_pole_level(diagram) is False else "theta"
            sub.set_xlabel(axis, fontsize=7, labelpad=1)
    if count_map is not None:
        axc = fig.add_subplot(grid[:, 3 + cols :])
        counts = np.ma.masked_less(count_map.count, 0)
        top = max(int(np.max(count_map.count)), 1)
        cm = ListedColormap([colormaps["Blues"](0.15 + 0.7 * i / max(top, 1))
                             for i in range(top + 1)])  # fmt: skip
        mesh = axc.pcolormesh(count_map.C1_grid, count_map.C2_grid, counts, cmap=cm,
                              shading="nearest", vmin=-0.5, vmax=top + 0.5,
                              rasterized=True)  # fmt: skip
        axc.plot(count_map.fold_C1, count_map.fold_C2, ".", color="k", ms=1.5, label="folds")
        for pole in (count_map.M3, -count_map.M3):
            axc.axvline(pole, color="0.5", lw=0.8, ls=":")
        axc.plot([diagram.C1], [mark_C2 if mark_C2 is not None else np.nan], "*", color="w",
                 mec="k", ms=9)  # fmt: skip
        axc.set_xlim(count_map.C1_grid[0], count_map.C1_grid[-1])
        axc.set_ylim(count_map.C2_grid[0], count_map.C2_grid[-1])
        axc.set_xlabel("C1")
        axc.set_ylabel("C2")
        axc.set_title(f"number of steady motions, M3 = {count_map.M3:g}\n"
                      "(dotted: pole lines C1 = +-M3)", fontsize=9)  # fmt: skip
        cbar = fig.colorbar(mesh, ax=axc, ticks=range(top + 1), fraction=0.05)
        cbar.ax.tick_params(labelsize=7)
    return fig
