"""Phase portraits of the reduced system in the plane ``(gamma3, w_tau)`` (paper Fig. 5), drawn
from the curves :mod:`rollingtop.reduction.curves` computes: each orbit from its exact
parametrisation, closed at its turning points, the separatrices through the saddles. Where the
normal reaction of the plane would be negative (the body would jump: the model does not apply)
the plane is shaded.

In a pole case (``C1 = +-M3``) the horizontal axis is the signed nutation angle ``theta``
(``gamma3 = cos theta``), in which the flow through the pole is regular.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rollingtop.plot._axes import axes_for
from rollingtop.reduction import SteadyMotion, steady_motions
from rollingtop.reduction.curves import (
    abscissa,
    default_h_levels,
    normal_force_grid,
    on_a_saddle,
    portrait_curves,
)
from rollingtop.reduction.level import Level

__all__ = ["default_h_levels", "draw_portrait", "draw_potential", "phase_portrait"]

#: The abscissa's label: ``gamma3``, or the signed angle in a pole case.
_XLABEL = {False: r"$\gamma_3$", True: r"$\theta$ (signed nutation angle, $\gamma_3 = \cos\theta$)"}


def _colour(levels: Sequence[float], h: float) -> Any:
    """The colour of the orbits at ``h`` among ``levels`` (viridis, in the order of ``h``)."""
    lo_h, hi_h = min(levels), max(levels)
    frac = (h - lo_h) / (hi_h - lo_h) if hi_h > lo_h else 0.5
    return colormaps["viridis"](0.1 + 0.8 * frac)


def _draw_orbits(
    ax: Axes,
    level: Level,
    levels: Sequence[float],
    motions: Sequence[SteadyMotion],
    show_contact: bool,
) -> tuple[float, float]:
    """The upper panel of :func:`phase_portrait` on ``ax``; returns its abscissa's limits."""
    body = level.body
    saddle_levels = {m.U for m in motions if m.type == "saddle"}
    found = portrait_curves(level, levels, motions=motions)
    g_lo, g_hi, w_top = found.window
    drawn_sep = drawn = False
    for curve in found.curves:
        h, x, y = curve.h, curve.x, curve.w
        if curve.separatrix:
            ax.plot(
                x, y, color="crimson", lw=1.8, zorder=3, label=None if drawn_sep else "separatrix"
            )
            drawn_sep = True
        else:
            ax.plot(
                x,
                y,
                color=_colour(levels, h),
                lw=1.0,
                zorder=2,
                label=None if drawn else "orbits (colour: h)",
            )
            drawn = True
    if show_contact and not level.pole:
        gg = np.linspace(max(g_lo, -0.999), min(g_hi, 0.999), 90)
        ww = np.linspace(-w_top, w_top, 80)
        N = normal_force_grid(level, gg, ww)
        if np.any(N < 0):
            ax.contourf(gg, ww, N, levels=[N.min() - 1, 0.0], colors=["#f4c7c3"], zorder=1)
            ax.plot([], [], color="#f4c7c3", lw=6, label="normal force < 0 (contact lost)")
    _mark_steady(ax, level, motions, (g_lo, g_hi), on_potential=False)
    for pole_theta in level.pole_thetas:
        ax.axvline(pole_theta, color="0.5", ls="--", lw=0.8, zorder=0)
    if level.pole:
        names = {
            "south": "south pole (gamma3 = +1)",
            "north": "north pole (gamma3 = -1)",
            "both": "poles (gamma3 = +1 at 0, -1 at pi)",
        }
        ax.plot([], [], color="0.5", ls="--", lw=0.8, label=names[level.pole])
    ax.plot([], [], "o", color="black", ms=5, label="steady motion (centre)")
    if saddle_levels:
        ax.plot([], [], "x", color="crimson", ms=8, mew=2, label="steady motion (saddle)")
    ax.set_xlim(g_lo, g_hi)
    ax.set_ylim(-w_top, w_top)
    ax.set_ylabel(r"$\omega_\tau$")
    ax.axhline(0, color="0.85", lw=0.6, zorder=0)
    pole = {
        None: "",
        "south": ", south pole case",
        "north": ", north pole case",
        "both": ", no spin: both poles",
    }[level.pole]
    symbols = {"M3": "M_3", "C1": "C_1", "C2": "C_2", "p_horizontal": r"p_{\rm h}"}
    upright = {k: r"\mathrm{" + k.replace("_", r"\_") + "}" for k in level.values()}
    named = r",\ ".join(f"{symbols.get(k, upright[k])}={v:g}" for k, v in level.values().items())
    ax.set_title(
        rf"{level.model} model: ${named}${pole}"
        "\n"
        rf"$R={body.R:g},\ m={body.m:g},\ g={body.g:g},\ a_3={body.a3:g},\ "
        rf"I_1={body.I1:g},\ I_3={body.I3:g}$",
        fontsize=10,
    )
    return g_lo, g_hi


def _mark_steady(
    ax: Axes,
    level: Level,
    motions: Sequence[SteadyMotion],
    window: tuple[float, float],
    on_potential: bool,
) -> None:
    """Each steady motion inside ``window``: a centre as a black dot, a saddle as a crimson
    cross, at ``w_tau = 0`` (the portrait) or at its ``U`` (the potential)."""
    for m in motions:
        xm = float(abscissa(level, m.theta))
        if not window[0] <= xm <= window[1]:
            continue
        y = m.U if on_potential else 0.0
        if m.type == "center":
            ax.plot(xm, y, "o", color="black", ms=5, zorder=4)
        else:
            ax.plot(xm, y, "x", color="crimson", ms=8, mew=2, zorder=4)


