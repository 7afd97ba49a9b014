"""Regenerate docs/parallel_cases.png: Poincare sections (w_tau = 0 upward) of the companion
(parallel) model's particular cases found by rollingtop.symbolic.parallel.

(a) a3 = 0, I3 = I1 (examples/parallel_balanced.toml): the slip along nu is a third integral,
    so the level (energy, Jellett, slip) is two-dimensional and the section a curve; there is
    still no invariant measure, and the points run along the curve into a steady spin about
    the tilted axis (w_tau = w_n = 0), where the crossings stop.
(b, c) near the Euler-Jacobi limit I3 -> 0 (examples/parallel_axial.toml, I3 = 1e-4): in the
    plane (w3, v_nu) every trajectory's crossings lie on a closed invariant curve; in the plane
    (gamma3, w_n) they shrink towards one point per trajectory (at I3 = 0 the axis moves on
    its own 1-degree-of-freedom level of h0 and Jellett, as a heavy top's axis does).
Run: python docs/parallel_cases.py (about 10 s)."""

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rollingtop.chaos import poincare_section
from rollingtop.plot import save_figure
from rollingtop.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]


def _section(name, trajectories, crossings, t_max):
    sc = load_scenario(ROOT / "examples" / f"{name}.toml")
    ds = poincare_section(sc.body, sc.model, sc.require_state(), crossings=crossings,
                          trajectories=trajectories, t_max=t_max, seed=0)  # fmt: skip
    return sc, ds


def _v_nu(states):
    """(v, nu) of states, shape (..., 18) -> (...)."""
    g = states[..., 12:15]
    s = np.hypot(g[..., 0], g[..., 1])
    nu = np.stack([-g[..., 2] * g[..., 0], -g[..., 2] * g[..., 1], s * s], axis=-1) / s[..., None]
    return np.sum(states[..., 0:3] * nu, axis=-1)


def main():
    fig = Figure(figsize=(13.5, 4.4), layout="constrained")
    axes = fig.subplots(1, 3)
    colours = [f"C{k % 10}" for k in range(64)]
    sc, ds = _section("parallel_balanced", 24, 300, 1000.0)
    ax = axes[0]
    for k in range(ds.sizes["trajectory"]):
        n = int(ds["n_crossings"][k])
        ax.plot(ds["gamma3"][k, :n], ds["w_n"][k, :n], ".", ms=3, color=colours[k])
    ax.set(xlabel=r"$\gamma_3$ at the crossing", ylabel=r"$\omega_n$",
           title="(a) a3 = 0, I3 = I1: slip along nu conserved\n"
                 f"{int(ds['n_crossings'].sum())} crossings of {ds.sizes['trajectory']} "
                 "trajectories, t <= 1000")  # fmt: skip
    ax.text(0.03, 0.03, "points run along the curve into a steady spin\n(w_tau = w_n = 0), "
            "then cross no more", transform=ax.transAxes, fontsize=8)  # fmt: skip
    sc, ds = _section("parallel_axial", 12, 300, 5000.0)
    states = ds["crossing_state"].values
    for k in range(ds.sizes["trajectory"]):
        n = int(ds["n_crossings"][k])
        axes[1].plot(states[k, :n, 5], _v_nu(states[k, :n]), ".", ms=1.5, color=colours[k])
        axes[2].plot(ds["gamma3"][k, :n], ds["w_n"][k, :n], ".", ms=1.5, color=colours[k])
    axes[1].set(xlabel=r"$\omega_3$ at the crossing", ylabel=r"$v_\nu$",
                title="(b) I3 = 1e-4 (limit I3 -> 0): invariant curves\n"
                      "12 trajectories x 300 crossings, same energy and Jellett")  # fmt: skip
    axes[2].set(xlabel=r"$\gamma_3$ at the crossing", ylabel=r"$\omega_n$",
                title="(c) the same crossings in (gamma3, w_n):\n"
                      "one point per trajectory at I3 = 0")  # fmt: skip
    b = sc.body
    fig.suptitle(
        "Companion model (parallel): particular cases.  (a) R = m = g = 1, I1 = I3 = 0.4;"
        f"  (b, c) R = m = g = 1, a3 = {b.a3:g}, I1 = {b.I1:g}, I3 = {b.I3:g}"
    )
    save_figure(fig, ROOT / "docs" / "parallel_cases.png")


if __name__ == "__main__":
    main()
