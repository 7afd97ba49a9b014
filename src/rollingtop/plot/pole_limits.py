"""Period and ``Delta psi`` across a pole level: the jump the paper's pole cases hide."""

from __future__ import annotations

import math
from typing import TypedDict

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from rollingtop.absolute import period_map
from rollingtop.body import SphericalTop
from rollingtop.reduction import LevelSet, orbits
from rollingtop.reduction.near_pole import NearPole, near_pole

__all__ = ["PoleLimits", "pole_limits_figure", "pole_limits_table"]


class PoleLimits(TypedDict):
    """What :func:`pole_limits_table` returns, per side ``+1`` (``C1 > M3``) and ``-1``."""

    #: Rows ``(|C1 - M3|, T, Delta psi, friction needed)``, shape ``(n, 4)``.
    rows: dict[int, NDArray[np.float64]]
    #: The limits on the pole level, from the side's orbits next to the wall.
    limits: dict[int, NearPole]


def pole_limits_table(
    body: SphericalTop, M3: float, C2: float, h: float, exponents: ArrayLike | None = None
) -> PoleLimits:
    """``T``, ``Delta psi`` and the friction needed on the levels ``C1 = M3 + side 10^k`` next to
    the south pole level (``k`` in ``exponents``, default ``-12, -11.5, ..., -1``), and the
    limits (:class:`PoleLimits`)."""
    exponents = np.arange(-12.0, -0.9, 0.5) if exponents is None else np.asarray(exponents)
    rows: dict[int, list[tuple[float, float, float, float]]] = {+1: [], -1: []}
    info: dict[int, NearPole] = {}
    for side in (+1, -1):
        for k in exponents:
            level = LevelSet(body, M3, M3 + side * 10.0**k, C2)
            orbit = min(orbits(level, h), key=lambda o: o.pole_distance)
            pm = period_map(level, h, orbit)
            npl = near_pole(level, h, orbit)
            rows[side].append(
                (10.0**k, orbit.period, pm.delta_psi, npl.friction_needed if npl else math.nan)
            )
            if npl is not None:
                info[side] = npl
    return {"rows": {s: np.array(r) for s, r in rows.items()}, "limits": info}


def pole_limits_figure(
    body: SphericalTop,
    M3: float,
    C2: float,
    h: float,
    *,
    figsize: tuple[float, float] = (7, 8.5),
) -> Figure:
    """Three panels against ``|C1 - M3|`` (log scale), on each side of the south pole level
    ``C1 = M3``: the period with its limit and the pole level's own period, ``Delta psi`` with its
    two limits (``2 pi`` apart) and the pole level's value, and the friction coefficient the
    constraint needs."""
    data = pole_limits_table(body, M3, C2, h)
    rows, lim = data["rows"], data["limits"]
    any_lim = lim.get(+1) or lim.get(-1)
    fig = Figure(figsize=figsize, layout="constrained")
    axT, axP, axF = fig.subplots(3, 1, sharex=True)
    style = {
        +1: dict(color="tab:blue", marker="o", label="C1 > M3"),
        -1: dict(color="tab:orange", marker="s", label="C1 < M3"),
    }
    for side, r in rows.items():
        d, T, dpsi, mu = r.T
        axT.plot(d, T, ms=3, lw=1, **style[side])
        axF.plot(d, mu, ms=3, lw=1, **style[side])
        if side in lim:
            sty = {**style[side], "label": None}
            axP.plot(d, np.abs(T - lim[side].period_limit), ms=3, lw=1, ls="-", **sty)
            sty["marker"] = "x"
            axP.plot(d, np.abs(dpsi - lim[side].delta_psi_limit), ms=4, lw=1, ls="--", **sty)
    d = rows[+1][:, 0]
    axP.plot(d, d * np.log(1 / d), color="0.4", lw=0.8, ls=":", label=r"$\delta\,\log(1/\delta)$")
    axP.plot([], [], color="0.3", marker="o", ms=3, lw=1, label=r"$|T - T_{lim}|$")
    axP.plot(
        [],
        [],
        color="0.3",
        marker="x",
        ms=4,
        lw=1,
        ls="--",
        label=r"$|\Delta\psi - \Delta\psi_{lim}|$",
    )
    if any_lim:
        axT.axhline(
            any_lim.period_limit,
            color="0.3",
            ls=":",
            lw=1,
            label=f"limit T = {any_lim.period_limit:.10g}",
        )
        axT.axhline(
            any_lim.pole_level_period,
            color="crimson",
            ls="--",
            lw=1,
            label=f"pole level C1 = M3: T = {any_lim.pole_level_period:.10g}",
        )
        limits = ", ".join(
            f"{lim[s].delta_psi_limit:.6g} (C1 {'>' if s > 0 else '<'} M3)"
            for s in (+1, -1)
            if s in lim
        )
        axP.set_title(
            rf"limits of $\Delta\psi$: {limits}; on the pole level "
            rf"$\Delta\psi$ = {any_lim.pole_level_delta_psi:.6g}",
            fontsize=8,
        )
    axT.set_ylabel("period T")
    axP.set_ylabel("distance from the limit")
    axP.set_yscale("log")
    axF.set_ylabel("friction coefficient needed")
    axF.set_yscale("log")
    axF.set_xscale("log")
    axF.set_xlabel(r"$\delta = |C_1 - M_3|$")
    for ax in (axT, axP, axF):
        ax.grid(True, which="major", color="0.9")
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(
        rf"Across the south pole level: $M_3={M3:g},\ C_2={C2:g},\ h={h:g}$; "
        rf"$a_3={body.a3:g},\ I_1={body.I1:g},\ I_3={body.I3:g}$",
        fontsize=10,
    )
    return fig
