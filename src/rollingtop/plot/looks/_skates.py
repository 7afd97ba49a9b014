"""The sphere of skates (Kilin & Ivanova 2023, Fig. 3): thin disks threaded onto the axis
``e3``, sharp-edged, their edges the parallels of the sphere. The disk on the ice slides in its
own plane (along ``tau``) and not across it (along ``nu``); the sphere rolls over from disk to
disk along the meridian (:class:`rollingtop.devices.SkateLayout`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from mpl_toolkits.mplot3d import Axes3D

from rollingtop._types import FloatArray, IntArray
from rollingtop.devices import SkateLayout, skate_layout
from rollingtop.plot._frames import FrameGeometry
from rollingtop.plot.looks._mesh import Faces, ShadedMesh, revolve, rgba
from rollingtop.plot.looks._parts import axle, place
from rollingtop.trajectory import Trajectory

__all__ = ["draw_skates", "skate_quads", "skates_look"]

DISK, SECTOR, EDGE, CONTACT = "#b4c6d8", "#5f7c9c", "#eef3f8", "#d62728"
#: Faces around the axis; each disk face is split in rings so that mplot3d sorts it well.
N_AROUND, N_RINGS = 36, 3
#: Width of the bevel that sharpens each disk's edge, units of ``R``.
BEVEL = 0.05


def skate_quads(layout: SkateLayout) -> tuple[FloatArray, IntArray, IntArray]:
    """Every disk, body frame, units of ``R``: quads (m, 4, 3), the disk of each (m,) and its
    part (m,): 0 plain face, 1 dark sector (every other 30 degrees, so spin shows), 2 edge."""
    quads, disk, part = [], [], []
    half = layout.thickness / 2
    for k, (z, r) in enumerate(zip(layout.height, layout.radius, strict=True)):
        flat = np.linspace(0.0, r - BEVEL, N_RINGS + 1)
        zs = np.concatenate([np.full(N_RINGS + 1, z - half), [z], np.full(N_RINGS + 1, z + half)])
        rs = np.concatenate([flat, [r], flat[::-1]])
        q = revolve(zs, rs, N_AROUND)[..., [1, 2, 0]]  # phi-major, then along the profile
        n_seg = len(zs) - 1
        seg = np.arange(n_seg)
        edge = (seg == N_RINGS) | (seg == N_RINGS + 1)
        sector = np.arange(N_AROUND)[:, None] // 3 % 2 == 1
        kind = np.where(edge[None, :], 2, np.where(sector, 1, 0)).reshape(-1)
        quads.append(q)
        disk.append(np.full(len(q), k))
        part.append(kind)
    return np.concatenate(quads), np.concatenate(disk), np.concatenate(part)


def draw_skates(
    ax: Axes3D,
    geom: FrameGeometry,
    layout: SkateLayout,
    contact: IntArray,
    view: tuple[float, float],
) -> Callable[[int], None]:
    """Artists of the sphere of skates; ``contact`` (frames,): the disk on the ice (its edge
    drawn red). Returns ``draw(frame)``."""
    mesh = ShadedMesh(ax, *view)
    quads, disk, part = skate_quads(layout)
    base = np.select(
        [part[:, None] == 2, part[:, None] == 1], [rgba(EDGE, 1), rgba(SECTOR, 1)], rgba(DISK, 1)
    )
    north, south = axle(0.0, 1.15, 0.05)

    def draw(i: int) -> None:
        colours = base.copy()
        colours[(disk == contact[i]) & (part == 2)] = rgba(CONTACT, 1)[0]
        mesh.update(
            [
                Faces(place(quads, geom, i), colours, gloss=0.6, shininess=50),
                Faces(place(north.quads, geom, i), north.colours),
                Faces(place(south.quads, geom, i), south.colours),
            ]
        )

    return draw


def skates_look(
    ax: Axes3D, geom: FrameGeometry, traj: Trajectory, view: tuple[float, float]
) -> Callable[[int], None]:
    """:func:`draw_skates` with the disk in contact: the one whose plane is nearest the contact
    point ``-gamma``."""
    layout = skate_layout()
    return draw_skates(ax, geom, layout, layout.nearest(-geom.Q[:, 2, :]), view)
