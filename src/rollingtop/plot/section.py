"""Poincare sections (:func:`rollingtop.chaos.poincare_section`) and the chaos indicators'
time series (:func:`rollingtop.chaos.chaos_indicators`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

if TYPE_CHECKING:
    import xarray as xr

    from rollingtop.chaos.lyapunov import ChaosIndicators

__all__ = ["indicators_figure", "section_figure"]

#: Crossings of a trajectory closer than this in both coordinates count as one point...
SAME_POINT = 1e-6
#: ... drawn with this marker size.
SINGLE_SIZE = 6.0


def section_figure(ds: xr.Dataset, *, marker_size: float = 0.6) -> Figure:
    """The crossings in the plane ``(gamma3, w_n)``, one colour per trajectory; a trajectory
    whose normal force turns negative at some time (the body would leave the plane: the model
    keeps the contact) is drawn with open circles and counted in the title."""
    fig = Figure(figsize=(7.0, 5.6))
    ax = fig.add_subplot()
    K = ds.sizes["trajectory"]
    cmap = colormaps["turbo"]
    lost = ds["min_normal_force"].values < 0
    for k in range(K):
        g3 = ds["gamma3"].values[k]
        wn = ds["w_n"].values[k]
        ok = np.isfinite(g3)
        if not ok.any():
            continue
        # a trajectory whose crossings coincide (the paper's model: one point per orbit) is
        # drawn as one visible dot
        single = max(np.ptp(g3[ok]), np.ptp(wn[ok])) < SAME_POINT
        colour = cmap((k + 0.5) / K)
        if lost[k]:
            ax.plot(
                g3[ok],
                wn[ok],
                "o",
                ms=SINGLE_SIZE if single else 4 * marker_size,
                mfc="none",
                mec=colour,
                mew=0.4,
                rasterized=True,
            )
        else:
            ax.plot(
                g3[ok],
                wn[ok],
                ".",
                ms=SINGLE_SIZE if single else marker_size,
                color=colour,
                rasterized=True,
            )
    ax.set_xlabel(r"$\gamma_3$ at the crossing")
    ax.set_ylabel(r"$\omega_n = (\omega, n)$")
    held = ds.attrs["held"].replace(",", ", ")
    energy = float(ds["level_energy"].values[0])
    found = int(ds["n_crossings"].sum())
    ax.set_title(
        f"Poincare section w_tau = 0 (upward), model {ds.attrs['model']}\n"
        f"E = {energy:.6g}; held: {held}; {K} trajectories, {found} crossings"
        + (f"; {int(lost.sum())} lose contact (open circles)" if lost.any() else ""),
        fontsize=9,
    )
    body = ", ".join(f"{k[5:]} = {ds.attrs[k]:g}" for k in ds.attrs if k.startswith("body_"))
    ax.text(0.01, 0.01, body, transform=ax.transAxes, fontsize=7, color="0.35")
    return fig


def indicators_figure(result: ChaosIndicators) -> Figure:
    """Finite-time maximal Lyapunov exponent against time (log-log, with ``ln t / t`` for
    comparison) and MEGNO ``Y(t)`` with its running mean ``<Y>(t)`` (2: quasi-periodic)."""
    fig = Figure(figsize=(11.0, 4.2))
    ax1, ax2 = fig.subplots(1, 2)
    t = result.t
    lam = result.lyapunov
    ax1.loglog(t, np.abs(lam), lw=1.0, label=r"$|\lambda(t)|$")
    ax1.loglog(t, np.log(t) / t, "k--", lw=0.8, label=r"$\ln t / t$")
    ax1.set_xlabel("t")
    ax1.set_ylabel("finite-time maximal Lyapunov exponent")
    ax1.legend(fontsize=8)
    ax2.plot(t, result.megno, lw=0.6, alpha=0.6, label="Y(t)")
    ax2.plot(t, result.megno_mean, lw=1.2, label="<Y>(t)")
    ax2.axhline(2.0, color="k", ls="--", lw=0.8)
    ax2.set_xlabel("t")
    ax2.set_ylabel("MEGNO")
    ax2.legend(fontsize=8)
    fig.suptitle(
        f"model {result.model.name}: lambda(t_end) = {lam[-1]:.4g}, "
        f"<Y>(t_end) = {result.megno_mean[-1]:.4g}",
        fontsize=10,
    )
    fig.tight_layout()
    return fig
