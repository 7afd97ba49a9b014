"""The spherical shell with a rotor inside (Kilin & Ivanova 2023, Fig. 2): a transparent shell
rolling without slipping, and the heavy axisymmetric rotor on the shell-fixed axle ``e3``.

The rotor is the trajectory's body (it turns with ``w``); the shell turns with
``Omega = w + delta e3``, i.e. it is the rotor's frame turned by ``chi`` about ``e3``
(:func:`rollingtop.devices.shell_spin_angle`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from matplotlib.colors import to_rgba
from mpl_toolkits.mplot3d import Axes3D
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from rollingtop._types import FloatArray, IntArray
from rollingtop.devices import shell_spin_angle
from rollingtop.plot._frames import FrameGeometry
from rollingtop.plot.looks._mesh import Faces, ShadedMesh, revolve, rgba
from rollingtop.plot.looks._parts import axle, place, sphere_quads
from rollingtop.trajectory import Trajectory

__all__ = ["draw_shell", "rotor_quads", "shell_look", "spin_about_e3"]

SHELL, SHELL_LINES, SEAM = (0.62, 0.78, 0.92, 0.16), (0.2, 0.35, 0.55, 0.6), "#2ca02c"
ROTOR, ROTOR_STRIPE, HUB = "#c9cdd3", "#1f4e8c", "#5a6470"
N_MERIDIANS, N_PARALLELS = 12, 5


def spin_about_e3(points: FloatArray, angle: float) -> FloatArray:
    """``points`` (..., 3) turned by ``angle`` about ``e3``."""
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return np.asarray(points @ turn.T, dtype=np.float64)


def rotor_quads(a3: float) -> tuple[FloatArray, IntArray]:
    """The rotor, body frame, units of ``R``: a flywheel centred at the centre of mass
    ``x3 = a3`` on a hub, as quads (m, 4, 3) and their stripe flags (m,) (12 sectors around
    ``e3``, alternate ones dark, so its spin shows)."""
    n_phi = 24
    # flywheel profile along e3: a face in rings (mplot3d sorts small faces well), a chamfer,
    # the rim, a chamfer, the other face
    face = np.array([0.0, 0.16, 0.32, 0.46, 0.6])
    z = a3 + np.concatenate([np.full(5, -0.12), [-0.1, 0.1], np.full(5, 0.12)])
    r = np.concatenate([face, [0.64, 0.64], face[::-1]])
    wheel = revolve(z, r, n_phi)[..., [1, 2, 0]]  # (n_phi * 11, 4, 3), phi-major
    on_face = np.r_[np.ones(4), np.zeros(3), np.ones(4)].astype(np.int64)  # rim unstriped
    flag = (np.arange(n_phi, dtype=np.int64)[:, None] // 2 % 2) * on_face[None, :]
    return wheel, flag.reshape(-1)


def _shell_lines() -> list[FloatArray]:
    """Meridians and parallels of the unit sphere, body frame, each (n, 3)."""
    t = np.linspace(0, np.pi, 40)
    u = np.linspace(0, 2 * np.pi, 73)
    curves = []
    for k in range(N_MERIDIANS):
        p = 2 * np.pi * k / N_MERIDIANS
        curves.append(np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], 1))
    for j in range(1, N_PARALLELS + 1):
        z = np.cos(np.pi * j / (N_PARALLELS + 1))
        r = np.sqrt(1 - z * z)
        curves.append(np.stack([r * np.cos(u), r * np.sin(u), np.full_like(u, z)], 1))
    return curves


def draw_shell(
    ax: Axes3D, geom: FrameGeometry, chi: FloatArray, view: tuple[float, float]
) -> Callable[[int], None]:
    """Artists of the shell and its rotor. ``chi`` (frames,): the shell's turn about ``e3``
    relative to the rotor, from any source (the meridian model's
    :func:`~rollingtop.devices.shell_spin_angle`, or a model of its own). Returns
    ``draw(frame)``."""
    chi = np.asarray(chi, dtype=float)
    if chi.shape != geom.times.shape:
        raise ValueError(f"chi has shape {chi.shape}, the frames {geom.times.shape}")
    mesh = ShadedMesh(ax, *view)
    shell = sphere_quads(1.0, 24, 12)
    wheel, flag = rotor_quads(geom.a3 / geom.R)
    wheel_colours = np.where(flag[:, None] == 1, rgba(ROTOR_STRIPE, 1), rgba(ROTOR, 1))
    north, south = axle(0.0, 1.12, 0.045)
    # the shell's grid as segments; its meridian at azimuth 0 (the seam) marks its spin
    curves = _shell_lines()
    segments = np.concatenate([np.stack([c[:-1], c[1:]], 1) for c in curves])
    seam = np.zeros(len(segments), bool)
    seam[: len(curves[0]) - 1] = True
    back = Line3DCollection([], linewidths=0.6, zorder=1.5)  # behind the shell's faces
    front = Line3DCollection([], linewidths=0.8, zorder=3)
    for lines in (back, front):
        ax.add_collection3d(lines, autolim=False)
    colours = np.where(seam[:, None], to_rgba(SEAM), to_rgba(SHELL_LINES))
    widths = np.where(seam, 2.2, 0.7)

    def draw(i: int) -> None:
        turned = spin_about_e3(shell, chi[i])
        parts = [
            Faces(place(wheel, geom, i), wheel_colours, gloss=0.6, shininess=60),
            Faces(place(north.quads, geom, i), north.colours),
            Faces(place(south.quads, geom, i), south.colours),
            Faces(place(turned, geom, i), rgba(SHELL, len(shell)), two_sided=True, gloss=0.5),
        ]
        mesh.update(parts)
        seg = place(spin_about_e3(segments, chi[i]).reshape(-1, 2, 3), geom, i)
        facing = (seg.mean(1) - geom.centre[i]) @ mesh.eye > 0
        for lines, part in ((front, facing), (back, ~facing)):
            lines.set_segments(seg[part])
            lines.set_color(colours[part] * [1, 1, 1, 1.0 if lines is front else 0.45])
            lines.set_linewidth(widths[part])

    return draw


def shell_look(
    ax: Axes3D, geom: FrameGeometry, traj: Trajectory, view: tuple[float, float]
) -> Callable[[int], None]:
    """:func:`draw_shell` with the meridian model's shell spin
    (:func:`rollingtop.devices.shell_spin_angle` at the samples, interpolated at the frames)."""
    chi = shell_spin_angle(traj.t, traj.body, traj.y, traj.model)
    return draw_shell(ax, geom, geom.at(chi, traj.t), view)
