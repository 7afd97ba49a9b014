"""Regenerate docs/megno_map.png: the mean MEGNO <Y> at t = 1000 of the companion (parallel)
model over a plane of initial conditions -- the paper's body, axis tilt gamma3 and spin omega3,
omega = (2, -0.2, omega3), v_nu = 0.1 (the chaotic motion of examples/parallel_chaotic.toml is
the point gamma3 = 0.9, omega3 = 3). <Y> = 2: quasi-periodic; larger: chaotic; white: the
motion passed through the vertical (the tangent dynamics stops there: the continuation is not
determined).
Run: python docs/megno_map.py [--client ADDRESS]"""

import sys
from pathlib import Path

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from rollingtop import SphericalTop, initial_state
from rollingtop.chaos import indicator_map
from rollingtop.plot import save_figure

T_END = 1000.0
GAMMA3 = np.linspace(0.05, 0.95, 31)
OMEGA3 = np.linspace(1.0, 8.0, 29)


def main(client=None):
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
    states = np.array([
        initial_state(body, "parallel", gamma=(0.0, np.sqrt(1 - g3**2), g3),
                      omega=(2.0, -0.2, w3), free={"v_nu": 0.1})
        for w3 in OMEGA3 for g3 in GAMMA3
    ])  # fmt: skip
    ds = indicator_map(body, "parallel", states, t_end=T_END, client=client)
    # through the vertical (status REACHED_VERTICAL) or stopped: NaN, drawn white
    megno = np.where(ds["status"].values == 0, ds["megno"].values[:, -1], np.nan)
    grid = megno.reshape(len(OMEGA3), len(GAMMA3))
    fig = Figure(figsize=(7.0, 5.2))
    ax = fig.add_subplot()
    top = max(50.0, float(np.nanmax(grid)))
    mesh = ax.pcolormesh(GAMMA3, OMEGA3, grid, norm=LogNorm(vmin=1.5, vmax=top), cmap="magma_r",
                         shading="nearest")  # fmt: skip
    fig.colorbar(mesh, ax=ax, label=r"mean MEGNO $\langle Y\rangle$ at $t = 1000$ (2: regular)")
    ax.plot([0.9], [3.0], "c*", ms=12, label="examples/parallel_chaotic.toml")
    ax.set_xlabel(r"initial $\gamma_3$ (axis tilt)")
    ax.set_ylabel(r"initial $\omega_3$")
    ax.set_title("companion model (parallel), paper's body: " r"$\omega = (2, -0.2, \omega_3)$, "
                 r"$v_\nu = 0.1$" "\nwhite: the motion passes through the vertical before "
                 r"$t = 1000$", fontsize=9)  # fmt: skip
    ax.legend(loc="lower left", fontsize=8)
    out = save_figure(fig, Path(__file__).with_name("megno_map.png"), dpi=150)
    finite = grid[np.isfinite(grid)]
    chaotic = float(np.mean(finite > 4.0)) if finite.size else 0.0
    print(
        f"wrote {out}: {np.isnan(grid).mean():.0%} through the vertical, "
        f"{chaotic:.0%} of the rest with <Y> > 4"
    )


if __name__ == "__main__":
    client = None
    if "--client" in sys.argv:
        from distributed import Client

        client = Client(sys.argv[sys.argv.index("--client") + 1])
    main(client)
