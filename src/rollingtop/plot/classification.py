"""The reduced models side by side (:func:`rollingtop.reduction.classify.classify_models`): for
one body started one way, each integrable model's effective potential, phase portrait and
critical values, with the state marked."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rollingtop.contact import get_model
from rollingtop.reduction.classify import CriticalValues, ModelClassification, RotationGrid
from rollingtop.reduction.level import Level

__all__ = ["classification_figure", "critical_values_figure", "rotation_grid_figure"]

FloatArray: TypeAlias = NDArray[np.float64]
#: Labels of the integrals in the figure (mathtext).
SYMBOLS = {
    "M3": "M_3",
    "C1": "C_1",
    "C2": "C_2",
    "p_horizontal": r"p_{\rm h}",
    "jellett": r"\mathrm{jellett}",
    "routh": r"\mathrm{routh}",
    "rubber_spin": r"\mathrm{rubber\_spin}",
}


def _window(c: ModelClassification) -> tuple[float, float, float, float]:
    """``gamma3`` and ``U`` limits: the orbit through the state and the steady motions, with a
    margin."""
    g = [float(c.state[14])] + [m.gamma3 for m in c.steady]
    if c.orbit is not None:
        g += [c.orbit.gamma3_min, c.orbit.gamma3_max]
    lo, hi = min(g), max(g)
    pad = max(0.15 * (hi - lo), 0.05)
    g_lo, g_hi = max(-0.999, lo - pad), min(0.999, hi + pad)
    u_min = min([c.h] + [m.U for m in c.steady])
    span = max(c.h - u_min, 1e-3)
    return g_lo, g_hi, u_min - 0.2 * span, c.h + 0.8 * span


def classification_figure(classes: Sequence[ModelClassification]) -> Figure:
    """One column per model: ``U(gamma3)`` with the state's ``h``, the phase portrait
    ``(gamma3, w_tau)`` with the orbit through the state, and the critical values of the
    reduced energy along the model's axis integral with the state's level marked.

    Parameters
    ----------
    classes : sequence of ModelClassification

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = len(classes)
    fig = Figure(figsize=(3.6 * n + 0.4, 9.6), layout="constrained")
    axes = fig.subplots(3, n, squeeze=False)
    for j, c in enumerate(classes):
        colour = get_model(c.model).colour
        level = c.level
        g_lo, g_hi, u_lo, u_hi = _window(c)
        gamma3 = np.linspace(g_lo, g_hi, 600)
        theta = np.arccos(gamma3)
        U = np.asarray(level.U(theta), dtype=float)
        ax = axes[0, j]
        ax.plot(gamma3, U, color=colour, lw=1.6)
        ax.axhline(c.h, color="0.3", lw=0.8, ls="--", label="h of the state")
        ax.plot([c.state[14]], [c.h], "k*", ms=9, label="the state")
        for m in c.steady:
            ax.plot([m.gamma3], [m.U], "o" if m.type == "center" else "x", color="k", ms=5)
        ax.set_ylim(u_lo, u_hi)
        ax.set_xlim(g_lo, g_hi)
        named = r",\ ".join(f"{SYMBOLS.get(k, k)}={v:.4g}" for k, v in level.values().items())
        ax.set_title(f"{c.model}\n${named}$", fontsize=9)
        ax.set_xlabel(r"$\gamma_3$")
        if j == 0:
            ax.set_ylabel(r"$U(\gamma_3)$")
            ax.legend(fontsize=7, loc="upper center", frameon=False)
        # the phase portrait: level curves of h on (gamma3, w_tau), the state's own in black
        ax = axes[1, j]
        w_top = 1.3 * math.sqrt(
            max(2 * (u_hi - float(np.min(U))), 1e-6) / float(np.min(level.rho(theta)))
        )
        w = np.linspace(-w_top, w_top, 301)
        G, Wt = np.meshgrid(gamma3, w)
        H = np.asarray(level.energy(np.arccos(G), Wt), dtype=float)
        ax.contour(
            G,
            Wt,
            H,
            levels=np.linspace(u_lo, u_hi, 12)[1:],
            colors=colour,
            linewidths=0.6,
            alpha=0.7,
        )
        ax.contour(G, Wt, H, levels=[c.h], colors="k", linewidths=1.5)
        ax.plot([c.state[14]], [_w_tau(c.state)], "k*", ms=9)
        ax.set_xlabel(r"$\gamma_3$")
        if j == 0:
            ax.set_ylabel(r"$\omega_\tau$")
        # the critical values along the axis integral
        ax = axes[2, j]
        cv = c.critical
        _draw_critical(ax, cv, colour)
        ax.plot([level.values()[cv.axis]], [c.h], "k*", ms=9, label="the state's level")
        ax.set_xlabel(f"${SYMBOLS.get(cv.axis, cv.axis)}$")
        if j == 0:
            ax.set_ylabel("critical values of $h$")
            ax.legend(fontsize=7, frameon=False)
        fixed = ", ".join(f"{k} = {v:.3g}" for k, v in cv.fixed.items())
        ax.set_title(
            f"at {fixed}" if fixed else f"{cv.axis}: the level's only integral", fontsize=8
        )
    return fig


