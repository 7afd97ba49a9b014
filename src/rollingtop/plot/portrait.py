"""Phase portraits of the reduced system in the plane ``(gamma3, w_tau)`` (paper Fig. 5).

Each orbit is drawn from its exact parametrisation, not from a contoured grid: between its
turning points ``theta = c + d sin(phi)`` and ``w_tau = +-sqrt(2 (h - U) / rho)``, so curves close
exactly at the turning points and the separatrices pass exactly through the saddles. Where the
normal reaction of the plane would be negative (the body would jump: the model does not apply)
the plane is shaded.

In a pole case (``C1 = +-M3``) orbits pass through the pole, where the paper's ``tau`` and
``w_tau`` change sign; there the horizontal axis is the signed nutation angle ``theta``
(``gamma3 = cos theta``, see :mod:`rollingtop.reduction.level`), in which the flow is regular.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeAlias

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rollingtop.reduction import (
    LevelSet,
    LevelSetError,
    Orbit,
    orbits,
    steady_motions,
)
from rollingtop.reduction._quadrature import energy_gap
from rollingtop.reduction.level import Real

__all__ = ["phase_portrait", "default_h_levels"]

FloatArray: TypeAlias = NDArray[np.float64]


def default_h_levels(level: LevelSet, count: int = 10) -> list[float]:
    """``count`` energies from just above the lowest steady motion to half again past the highest
    saddle (or, without saddles, a band above the minimum), plus the saddles' levels."""
    motions = steady_motions(level)
    if not motions:
        raise LevelSetError(f"no steady motion on {level.describe()}: U has no minimum")
    u_min = min(m.U for m in motions)
    saddles = [m.U for m in motions if m.type == "saddle"]
    if saddles:
        top = max(saddles) + 0.5 * (max(saddles) - u_min)
    else:
        grid = np.linspace(*level.theta_domain, 2001)[200:-200]
        top = u_min + 0.5 * (float(np.median(level.U(grid))) - u_min)
    levels = u_min + (top - u_min) * (np.arange(1, count + 1) / count) ** 1.5
    return sorted({*map(float, levels), *saddles})


def _abscissa(level: LevelSet, theta: Real) -> Real:
    """``gamma3 = cos(theta)``, or ``theta`` itself in a pole case (same shape)."""
    if level.pole:
        return theta
    x: Real = np.cos(theta)
    return x


def _orbit_curve(
    level: LevelSet, h: float, orbit: Orbit, n: int = 400
) -> tuple[FloatArray, FloatArray]:
    """The closed curve ``(abscissa, w_tau)`` of ``orbit`` at energy ``h``, each of shape
    ``(2 n,)`` (rolling over: two branches of ``2 n`` points joined by a NaN)."""
    t1, t2 = orbit.theta_min, orbit.theta_max
    if orbit.rolls_over:
        # rolling over (no spin): theta runs round the circle; draw w_tau > 0 and < 0 branches
        # over the plotted window, separated by a NaN so that they are not joined
        theta = np.linspace(*level.theta_domain, 2 * n)
        w = level.w_tau(theta, h)
        return np.concatenate([theta, [np.nan], theta]), np.concatenate([w, [np.nan], -w])
    phi = np.linspace(-math.pi / 2, math.pi / 2, n)
    theta = (t1 + t2) / 2 + (t2 - t1) / 2 * np.sin(phi)
    w = level.w_tau(theta, h, gap=energy_gap(level, h, t1, t2, phi))
    x = _abscissa(level, theta)
    return np.concatenate([x, x[::-1]]), np.concatenate([w, -w[::-1]])


def _normal_force_grid(level: LevelSet, g3: FloatArray, w: FloatArray) -> FloatArray:
    """Normal reaction at the states ``(gamma3, w_tau)`` of the level set, shape (nw, ng), in
    closed form (:meth:`rollingtop.reduction.LevelSet.normal_force`; no compiled code)."""
    G, Wt = np.meshgrid(g3, w, indexing="ij")
    N: FloatArray = level.normal_force(np.arccos(G), Wt).T
    return N


