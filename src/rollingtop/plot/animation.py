"""3D animation of the rolling sphere (matplotlib ``mplot3d``), written to MP4 or GIF.

The body is drawn in one of the looks of :mod:`rollingtop.plot.looks`: ``plain``, a wireframe
of meridians (through the poles on the symmetry axis) and parallels fixed in the body, so that
spin is visible, with the symmetry axis (red on the side of ``+e3``) and the centre of mass; or
one of the paper's devices, shaded solids (``roller``, ``shell``, ``skates``). The contact
point leaves a trail on the plane. The plain look only updates line data, so its cost per frame
is one Agg render; the devices re-sort a few thousand faces per frame. MP4 goes through the
ffmpeg binary shipped by the ``imageio-ffmpeg`` package; GIF through Pillow (no ffmpeg needed).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rollingtop._errors import ScenarioError
from rollingtop.io import PathArg, atomic_write, check_output_path
from rollingtop.plot._frames import frame_geometry
from rollingtop.plot.looks import LOOKS

if TYPE_CHECKING:
    from matplotlib.animation import AbstractMovieWriter

    from rollingtop.trajectory import Trajectory

__all__ = ["ANIMATION_SUFFIXES", "animate", "frame_figure"]

ANIMATION_SUFFIXES = (".mp4", ".gif")


#: The camera's elevation and azimuth, degrees.
VIEW = (22.0, -60.0)


def _scene(
    traj: Trajectory,
    times: NDArray[np.float64],
    *,
    look: str,
    camera: str,
    size: tuple[float, float],
    dpi: int,
    caption: str,
) -> tuple[Figure, Callable[[int], None]]:
    """The figure and ``draw(frame)`` that puts it at ``times[frame]``."""
    if look not in LOOKS:
        raise ValueError(f"look = {look!r} must be one of {', '.join(map(repr, LOOKS))}")
    if camera not in ("follow", "fixed"):
        raise ValueError(f"camera = {camera!r} must be 'follow' or 'fixed'")
    if look != "plain":
        from rollingtop.devices import check_device

        check_device(look, traj.model)
    geom = frame_geometry(traj, times)
    R, centre, contact = geom.R, geom.centre, geom.contact

    fig = Figure(figsize=size, dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    half, top = (2.2 * R, 2.6 * R) if look == "plain" else (1.7 * R, 2.2 * R)
    ax.set_box_aspect((2 * half, 2 * half, top))  # equal units: the sphere looks round
    ax.set_xlabel("X")
    ax.set_ylabel("Y")
    ax.set_zlabel("Z")
    stage = None
    if look != "plain":
        from rollingtop.plot.looks._parts import Stage

        stage = Stage(ax, R)
        ax.set_position((0.0, 0.0, 1.0, 0.9))  # no axes to label: the scene fills the figure
        ax.set_box_aspect((2 * half, 2 * half, top), zoom=1.3)
    draw_body = LOOKS[look](ax, geom, traj, VIEW)
    trail = ax.plot([], [], [], color="#ff7f0e", lw=1.2, zorder=1)[0]
    clock = fig.text(0.04, 0.95, "", fontsize=10, family="monospace")
    fig.text(0.04, 0.91, caption, fontsize=8)
    if camera == "fixed":
        lo = np.minimum(contact.min(0), centre.min(0)) - 1.3 * R
        hi = np.maximum(contact.max(0), centre.max(0)) + 1.3 * R
        span = max(hi[0] - lo[0], hi[1] - lo[1])
        mid = (lo + hi) / 2
        ax.set_xlim(mid[0] - span / 2, mid[0] + span / 2)
        ax.set_ylim(mid[1] - span / 2, mid[1] + span / 2)
        ax.set_zlim(0, top)
        ax.set_box_aspect((span, span, top), zoom=1.0 if stage is None else 1.3)
        # the plane as a coarse grid (the devices' stage has a floor of its own)
        grid = np.linspace(-span / 2, span / 2, 9) if stage is None else np.empty(0)
        for g in grid:
            ax.plot(
                [mid[0] + g] * 2,
                [mid[1] - span / 2, mid[1] + span / 2],
                [0, 0],
                color="0.85",
                lw=0.5,
                zorder=0,
            )
            ax.plot(
                [mid[0] - span / 2, mid[0] + span / 2],
                [mid[1] + g] * 2,
                [0, 0],
                color="0.85",
                lw=0.5,
                zorder=0,
            )
    ax.view_init(elev=VIEW[0], azim=VIEW[1])

    def draw(i: int) -> None:
        draw_body(i)
        trail.set_data_3d(contact[: i + 1, 0], contact[: i + 1, 1], contact[: i + 1, 2])
        clock.set_text(f"t = {times[i]:8.3f}")
        if camera == "follow":
            o = centre[i]
            ax.set_xlim(o[0] - half, o[0] + half)
            ax.set_ylim(o[1] - half, o[1] + half)
            ax.set_zlim(0, top)
        if stage is not None:
            stage.update(centre[i])

    return fig, draw


def _caption(traj: Trajectory, look: str, speed: float) -> str:
    device = {
        "plain": "",
        "roller": "roller-bearing sphere, ",
        "shell": "shell with a rotor, ",
        "skates": "sphere of skates, ",
    }[look]
    return f"{device}{traj.model.name} model, speed x{speed:g}"


def frame_figure(
    traj: Trajectory,
    t: float,
    *,
    look: str = "plain",
    camera: str = "follow",
    size: tuple[float, float] = (6.0, 6.0),
    dpi: int = 80,
) -> Figure:
    """One frame of :func:`animate` at time ``t`` (the trajectory's path so far as its trail).

    The devices' moving parts (rollers' turn, shell's spin) are integrated from ``traj.t[0]``
    over the trajectory's samples, so sample densely up to ``t``.
    """
    if not traj.t[0] <= t <= traj.t[-1]:
        raise ValueError(f"t = {t:g} lies outside the trajectory [{traj.t[0]:g}, {traj.t[-1]:g}]")
    times = np.append(traj.t[traj.t < t], t)
    fig, draw = _scene(
        traj,
        times,
        look=look,
        camera=camera,
        size=size,
        dpi=dpi,
        caption=_caption(traj, look, 1.0).removesuffix(", speed x1"),
    )
    draw(len(times) - 1)
    return fig


def animate(
    traj: Trajectory,
    path: PathArg,
    *,
    look: str = "plain",
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
    look : {"plain", "roller", "shell", "skates"}
        The plain wireframe, or the device of the paper's Sec. 1 that realises the constraint:
        the roller-bearing sphere, the shell with a rotor, the sphere of skates
        (:mod:`rollingtop.plot.looks`; the devices need the meridian model).
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
    if fps <= 0 or speed <= 0:
        raise ValueError("fps and speed must be positive")
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    if duration is None:
        duration = (t1 - t0) / speed
    n_frames = int(round(duration * fps))
    if n_frames < 1:
        raise ScenarioError(
            f"duration * fps = {duration * fps:g} gives no frame (at least one "
            "is needed: a longer duration or a higher fps)"
        )
    if t0 + (n_frames - 1) / fps * speed > t1 * (1 + 1e-12) + 1e-12:
        raise ValueError(
            f"the video needs t up to {t0 + (n_frames - 1) / fps * speed:g} but the trajectory "
            f"ends at {t1:g}: simulate longer, or lower duration or speed"
        )
    times = t0 + np.arange(n_frames) / fps * speed
    fig, draw = _scene(
        traj,
        times,
        look=look,
        camera=camera,
        size=size,
        dpi=dpi,
        caption=_caption(traj, look, speed),
    )

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
