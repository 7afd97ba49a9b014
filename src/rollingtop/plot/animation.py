"""3D animation of the rolling sphere (matplotlib ``mplot3d``), written to MP4 or GIF.

The sphere is drawn as a wireframe of meridians (through the poles on the symmetry axis) and
parallels fixed in the body, so that spin is visible; the symmetry axis sticks out of both poles
(red on the side of ``+e3``, dark on the side of ``-e3``); the centre of mass is a dot; the
contact point leaves a trail on the plane. Every frame only updates line data, so the
cost per frame is one Agg render. MP4 goes through the ffmpeg binary shipped by the
``imageio-ffmpeg`` package; GIF through Pillow (no ffmpeg needed).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rollingtop.io import PathArg, atomic_write, check_output_path

if TYPE_CHECKING:
    from matplotlib.animation import AbstractMovieWriter

    from rollingtop.trajectory import Trajectory

__all__ = ["animate", "ANIMATION_SUFFIXES"]

ANIMATION_SUFFIXES = (".mp4", ".gif")


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


def animate(
    traj: Trajectory,
    path: PathArg,
    *,
    fps: int = 25,
    duration: float | None = None,
    speed: float = 1.0,
    camera: str = "follow",
    dpi: int = 80,
    size: tuple[float, float] = (6.0, 6.0),
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Render ``traj`` as an animation and write it atomically to ``path`` (.mp4 or .gif).

    Parameters
    ----------
    traj : Trajectory
        The motion; its samples are interpolated (linearly, then re-orthonormalised) at the frame
        times, so sample it densely enough (a few samples per frame).
    fps : int
        Frames per second of the video.
    duration : float, optional
        Length of the video in seconds; default: the whole trajectory at ``speed``.
    speed : float
        Simulated time per second of video.
    camera : {"follow", "fixed"}
        Follow the sphere, or frame the whole contact-point path.
    progress : callable, optional
        ``progress(frame, total)`` after each rendered frame.

    Returns
    -------
    Path
        The file written. Its frame count is ``round(duration * fps)``.
    """
    path = check_output_path(path, ANIMATION_SUFFIXES)
    if camera not in ("follow", "fixed"):
        raise ValueError(f"camera = {camera!r} must be 'follow' or 'fixed'")
    if fps <= 0 or speed <= 0:
        raise ValueError("fps and speed must be positive")
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    if duration is None:
        duration = (t1 - t0) / speed
    n_frames = int(round(duration * fps))
    if n_frames < 1:
        raise ValueError(f"duration * fps = {duration * fps:g} gives no frame")
    if t0 + (n_frames - 1) / fps * speed > t1 * (1 + 1e-12) + 1e-12:
        raise ValueError(
            f"the video needs t up to {t0 + (n_frames - 1) / fps * speed:g} but the trajectory "
            f"ends at {t1:g}: simulate longer, or lower duration or speed"
        )
    times = t0 + np.arange(n_frames) / fps * speed
    Y = np.stack([np.interp(times, traj.t, traj.y[:, k]) for k in range(traj.y.shape[1])], 1)
    body = traj.body
    R, a3 = body.R, body.a3

    # Fixed-frame geometry of every frame: Q maps body components to fixed ones.
    Q = Y[:, 6:15].reshape(-1, 3, 3)
    U, _, Vt = np.linalg.svd(Q)
    Q = U @ Vt  # interpolated frames re-orthonormalised
    com = np.concatenate([Y[:, 15:17], (R + a3 * Q[:, 2, 2])[:, None]], 1)  # CoM height R + a3 g3
    centre = com - a3 * Q[:, :, 2]  # geometric centre = CoM - Q a
    contact = np.concatenate([centre[:, :2], np.zeros((n_frames, 1))], 1)
    curves = _wireframe()

    fig = Figure(figsize=size, dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    half = 2.2 * R
    ax.set_box_aspect((2 * half, 2 * half, 2.6 * R))  # equal units: the sphere looks round
    ax.set_xlabel("X")
    ax.set_ylabel("Y")
    ax.set_zlabel("Z")
    lines = [ax.plot([], [], [], color="#3b6ea8", lw=0.8, alpha=0.8)[0] for _ in curves]
    axis_south = ax.plot([], [], [], color="crimson", lw=2.2)[0]
    axis_north = ax.plot([], [], [], color="0.25", lw=2.2)[0]
    dot = ax.plot([], [], [], "o", color="black", ms=4)[0]
    trail = ax.plot([], [], [], color="#ff7f0e", lw=1.2)[0]
    clock = fig.text(0.04, 0.95, "", fontsize=10, family="monospace")
    fig.text(0.04, 0.91, f"{traj.model.name} model, speed x{speed:g}", fontsize=8)
    if camera == "fixed":
        lo = np.minimum(contact.min(0), centre.min(0)) - 1.3 * R
        hi = np.maximum(contact.max(0), centre.max(0)) + 1.3 * R
        span = max(hi[0] - lo[0], hi[1] - lo[1])
        mid = (lo + hi) / 2
        ax.set_xlim(mid[0] - span / 2, mid[0] + span / 2)
        ax.set_ylim(mid[1] - span / 2, mid[1] + span / 2)
        ax.set_zlim(0, 2.6 * R)
        ax.set_box_aspect((span, span, 2.6 * R))
        # the plane as a coarse grid
        for x in np.linspace(mid[0] - span / 2, mid[0] + span / 2, 9):
            ax.plot([x, x], [mid[1] - span / 2, mid[1] + span / 2], [0, 0], color="0.85", lw=0.5)
        for y in np.linspace(mid[1] - span / 2, mid[1] + span / 2, 9):
            ax.plot([mid[0] - span / 2, mid[0] + span / 2], [y, y], [0, 0], color="0.85", lw=0.5)
    ax.view_init(elev=22, azim=-60)

    def draw(i: int) -> None:
        q, o = Q[i], centre[i]
        for line, c in zip(lines, curves, strict=True):
            p = o + R * c @ q.T
            line.set_data_3d(p[:, 0], p[:, 1], p[:, 2])
        e3 = q[:, 2]
        s_end, n_end = o + 1.45 * R * e3, o - 1.45 * R * e3
        axis_south.set_data_3d(*np.stack([o, s_end], 1))
        axis_north.set_data_3d(*np.stack([o, n_end], 1))
        dot.set_data_3d([com[i, 0]], [com[i, 1]], [com[i, 2]])
        trail.set_data_3d(contact[: i + 1, 0], contact[: i + 1, 1], contact[: i + 1, 2])
        clock.set_text(f"t = {times[i]:8.3f}")
        if camera == "follow":
            ax.set_xlim(o[0] - half, o[0] + half)
            ax.set_ylim(o[1] - half, o[1] + half)
            ax.set_zlim(0, 2.6 * R)

    def write(tmp: Path) -> None:
        writer: AbstractMovieWriter
        if path.suffix.lower() == ".gif":
            from matplotlib.animation import PillowWriter

            writer = PillowWriter(fps=fps)
        else:
            import imageio_ffmpeg
            from matplotlib import rcParams
            from matplotlib.animation import FFMpegWriter

            rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
            writer = FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
        with writer.saving(fig, os.fspath(tmp), dpi):
            for i in range(n_frames):
                draw(i)
                writer.grab_frame()
                if progress is not None:
                    progress(i + 1, n_frames)

    return atomic_write(path, write, keep_suffix=True)
