"""The plain look: a wireframe of body-fixed meridians and parallels, the symmetry axis sticking
out of both poles (red on the side of ``+e3``, dark on the side of ``-e3``), the centre of mass."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from mpl_toolkits.mplot3d import Axes3D
from numpy.typing import NDArray

from rollingtop.plot._frames import FrameGeometry
from rollingtop.trajectory import Trajectory

__all__ = ["plain_look"]


def _wireframe(
    n_meridians: int = 12, n_parallels: int = 5, n: int = 48
) -> list[NDArray[np.float64]]:
    """Unit-sphere curves in the body frame, each of shape (n, 3)."""
    curves = []
    t = np.linspace(0, np.pi, n)
    for k in range(n_meridians):
        phi = 2 * np.pi * k / n_meridians
        curves.append(np.stack([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)], 1))
    u = np.linspace(0, 2 * np.pi, n)
    for j in range(1, n_parallels + 1):
        z = np.cos(np.pi * j / (n_parallels + 1))
        r = np.sqrt(1 - z * z)
        curves.append(np.stack([r * np.cos(u), r * np.sin(u), np.full_like(u, z)], 1))
    return curves


def plain_look(
    ax: Axes3D, geom: FrameGeometry, traj: Trajectory, view: tuple[float, float]
) -> Callable[[int], None]:
    """Lines only (one Agg render per frame): 12 meridians and 5 parallels, the axis, the CoM."""
    R = geom.R
    curves = _wireframe()
    lines = [ax.plot([], [], [], color="#3b6ea8", lw=0.8, alpha=0.8)[0] for _ in curves]
    axis_south = ax.plot([], [], [], color="crimson", lw=2.2)[0]
    axis_north = ax.plot([], [], [], color="0.25", lw=2.2)[0]
    dot = ax.plot([], [], [], "o", color="black", ms=4)[0]

    def draw(i: int) -> None:
        q, o, com = geom.Q[i], geom.centre[i], geom.com[i]
        for line, c in zip(lines, curves, strict=True):
            p = o + R * c @ q.T
            line.set_data_3d(p[:, 0], p[:, 1], p[:, 2])
        e3 = q[:, 2]
        s_end, n_end = o + 1.45 * R * e3, o - 1.45 * R * e3
        axis_south.set_data_3d(*np.stack([o, s_end], 1))
        axis_north.set_data_3d(*np.stack([o, n_end], 1))
        dot.set_data_3d([com[0]], [com[1]], [com[2]])

    return draw
