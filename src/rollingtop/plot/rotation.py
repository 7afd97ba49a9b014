"""The rotation-number map over ``(C2, h)`` and a contact-point path of each class of motion
(:mod:`rollingtop.reduction.rotation`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from rollingtop.absolute import reconstruct
from rollingtop.reduction.bifurcation import BifurcationDiagram
from rollingtop.reduction.level import LevelSet
from rollingtop.reduction.orbits import orbits
from rollingtop.reduction.rotation import RotationMap

__all__ = ["rotation_figure"]

#: Periods drawn for each class (closed: its q periods, at most this many).
PERIODS = {"drifting": 6, "closed": 60, "quasi-periodic": 60}
MARKERS = {"drifting": "s", "closed": "o", "quasi-periodic": "^"}


def _path(diagram: BifurcationDiagram, example: dict[str, Any], name: str) -> dict[str, Any]:
    level = LevelSet(diagram.body, diagram.M3, diagram.C1, example["C2"])
    orbit = [o for o in orbits(level, example["h"]) if o.kind == "periodic"][example["orbit"]]
    q = example["q"]
    n = PERIODS[name] if q is None or name == "drifting" else min(q, PERIODS[name])
    t = np.linspace(0.0, n * orbit.period, 200 * n + 1)
    return reconstruct(level, t, theta0=orbit.start_theta, w_tau0=0.0, rtol=1e-11, atol=1e-12)


def rotation_figure(
    diagram: BifurcationDiagram, rmap: RotationMap, examples: dict[str, dict[str, Any]]
) -> Figure:
    """Left: ``|N - nearest integer|`` of the first orbit of each level over ``(C2, h)`` (dark:
    near a resonance, where the centre of mass drifts or circles far), the curves of critical
    values, the points where ``N`` is an integer; right: the contact-point path of one level of
    each class (drifting, closed, quasi-periodic), marked on the map."""
    fig = Figure(figsize=(16.0, 4.8))
    grid = fig.add_gridspec(1, 4, width_ratios=[1.6, 1, 1, 1], wspace=0.45)
    ax = fig.add_subplot(grid[0, 0])
    n0 = rmap.N[:, :, 0]
    dist = np.abs(n0 - np.round(n0))
    dist = np.where(np.isfinite(dist), np.maximum(dist, 1e-4), np.nan)
    mesh = ax.pcolormesh(
        rmap.C2_grid,
        rmap.h_grid,
        dist,
        shading="nearest",
        cmap="magma",
        norm=LogNorm(vmin=1e-4, vmax=0.5),
        rasterized=True,
    )
    cbar = fig.colorbar(mesh, ax=ax, fraction=0.05)
    cbar.set_label("|N - nearest integer|, first orbit", fontsize=8)
    for br in diagram.branches:
        ax.plot(br.C2, br.h, color="w", lw=0.9, alpha=0.8)
    for q, colour, what in (
        (1, "cyan", "N integer (drift)"),
        (2, "#7fff00", "N = k + 1/2"),
        (3, "#ffd700", "N = p/3"),
    ):
        res = [r for r in rmap.resonances if r["orbit"] == 0 and r["q"] == q]
        if res:
            ax.plot(
                [r["C2"] for r in res], [r["h"] for r in res], ".", color=colour, ms=3, label=what
            )
    for name, ex in examples.items():
        ax.plot(ex["C2"], ex["h"], MARKERS[name], color="w", mec="k", ms=7, label=name)
    ax.set_xlim(rmap.C2_grid[0], rmap.C2_grid[-1])
    ax.set_ylim(rmap.h_grid[0], rmap.h_grid[-1])
    ax.set_xlabel("C2")
    ax.set_ylabel("h")
    ax.set_title(
        f"rotation number N = Delta psi / 2 pi, M3 = {rmap.M3:g}, C1 = {rmap.C1:g}", fontsize=9
    )
    ax.legend(fontsize=7, loc="upper left", framealpha=0.85)
    for k, name in enumerate(("drifting", "closed", "quasi-periodic")):
        sub = fig.add_subplot(grid[0, 1 + k])
        if name not in examples:
            sub.set_axis_off()
            sub.set_title(f"{name}: not on this map", fontsize=8)
            continue
        ex = examples[name]
        path = _path(diagram, ex, name)
        cp = path["contact_point"]
        sub.plot(cp[:, 0], cp[:, 1], lw=0.5, color="#1f4e9c")
        sub.plot(cp[0, 0], cp[0, 1], MARKERS[name], color="w", mec="k", ms=5)
        sub.set_aspect("equal", adjustable="datalim")
        frac = "" if ex["q"] in (None, 1) else f" = {ex['p']}/{ex['q']}"
        sub.set_title(
            f"contact point, {name}: N = {ex['N']:.4g}{frac}\nC2 = {ex['C2']:.4g}, "
            f"h = {ex['h']:.4g}",
            fontsize=8,
        )
        sub.tick_params(labelsize=6)
    return fig
