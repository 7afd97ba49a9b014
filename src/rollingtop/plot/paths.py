"""Figures of a simulated motion: paths on the plane, time series, model comparison."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rollingtop.plot._axes import axes_for

if TYPE_CHECKING:
    from rollingtop.absolute import PeriodMap
    from rollingtop.trajectory import Trajectory

__all__ = [
    "PANELS",
    "compare_figure",
    "draw_drift",
    "draw_gamma3",
    "draw_path",
    "draw_reactions",
    "path_figure",
    "timeseries_figure",
]


def _title(traj: Trajectory) -> str:
    b = traj.body
    return (
        f"{traj.model.name} model, t = 0 .. {traj.t[-1]:g}   "
        rf"($R={b.R:g},\ m={b.m:g},\ g={b.g:g},\ a_3={b.a3:g},\ I_1={b.I1:g},\ I_3={b.I3:g}$)"
    )


def draw_path(ax: Axes | None, traj: Trajectory, period_map: PeriodMap | None = None) -> Axes:
    """Contact-point and CoM paths on the plane, on ``ax`` (:func:`path_figure`). Returns
    ``ax`` (``None``: a new figure's, :func:`~rollingtop.plot._axes.axes_for`)."""
    ax = axes_for(ax, (6.4, 6.4))
    cp, com = traj.contact_point, traj.position
    ax.plot(cp[:, 0], cp[:, 1], color="0.55", lw=0.6, label="contact point")
    ax.plot(com[:, 0], com[:, 1], color="#1f77b4", lw=0.9, label="centre of mass")
    ax.plot(*com[0], "s", color="black", ms=5, label="start")
    if len(traj.event_t):
        P = traj.event_y[:, 15:17]
        ax.plot(
            P[:, 0],
            P[:, 1],
            "o",
            color="#ff7f0e",
            ms=4,
            zorder=4,
            label="CoM once per period (min of $\\gamma_3$)",
        )
        if period_map is not None and period_map.motion == "bounded":
            c, radius = period_map.center_from(traj.event_y[0, 17], P[0]), period_map.radius
            assert c is not None and radius is not None  # a bounded motion has its circle
            phi = np.linspace(0, 2 * np.pi, 400)
            ax.plot(
                c[0] + radius * np.cos(phi),
                c[1] + radius * np.sin(phi),
                "--",
                color="#ff7f0e",
                lw=0.8,
                label="predicted circle",
            )
            ax.plot(*c, "+", color="#ff7f0e", ms=10, mew=1.5)
        elif period_map is not None:
            assert period_map.drift_velocity is not None  # a drifting motion has its velocity
            vx, vy = period_map.drift_velocity
            psi0 = traj.event_y[0, 17]
            v = complex(vx, vy) * np.exp(1j * psi0)
            span = traj.t[-1] - traj.event_t[0]
            ax.plot(
                [P[0, 0], P[0, 0] + v.real * span],
                [P[0, 1], P[0, 1] + v.imag * span],
                "--",
                color="#ff7f0e",
                lw=0.8,
                label="predicted drift",
            )
    kind = ""
    if period_map is not None:
        if period_map.motion == "bounded":
            kind = f"\nbounded: circle of radius {period_map.radius:.4g}" + (
                " (near-resonant)" if period_map.near_resonant else ""
            )
        else:
            assert period_map.drift_velocity is not None  # a drifting motion has its velocity
            kind = f"\ndrifting at {np.hypot(*period_map.drift_velocity):.4g}"
        kind += rf", $\Delta\psi = {period_map.delta_psi:.6g}$ per period {period_map.period:.6g}"
    ax.set_title(_title(traj) + kind, fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("X")
    ax.set_ylabel("Y")
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    return ax


def path_figure(
    traj: Trajectory,
    period_map: PeriodMap | None = None,
    *,
    figsize: tuple[float, float] = (7.0, 7.0),
) -> Figure:
    """Contact-point and CoM paths on the plane (:func:`draw_path`).

    Parameters
    ----------
    traj : Trajectory
        If it carries events (rising zeros of ``w_tau``: the minima of ``gamma3``), the CoM's
        once-per-period positions are marked.
    period_map : PeriodMap, optional
        Draws the predicted circle of the once-per-period positions (bounded motion) or the drift
        direction, anchored at the first event.
    """
    fig = Figure(figsize=figsize, layout="constrained")
    draw_path(fig.subplots(), traj, period_map)
    return fig


def draw_gamma3(ax: Axes | None, traj: Trajectory) -> Axes:
    """``gamma3(t)`` on ``ax``, titled with the model and body (:func:`timeseries_figure`'s
    first panel). Returns ``ax`` (``None``: a new figure's)."""
    ax = axes_for(ax, (6.4, 3.2))
    ax.plot(traj.t, traj.gamma[:, 2], color="black", lw=0.9)
    ax.set_xlabel("t")
    ax.set_ylabel(r"$\gamma_3$")
    ax.set_title(_title(traj), fontsize=9)
    return ax


def draw_drift(ax: Axes | None, traj: Trajectory) -> Axes:
    """Each first integral's relative drift ``|I - I0| / max |I|`` along the samples, on a log
    scale (:func:`timeseries_figure`'s second panel). Returns ``ax`` (``None``: a new
    figure's)."""
    ax = axes_for(ax, (6.4, 3.2))
    for name, values in traj.integrals.items():
        scale = max(np.max(np.abs(values)), 1e-300)
        drift = np.abs(values - values[0]) / scale
        ax.semilogy(traj.t, np.maximum(drift, 1e-17), lw=0.8, label=name)
    ax.set_xlabel("t")
    ax.set_ylabel("relative drift of\nthe first integrals")
    ax.legend(fontsize=7, ncols=3, loc="upper left")
    ax.set_ylim(1e-17, None)
    return ax


def draw_reactions(ax: Axes | None, traj: Trajectory) -> Axes:
    """The normal and tangential forces along the samples, the loss of contact marked, and the
    friction coefficient the motion needs (:func:`timeseries_figure`'s third panel). Returns
    ``ax`` (``None``: a new figure's)."""
    ax = axes_for(ax, (6.4, 3.2))
    t = traj.t
    ax.plot(t, traj.normal_force, color="#1f77b4", lw=0.9, label="normal force N")
    ax.plot(t, traj.tangential_force, color="#d62728", lw=0.9, label="tangential force T")
    ax.axhline(0, color="0.6", lw=0.6)
    lost = traj.contact_lost_at
    if lost is not None:
        ax.axvline(lost, color="black", ls="--", lw=0.8, label=f"contact lost, t = {lost:.4g}")
    ax.set_ylabel("reactions")
    ax.set_xlabel("t")
    ax.legend(fontsize=7, loc="upper left")
    ratio = np.nanmax(traj.friction_ratio) if np.any(traj.normal_force > 0) else np.nan
    ax.set_title(f"friction coefficient needed (max T/N at the samples): {ratio:.4g}", fontsize=8)
    return ax


#: What :meth:`rollingtop.Trajectory.plot` draws for each ``kind``.
PANELS = {
    "path": draw_path,
    "gamma3": draw_gamma3,
    "drift": draw_drift,
    "reactions": draw_reactions,
}


def timeseries_figure(traj: Trajectory, *, figsize: tuple[float, float] = (8.0, 8.0)) -> Figure:
    """``gamma3(t)``, the first integrals' relative drift, and the contact reactions
    (:func:`draw_gamma3`, :func:`draw_drift`, :func:`draw_reactions`)."""
    fig = Figure(figsize=figsize, layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    for ax, draw in ((ax1, draw_gamma3), (ax2, draw_drift), (ax3, draw_reactions)):
        draw(ax, traj)
    for ax in (ax1, ax2):
        ax.set_xlabel("")  # the panels share the lowest one's time axis
    return fig


def compare_figure(
    runs: dict[str, Trajectory], *, figsize: tuple[float, float] = (10.0, 8.0)
) -> Figure:
    """Paths and integrals of the same initial state under several contact models.

    ``runs``: ``{model name: Trajectory}`` (:func:`rollingtop.simulate_models`). Left: CoM paths.
    Right: each integral that some model conserves, relative to its initial value, for every
    model -- flat exactly where the model conserves it.
    """
    from rollingtop.dynamics.integrals import evaluate

    fig = Figure(figsize=figsize, layout="constrained")
    grid = fig.add_gridspec(4, 2)
    ax = fig.add_subplot(grid[:, 0])
    names: list[str] = []
    for run in runs.values():
        names += [n for n in run.integrals if n not in names]
    shown = [n for n in ("energy", "F6", "momentum_x", "routh") if n in names] or names[:4]
    axes = [fig.add_subplot(grid[i, 1]) for i in range(len(shown))]
    for model, run in runs.items():
        colour = run.model.colour
        ax.plot(run.position[:, 0], run.position[:, 1], lw=0.9, color=colour, label=model)
        ax.plot(*run.position[0], "s", color="black", ms=4)
        values = evaluate(run.body, run.y, shown, pole=run.pole_case, model=run.model)
        for a, name in zip(axes, shown, strict=True):
            v = values[name]
            scale = max(abs(v[0]), 1e-300)
            conserved = name in run.integrals
            a.plot(
                run.t,
                (v - v[0]) / scale,
                color=colour,
                lw=1.6 if conserved else 0.9,
                ls="-" if conserved else "--",
                label=f"{model}" + (" (conserved)" if conserved else ""),
            )
    for a, name in zip(axes, shown, strict=True):
        a.set_ylabel(f"{name}:\n(I - I0)/|I0|", fontsize=8)
        a.legend(fontsize=7, loc="upper left")
        a.grid(alpha=0.3)
    if axes:
        axes[-1].set_xlabel("t")
    first = next(iter(runs.values()))
    ax.set_title("CoM paths, same initial state\n" + _title(first).split("   ")[1], fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("X")
    ax.set_ylabel("Y")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig
