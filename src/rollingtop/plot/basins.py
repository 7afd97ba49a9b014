"""Basins of attraction on a level's section (:func:`rollingtop.basins.basin_map`)."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["basins_figure"]

#: Colours of the attractors, in order; then those of the other labels.
ATTRACTOR_COLOURS = ["#2ca02c", "#1f77b4", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
OTHER_COLOURS = {-1: "#d9d9d9", -2: "#404040", -3: "#ffffff"}


def basins_figure(ds: xr.Dataset) -> Figure:
    """Each grid point of the section plane ``(gamma3, w_n)`` coloured by the attractor its
    start reaches (light grey: none; dark grey: stopped; white: not on the level), with the
    attractors' crossings marked; the legend gives each attractor's share of the starts on the
    level."""
    attractors = json.loads(ds.attrs["attractors"])
    labels = json.loads(ds.attrs["labels"])
    n = len(attractors)
    colours = [OTHER_COLOURS[-3], OTHER_COLOURS[-2], OTHER_COLOURS[-1]]
    colours += [ATTRACTOR_COLOURS[k % len(ATTRACTOR_COLOURS)] for k in range(n)]
    label = ds["label"].values  # (gamma3, w_n); -3..n-1 -> colour index 0..n+2
    g3, wn = ds["gamma3"].values, ds["w_n"].values
    fig = Figure(figsize=(7.0, 5.6))
    ax = fig.add_subplot()
    ax.pcolormesh(
        g3,
        wn,
        (label + 3).T,
        cmap=ListedColormap(colours),
        vmin=-0.5,
        vmax=n + 2.5,
        shading="nearest",
    )
    handles = []
    for k, a in enumerate(attractors):
        pts = np.array(a["points"])
        colour = ATTRACTOR_COLOURS[k % len(ATTRACTOR_COLOURS)]
        ax.plot(pts[:, 0], pts[:, 1], "o", ms=7, color=colour, mec="black", mew=0.8)
        share = float(np.mean(label[label != -3] == k)) if np.any(label != -3) else 0.0
        handles.append(
            Patch(
                color=colour,
                label=f"{k + 1}: {a['returns']} return{'s' * (a['returns'] != 1)}, "
                f"period {a['period']:.4g} ({share:.0%})",
            )
        )
    for code in (-1, -2):
        if np.any(label == code):
            handles.append(Patch(color=OTHER_COLOURS[code], label=labels[str(code)]))
    ax.legend(handles=handles, loc="best", fontsize=8)
    level = ", ".join(f"{k[6:]} = {v:.6g}" for k, v in ds.attrs.items() if k.startswith("level_"))
    ax.set_title(
        f"{ds.attrs['model']}: basins on the level {level}\n"
        f"(sheet {ds.attrs['sheet']}, after {ds.attrs['crossings']} crossings; white: not on the "
        "level)",
        fontsize=10,
    )
    ax.set_xlabel("gamma3 at the section (minimum of gamma3)")
    ax.set_ylabel("w_n")
    fig.tight_layout()
    return fig