def phase_portrait(
    level: LevelSet,
    h_levels: Sequence[float] | None = None,
    *,
    show_contact: bool = True,
    figsize: tuple[float, float] = (7.0, 7.5),
) -> Figure:
    """Phase portrait on a level set (the meridian model's ``(M3, C1, C2)``, or another model's
    :class:`~rollingtop.reduction.LevelSet`): orbits at ``h_levels``, separatrices,
    steady motions, the effective potential below.

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
    body = level.body
    motions = steady_motions(level)
    levels = default_h_levels(level) if h_levels is None else sorted(map(float, h_levels))
    saddle_levels = {m.U for m in motions if m.type == "saddle"}
    fig = Figure(figsize=figsize, layout="constrained")
    ax, axu = fig.subplots(2, 1, height_ratios=[3, 1.3], sharex=True)
    cmap = fig.colormaps["viridis"] if hasattr(fig, "colormaps") else None
    if cmap is None:
        import matplotlib

        cmap = matplotlib.colormaps["viridis"]
    lo_h, hi_h = min(levels), max(levels)
    g_lo, g_hi, w_top = 1.0, -1.0, 0.0
    drawn_sep = drawn = False
    for h in levels:
        try:
            comps = orbits(level, h)
        except LevelSetError:
            continue
        separatrix = any(abs(h - u) <= 1e-12 * max(1.0, abs(u)) for u in saddle_levels)
        for o in comps:
            if o.kind == "steady":
                continue
            x, y = _orbit_curve(level, h, o)
            g_lo, g_hi = min(g_lo, np.nanmin(x)), max(g_hi, np.nanmax(x))
            w_top = max(w_top, float(np.nanmax(np.abs(y))))
            if separatrix or o.kind == "separatrix":
                ax.plot(x, y, color="crimson", lw=1.8, zorder=3,
                        label=None if drawn_sep else "separatrix")  # fmt: skip
                drawn_sep = True
            else:
                frac = (h - lo_h) / (hi_h - lo_h) if hi_h > lo_h else 0.5
                ax.plot(x, y, color=cmap(0.1 + 0.8 * frac), lw=1.0, zorder=2,
                        label=None if drawn else "orbits (colour: h)")  # fmt: skip
                drawn = True
    if g_lo > g_hi:
        raise LevelSetError(f"no motion on {level.describe()} at the requested h levels")
    pad = 0.05 * (g_hi - g_lo) + 1e-3
    if level.pole:
        g_lo, g_hi = max(level.theta_domain[0], g_lo - pad), min(level.theta_domain[1], g_hi + pad)
    else:
        g_lo, g_hi = max(-1.0, g_lo - pad), min(1.0, g_hi + pad)
    w_top *= 1.1
    if show_contact and not level.pole:
        gg = np.linspace(max(g_lo, -0.999), min(g_hi, 0.999), 90)
        ww = np.linspace(-w_top, w_top, 80)
        N = _normal_force_grid(level, gg, ww)
        if np.any(N < 0):
            ax.contourf(gg, ww, N, levels=[N.min() - 1, 0.0], colors=["#f4c7c3"], zorder=1)
            ax.plot([], [], color="#f4c7c3", lw=6, label="normal force < 0 (contact lost)")
    for m in motions:
        xm = float(_abscissa(level, m.theta))
        if not g_lo <= xm <= g_hi:
            continue
        if m.type == "center":
            ax.plot(xm, 0, "o", color="black", ms=5, zorder=4)
        else:
            ax.plot(xm, 0, "x", color="crimson", ms=8, mew=2, zorder=4)
    for pole_theta in level.pole_thetas:
        ax.axvline(pole_theta, color="0.5", ls="--", lw=0.8, zorder=0)
    if level.pole:
        names = {"south": "south pole (gamma3 = +1)", "north": "north pole (gamma3 = -1)",
                 "both": "poles (gamma3 = +1 at 0, -1 at pi)"}  # fmt: skip
        ax.plot([], [], color="0.5", ls="--", lw=0.8, label=names[level.pole])
    ax.plot([], [], "o", color="black", ms=5, label="steady motion (centre)")
    if saddle_levels:
        ax.plot([], [], "x", color="crimson", ms=8, mew=2, label="steady motion (saddle)")
    ax.set_xlim(g_lo, g_hi)
    ax.set_ylim(-w_top, w_top)
    ax.set_ylabel(r"$\omega_\tau$")
    ax.axhline(0, color="0.85", lw=0.6, zorder=0)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncols=3, fontsize=8,
               frameon=False)  # fmt: skip
    pole = {None: "", "south": ", south pole case", "north": ", north pole case",
            "both": ", no spin: both poles"}[level.pole]  # fmt: skip
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
    # effective potential with the h levels
    if level.pole:
        g = np.linspace(g_lo, g_hi, 1500)
        U = level.U(g)
    else:
        g = np.linspace(max(g_lo, -0.9999), min(g_hi, 0.9999), 1500)
        U = level.U_gamma3(g)
    axu.plot(g, U, color="black", lw=1.2)
    for h in levels:
        sep = any(abs(h - u) <= 1e-12 * max(1.0, abs(u)) for u in saddle_levels)
        frac = (h - lo_h) / (hi_h - lo_h) if hi_h > lo_h else 0.5
        axu.axhline(h, color="crimson" if sep else cmap(0.1 + 0.8 * frac), lw=0.8)
    u_min = min((m.U for m in motions), default=float(np.min(U)))
    axu.set_ylim(u_min - 0.05 * (hi_h - u_min), hi_h + 0.15 * (hi_h - u_min))
    axu.set_xlabel(r"$\theta$ (signed nutation angle, $\gamma_3 = \cos\theta$)"
                   if level.pole else r"$\gamma_3$")  # fmt: skip
    axu.set_ylabel(r"$U,\ h$")
    what = r"$U(\theta)$" if level.pole else r"$U(\gamma_3)$"
    label_box = {"facecolor": "white", "edgecolor": "none", "alpha": 0.85, "pad": 1.5}
    axu.text(0.01, 0.95, what + r" and the levels $h$", transform=axu.transAxes, va="top",
             fontsize=8, zorder=5, bbox=label_box)  # fmt: skip
    return fig
