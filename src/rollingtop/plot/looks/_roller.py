"""The roller-bearing sphere (Kilin & Ivanova 2023, Fig. 1): barrels along the meridians,
each turning about its own axis (:func:`rollingtop.devices.roller_spin`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from mpl_toolkits.mplot3d import Axes3D

from rollingtop._types import FloatArray, IntArray
from rollingtop.devices import RollerLayout, roller_layout, roller_spin
from rollingtop.plot._frames import FrameGeometry
from rollingtop.plot.looks._mesh import Faces, ShadedMesh, rgba
from rollingtop.plot.looks._parts import axle, place, sphere_quads
from rollingtop.trajectory import Trajectory

__all__ = ["draw_rollers", "roller_look", "roller_quads"]

ROLLER, STRIPE, CONTACT, HUB = "#e9a23b", "#1f3b73", "#d62728", "#3d4f63"
#: Faces of one barrel: along its axis, around it (one dark stripe of two faces, sideways at rest).
N_ALONG, N_AROUND = 3, 12


def roller_quads(layout: RollerLayout, angle: FloatArray) -> FloatArray:
    """Every roller's barrel, body frame, units of ``R``, each turned by ``angle`` (k,) about
    its axis: shape (k, N_AROUND * (N_ALONG + 2), 4, 3), the sides then the two ends.

    The barrel's axis passes at ``1 - rho`` from the centre along ``layout.centre``; its profile
    is the meridian's arc (radius ``sqrt(1 - x^2) - (1 - rho)`` at ``x`` along the axis), so the
    rollers of one meridian make up its circle: each meridian is an omniwheel (Fig. 1b).
    """
    c, a, rho = layout.centre, layout.axis, layout.radius
    w = np.cross(a, c)
    x = np.sin(layout.half_angle) * np.linspace(-1.0, 1.0, N_ALONG + 1)
    r = np.sqrt(1 - x**2)[None, :] - (1 - rho)[:, None]  # (k, x)
    phi = angle[:, None] + 2 * np.pi * np.arange(N_AROUND + 1)[None, :] / N_AROUND  # (k, phi)
    radial = np.cos(phi)[..., None] * c[:, None, :] + np.sin(phi)[..., None] * w[:, None, :]
    pts = (
        ((1 - rho)[:, None] * c)[:, None, None, :]
        + x[None, None, :, None] * a[:, None, None, :]
        + r[:, None, :, None] * radial[:, :, None, :]
    )  # (k, phi, x, 3)
    # counter-clockwise seen from outside, as in revolve (a, c, a x c is right-handed)
    side = np.stack([pts[:, :-1, :-1], pts[:, 1:, :-1], pts[:, 1:, 1:], pts[:, :-1, 1:]], 3)
    hub = (1 - rho)[:, None] * c  # (k, 3), the axis's middle
    ends = []
    for j, sign in ((0, -1.0), (-1, 1.0)):
        ring = pts[:, :, j]  # (k, phi, 3)
        mid = np.broadcast_to((hub + sign * x[-1] * a)[:, None, :], ring[:, :-1].shape)
        a_, b_ = (ring[:, 1:], ring[:, :-1]) if sign < 0 else (ring[:, :-1], ring[:, 1:])
        fan = [mid, a_, b_, mid]
        ends.append(np.stack(fan, 2))
    k = len(rho)
    return np.concatenate([side.reshape(k, -1, 4, 3), *ends], 1)


def draw_rollers(
    ax: Axes3D,
    geom: FrameGeometry,
    layout: RollerLayout,
    angle: FloatArray,
    contact: IntArray,
    view: tuple[float, float],
) -> Callable[[int], None]:
    """Artists of the roller-bearing sphere; ``angle`` (frames, k): each roller's turn,
    ``contact`` (frames,): the roller on the plane (drawn red). Returns ``draw(frame)``."""
    mesh = ShadedMesh(ax, *view)
    hub_radius = 1 - 2 * float(layout.radius.max()) + 0.02
    hub = sphere_quads(hub_radius, 28, 14)
    north, south = axle(hub_radius - 0.05, 1.25, 0.06)
    stripes = np.repeat(np.isin(np.arange(N_AROUND), (2, 3)), N_ALONG).astype(int)
    stripes = np.concatenate([stripes, np.zeros(2 * N_AROUND, int)])  # per face of one barrel

    def draw(i: int) -> None:
        q = geom.Q[i]
        facing = layout.centre @ q.T @ mesh.eye  # rollers on the far side are behind the hub
        shown = np.flatnonzero(facing > -0.45)
        barrels = roller_quads(
            RollerLayout(
                layout.centre[shown], layout.axis[shown], layout.radius[shown], layout.half_angle
            ),
            angle[i, shown],
        )
        colours = np.where(stripes[None, :, None] == 1, rgba(STRIPE, 1), rgba(ROLLER, 1))
        colours = np.broadcast_to(colours, (len(shown), stripes.size, 4)).copy()
        colours[shown == contact[i]] = np.where(
            stripes[:, None] == 1, rgba(STRIPE, 1), rgba(CONTACT, 1)
        )
        parts = [
            Faces(place(hub, geom, i), rgba(HUB, len(hub)), gloss=0.5),
            Faces(place(barrels.reshape(-1, 4, 3), geom, i), colours.reshape(-1, 4)),
            Faces(place(north.quads, geom, i), north.colours),
            Faces(place(south.quads, geom, i), south.colours),
        ]
        mesh.update(parts)

    return draw


def roller_look(
    ax: Axes3D, geom: FrameGeometry, traj: Trajectory, view: tuple[float, float]
) -> Callable[[int], None]:
    """:func:`draw_rollers` with the spin of :func:`rollingtop.devices.roller_spin` (the
    trajectory's samples, interpolated at the frames)."""
    layout = roller_layout()
    _, _, angle = roller_spin(traj.t, traj.body, traj.y, layout)
    contact = layout.nearest(-geom.Q[:, 2, :])
    return draw_rollers(ax, geom, layout, geom.at(angle, traj.t), contact, view)
