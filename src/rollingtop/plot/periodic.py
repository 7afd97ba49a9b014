"""The relative periodic orbits of a level (:func:`rollingtop.chaos.periodic_orbits`) on its
Poincare section."""

from __future__ import annotations

from typing import TYPE_CHECKING

from matplotlib.figure import Figure

from rollingtop.plot._axes import axes_for

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from rollingtop.chaos.periodic import PeriodicOrbits

__all__ = ["draw_periodic", "periodic_figure"]

#: Marker and colour of each type of orbit.
STYLE = {
    "attracting": ("o", "#2ca02c"),
    "repelling": ("s", "#d62728"),
    "saddle": ("X", "#ff7f0e"),
    "elliptic": ("D", "#1f77b4"),
    "neutral": ("P", "#7f7f7f"),
}


def draw_periodic(ax: Axes | None, found: PeriodicOrbits, *, legend: bool = True) -> Axes:
    """The seeding trajectories' crossings (grey) in the plane ``(gamma3, w_n)`` and each
    orbit's crossings, marked by its type and labelled ``orbit:returns``, on ``ax`` (``None``: a
    new figure's); returns ``ax``."""
    ax = axes_for(ax, (7.0, 5.6))
    pts = found.iterates.reshape(-1, 2)
    ax.plot(pts[:, 0], pts[:, 1], ".", ms=1.2, color="0.7", zorder=1)
    seen = set()
    for k, orbit in enumerate(found.orbits):
        marker, colour = STYLE[orbit.type]
        label = orbit.type if orbit.type not in seen else None
        seen.add(orbit.type)
        ax.plot(
            orbit.points[:, 0],
            orbit.points[:, 1],
            marker,
            color=colour,
            ms=7,
            mec="black",
            mew=0.6,
            label=label,
            zorder=3,
        )
        for x, y in orbit.points[:, :2]:
            ax.annotate(
                f"{k + 1}:{orbit.returns}",
                (x, y),
                textcoords="offset points",
                xytext=(6, 5 - 11 * (k % 2)),  # neighbouring orbits' labels apart
                fontsize=8,
            )
    level = ", ".join(f"{k} = {v:.6g}" for k, v in found.level.items())
    ax.set_title(
        f"{found.model}: {len(found.orbits)} periodic orbits on the level {level}\n"
        "(label orbit:returns; grey: the section's trajectories)",
        fontsize=10,
    )
    ax.set_xlabel("gamma3 at the section (minimum of gamma3)")
    ax.set_ylabel("w_n")
    if legend and found.orbits:
        ax.legend(loc="best", fontsize=8)
    return ax


def periodic_figure(found: PeriodicOrbits) -> Figure:
    """``rollingtop periodic -o``'s figure: :func:`draw_periodic` on a figure of its own."""
    fig = Figure(figsize=(7.0, 5.6))
    draw_periodic(fig.add_subplot(), found)
    fig.tight_layout()
    return fig
