"""Parts shared by the device looks: placing body-frame quads, the hub sphere, the axle."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import to_rgba
from mpl_toolkits.mplot3d import Axes3D
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from rollingtop._types import FloatArray
from rollingtop.plot._frames import FrameGeometry
from rollingtop.plot.looks._mesh import Faces, revolve, rgba

__all__ = [
    "AXLE_NORTH",
    "AXLE_SOUTH",
    "Stage",
    "axle",
    "floor_tiles",
    "place",
    "shadow",
    "sphere_quads",
]

#: Colours of the axle's ends, as the plain look's axis: ``+e3`` red, ``-e3`` dark.
AXLE_NORTH, AXLE_SOUTH = "crimson", "0.25"


def place(quads: FloatArray, geom: FrameGeometry, i: int) -> FloatArray:
    """Body-frame quads in units of ``R`` (m, 4, 3) to the fixed frame at frame ``i``."""
    return np.asarray(geom.centre[i] + geom.R * quads @ geom.Q[i].T, dtype=np.float64)


def sphere_quads(radius: float, n_phi: int = 32, n_theta: int = 16) -> FloatArray:
    """A sphere about the origin, body frame, as quads facing outwards (poles on ``e3``)."""
    theta = np.linspace(np.pi, 0.0, n_theta + 1)
    q = revolve(radius * np.cos(theta), radius * np.sin(theta), n_phi)
    return q[..., [1, 2, 0]]  # the revolution axis x becomes e3


def axle(inner: float, outer: float, radius: float, n_phi: int = 12) -> tuple[Faces, Faces]:
    """The axle's two ends along ``+e3`` and ``-e3`` from ``inner`` to ``outer``, body frame."""
    x = np.array([inner, outer, outer])
    r = np.array([radius, radius, 0.0])
    north = revolve(x, r, n_phi)[..., [1, 2, 0]]
    south = north * np.array([1.0, -1.0, -1.0])  # turned half a turn about e1
    return (Faces(north, rgba(AXLE_NORTH, len(north))), Faces(south, rgba(AXLE_SOUTH, len(south))))


def floor_tiles(
    x: tuple[float, float], y: tuple[float, float], tile: float
) -> tuple[FloatArray, FloatArray]:
    """Checkerboard tiles of side ``tile`` on the plane ``z = 0`` (fixed in space), clipped to
    the rectangle ``x`` by ``y``: quads (m, 4, 3) and their parity (m,)."""
    ix = np.arange(np.floor(x[0] / tile), np.ceil(x[1] / tile))
    iy = np.arange(np.floor(y[0] / tile), np.ceil(y[1] / tile))
    gx, gy = np.meshgrid(ix, iy, indexing="ij")
    x0 = np.clip(gx * tile, *x).ravel()
    x1 = np.clip((gx + 1) * tile, *x).ravel()
    y0 = np.clip(gy * tile, *y).ravel()
    y1 = np.clip((gy + 1) * tile, *y).ravel()
    z = np.zeros_like(x0)
    quads = np.stack(
        [
            np.stack([x0, y0, z], 1),
            np.stack([x1, y0, z], 1),
            np.stack([x1, y1, z], 1),
            np.stack([x0, y1, z], 1),
        ],
        1,
    )
    return quads, ((gx + gy) % 2).ravel().astype(int)


def shadow(centre: FloatArray, radius: float, n: int = 32) -> FloatArray:
    """A disk on the plane under ``centre`` (the light from straight above): one polygon."""
    u = 2 * np.pi * np.arange(n) / n
    return np.stack(
        [centre[0] + radius * np.cos(u), centre[1] + radius * np.sin(u), np.full(n, 1e-3 * radius)],
        1,
    )[None]


class Stage:
    """The device looks' surroundings: no axes, orthographic projection, a checkerboard floor
    fixed in space (so sliding shows), the sphere's shadow. Painted in a fixed order: floor,
    shadow, trail, body."""

    def __init__(self, ax: Axes3D, R: float) -> None:
        ax.set_axis_off()
        ax.set_proj_type("ortho")  # one view direction: the meshes' culling is exact
        ax.computed_zorder = False
        self.ax, self.R = ax, R
        self.floor = Poly3DCollection(np.zeros((0, 4, 3)), linewidths=0.0, zorder=0)
        self.shade = Poly3DCollection(
            shadow(np.zeros(3), 0.8 * R), facecolor=(0, 0, 0, 0.18), linewidths=0.0, zorder=0.5
        )
        ax.add_collection3d(self.floor, autolim=False)
        ax.add_collection3d(self.shade, autolim=False)
        self.colours = np.array([to_rgba("#eef1f4"), to_rgba("#d9dee4")])

    def update(self, centre: FloatArray) -> None:
        """Floor tiles within the axes' current limits; the shadow under ``centre``."""
        quads, parity = floor_tiles(self.ax.get_xlim(), self.ax.get_ylim(), 0.5 * self.R)
        self.floor.set_verts(quads)
        self.floor.set_facecolor(self.colours[parity])
        self.shade.set_verts(shadow(centre, 0.8 * self.R))
