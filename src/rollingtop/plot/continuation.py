"""A branch of relative periodic orbits (:func:`rollingtop.chaos.continue_orbit`): the period
and the multipliers' moduli along it, the bifurcations marked."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from rollingtop.chaos.continuation import Branch

__all__ = ["branch_figure", "draw_branch"]

#: Marker and colour of each kind of bifurcation.
MARKS = {
    "fold": ("s", "#d62728"),
    "period-doubling": ("D", "#9467bd"),
    "neimark-sacker": ("*", "#ff7f0e"),
}
#: Colour of the branch and of its doubled branch.
COLOURS = ("#1f77b4", "#2ca02c")


def _axes(axes: Sequence[Axes] | None) -> tuple[Axes, Axes]:
    if axes is not None:
        top, bottom = axes
        return top, bottom
    import matplotlib.pyplot as plt

    _, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 7.0), sharex=True, layout="constrained")
    return top, bottom


def draw_branch(axes: Sequence[Axes] | None, branch: Branch) -> tuple[Axes, Axes]:
    """The period (top) and the moduli of the multipliers on the level (bottom, log scale, the
    unit circle dashed) against the parameter, for the branch and its doubled branch, each
    bifurcation marked on both; on ``axes`` (two axes, or ``None``: a new figure's). Returns
    the two axes."""
    top, bottom = _axes(axes)
    seen: set[str] = set()
    for k, br in enumerate(b for b in (branch, branch.doubled) if b is not None):
        lam = np.array([p.param for p in br.points])
        period = np.array([p.period for p in br.points])
        top.plot(lam, period, ".-", color=COLOURS[k], ms=3, lw=1, label=f"{br.returns} returns")
        d = max((len(p.multipliers) for p in br.points), default=0)
        for j in range(d):
            mods = [abs(p.multipliers[j]) if j < len(p.multipliers) else np.nan for p in br.points]
            bottom.plot(lam, mods, ".-", color=COLOURS[k], ms=3, lw=1, alpha=1.0 - 0.35 * j)
        for b in br.bifurcations:
            marker, colour = MARKS[b.kind]
            label = b.kind if b.kind not in seen else None
            seen.add(b.kind)
            top.plot(
                b.point.param,
                b.point.period,
                marker,
                color=colour,
                ms=10,
                mec="black",
                label=label,
                zorder=4,
            )
            for m in b.point.multipliers:
                bottom.plot(
                    b.point.param, abs(m), marker, color=colour, ms=10, mec="black", zorder=4
                )
    bottom.axhline(1.0, color="0.3", ls="--", lw=0.8)
    bottom.set_yscale("log")
    level = ", ".join(f"{k} = {v:.6g}" for k, v in branch.level.items())
    top.set_title(
        f"{branch.model}: an orbit with {branch.returns} returns followed in {branch.param}\n"
        f"(level held: {level}; largest unfolding parameter {branch.max_unfolding:.1g})",
        fontsize=10,
    )
    top.set_ylabel("period")
    bottom.set_ylabel("|multipliers| on the level")
    bottom.set_xlabel(branch.param)
    top.legend(loc="best", fontsize=8)
    return top, bottom


def branch_figure(branch: Branch) -> Figure:
    """``rollingtop continue -o``'s figure: :func:`draw_branch` on a figure of its own."""
    fig = Figure(figsize=(7.5, 7.0))
    top = fig.add_subplot(2, 1, 1)
    draw_branch((top, fig.add_subplot(2, 1, 2, sharex=top)), branch)
    fig.tight_layout()
    return fig