def _draw_potential(
    ax: Axes,
    level: Level,
    levels: Sequence[float],
    motions: Sequence[SteadyMotion],
    window: tuple[float, float],
) -> None:
    """The lower panel of :func:`phase_portrait` on ``ax``: ``U`` over ``window`` of the
    abscissa and a line at each of the energies ``levels`` (the separatrices crimson)."""
    saddle_levels = {m.U for m in motions if m.type == "saddle"}
    g_lo, g_hi = window
    if level.pole:
        g = np.linspace(g_lo, g_hi, 1500)
        U = level.U(g)
    else:
        g = np.linspace(max(g_lo, -0.9999), min(g_hi, 0.9999), 1500)
        U = level.U_gamma3(g)
    ax.plot(g, U, color="black", lw=1.2)
    for h in levels:
        sep = on_a_saddle(h, saddle_levels)
        ax.axhline(h, color="crimson" if sep else _colour(levels, h), lw=0.8)
    hi_h = max(levels)
    u_min = min((m.U for m in motions), default=float(np.min(U)))
    ax.set_ylim(u_min - 0.05 * (hi_h - u_min), hi_h + 0.15 * (hi_h - u_min))
    ax.set_xlabel(_XLABEL[bool(level.pole)])
    ax.set_ylabel(r"$U,\ h$")
    what = r"$U(\theta)$" if level.pole else r"$U(\gamma_3)$"
    label_box = {"facecolor": "white", "edgecolor": "none", "alpha": 0.85, "pad": 1.5}
    ax.text(
        0.01,
        0.95,
        what + r" and the levels $h$",
        transform=ax.transAxes,
        va="top",
        fontsize=8,
        zorder=5,
        bbox=label_box,
    )


def _levels(level: Level, h_levels: Sequence[float] | None) -> list[float]:
    return default_h_levels(level) if h_levels is None else sorted(map(float, h_levels))


def draw_portrait(
    ax: Axes | None,
    level: Level,
    h_levels: Sequence[float] | None = None,
    *,
    show_contact: bool = True,
    legend: bool = True,
) -> Axes:
    """The phase portrait's upper panel on ``ax``: the orbits at ``h_levels`` (default
    :func:`default_h_levels`), the separatrices, the steady motions and, with
    ``show_contact``, the shading where the normal force would be negative; with ``legend``,
    its legend on ``ax`` (:func:`phase_portrait` puts it below the figure). Returns ``ax``
    (``None``: a new figure's, :func:`~rollingtop.plot._axes.axes_for`)."""
    ax = axes_for(ax, (6.4, 5.2))
    levels = _levels(level, h_levels)
    _draw_orbits(ax, level, levels, steady_motions(level), show_contact)
    ax.set_xlabel(_XLABEL[bool(level.pole)])
    if legend:
        ax.legend(fontsize=7, loc="upper right", framealpha=0.9)
    return ax


def draw_potential(
    ax: Axes | None,
    level: Level,
    h_levels: Sequence[float] | None = None,
    *,
    window: tuple[float, float] | None = None,
    mark_steady: bool = True,
) -> Axes:
    """The phase portrait's lower panel on ``ax``: ``U`` and the energies ``h_levels``
    (default :func:`default_h_levels`), over ``window`` of the abscissa (default: the
    portrait's, the extent of those energies' orbits); with ``mark_steady``, each steady
    motion at its ``U`` (centres dots, saddles crosses). Returns ``ax`` (``None``: a new
    figure's)."""
    ax = axes_for(ax, (6.4, 3.6))
    levels = _levels(level, h_levels)
    motions = steady_motions(level)
    if window is None:
        g_lo, g_hi, _ = portrait_curves(level, levels, motions=motions).window
        window = (g_lo, g_hi)
    _draw_potential(ax, level, levels, motions, window)
    if mark_steady:
        _mark_steady(ax, level, motions, window, on_potential=True)
    ax.set_xlim(*window)
    return ax


def phase_portrait(
    level: Level,
    h_levels: Sequence[float] | None = None,
    *,
    show_contact: bool = True,
    figsize: tuple[float, float] = (7.0, 7.5),
) -> Figure:
    """Phase portrait on a level set (the meridian model's ``(M3, C1, C2)``, or another model's
    :class:`~rollingtop.reduction.LevelSet`): orbits at ``h_levels``, separatrices,
    steady motions, the effective potential below (:func:`draw_portrait` above
    :func:`draw_potential`).

    Parameters
    ----------
    level : LevelSet
    h_levels : sequence of float, optional
        Energies of the orbits drawn; default :func:`default_h_levels`.
    show_contact : bool
        Shade where the normal force of the plane would be negative.

    Returns
    -------
    matplotlib.figure.Figure
    """
    motions = steady_motions(level)
    levels = _levels(level, h_levels)
    fig = Figure(figsize=figsize, layout="constrained")
    ax, axu = fig.subplots(2, 1, height_ratios=[3, 1.3], sharex=True)
    window = _draw_orbits(ax, level, levels, motions, show_contact)
    fig.legend(
        *ax.get_legend_handles_labels(),
        loc="outside lower center",
        ncols=3,
        fontsize=8,
        frameon=False,
    )
    _draw_potential(axu, level, levels, motions, window)
    return fig