def _w_tau(y: FloatArray) -> float:
    """``w_tau = (w, tau)``, ``tau = e3 x gamma / s``, of the state ``y`` (body frame); 0 at a
    vertical axis (``s = 0``, where the orbit is a point)."""
    g = y[12:15]
    s = math.hypot(g[0], g[1])
    return 0.0 if s == 0.0 else float((-g[1] * y[3] + g[0] * y[4]) / s)


def _draw_critical(ax: Any, cv: CriticalValues, colour: str) -> None:
    """The critical values of ``cv`` on ``ax``: centres as dots, saddles as crosses."""
    pts = cv.points
    for kind, marker, label in ((1.0, "o", "centre"), (-1.0, "x", "saddle")):
        sel = pts[:, 3] == kind
        ax.plot(
            pts[sel, 0],
            pts[sel, 2],
            marker,
            color=colour if kind > 0 else "k",
            ms=2.5,
            ls="none",
            label=label,
        )


def critical_values_figure(cv: CriticalValues, level: Level, mark: bool = True) -> Figure:
    """The critical values of a reduced model's energy along its axis integral
    (:func:`rollingtop.reduction.classify.critical_values`), the level's own value marked
    (unless ``mark`` is false: a level that left the axis out); below, the number of steady
    motions along the axis."""
    fig = Figure(figsize=(6.4, 5.6), layout="constrained")
    ax, axn = fig.subplots(2, 1, height_ratios=[3, 1], sharex=True)
    _draw_critical(ax, cv, get_model(cv.model).colour)
    if mark:
        ax.axvline(level.values()[cv.axis], color="0.5", lw=0.8, ls="--", label="the level's value")
    ax.set_ylabel("critical values of $h$")
    fixed = ", ".join(f"{k} = {v:.4g}" for k, v in cv.fixed.items())
    ax.set_title(f"{cv.model} model" + (f", at {fixed}" if fixed else ""), fontsize=10)
    ax.legend(fontsize=8, frameon=False)
    ok = cv.count >= 0
    axn.step(cv.x[ok], cv.count[ok], where="mid", color="k")
    axn.set_ylabel("steady motions")
    axn.set_xlabel(f"${SYMBOLS.get(cv.axis, cv.axis)}$")
    return fig


def rotation_grid_figure(grid: RotationGrid) -> Figure:
    """The rotation number ``N`` of the first periodic orbit of each level over the model's axis
    integral and ``h`` (:func:`rollingtop.reduction.classify.rotation_grid`)."""
    fig = Figure(figsize=(6.4, 5.0), layout="constrained")
    ax = fig.subplots()
    mesh = ax.pcolormesh(grid.x, grid.h, grid.N[:, :, 0], shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=r"$N = \Delta\psi / 2\pi$ (first orbit)")
    ax.set_xlabel(f"${SYMBOLS.get(grid.axis, grid.axis)}$")
    ax.set_ylabel("$h$")
    fixed = ", ".join(f"{k} = {v:.4g}" for k, v in grid.fixed.items())
    ax.set_title(f"{grid.model} model" + (f", at {fixed}" if fixed else ""), fontsize=10)
    return fig
