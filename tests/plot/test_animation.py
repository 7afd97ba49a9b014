"""The 3D animation: what each frame draws, against the sphere's geometry computed here from the
trajectory's states (docs/model.md, "Motion in absolute space")."""

import numpy as np
import pytest
from matplotlib.animation import PillowWriter
from PIL import Image, ImageSequence

from rollingtop import simulate
from rollingtop.plot.animation import animate
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES

FPS, SPEED, FRAMES = 4, 1.0, 6
#: Frame geometry from the samples themselves (the frames fall on samples, so the animation's
#: interpolation and re-orthonormalisation of the frame change nothing beyond round-off).
GEOMETRY_TOL = 1e-12
#: The wireframe: 12 meridians and 5 parallels of the body.
N_WIREFRAME = 17


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    """The trajectory sampled at the frame times, and each frame's 3D line data."""
    sc = load_scenario(EXAMPLES / "paper.toml")
    traj = simulate(sc, t_end=(FRAMES - 1) / FPS * SPEED, samples=FRAMES)
    drawn = []
    grab = PillowWriter.grab_frame

    def record(writer, **kwargs):
        (ax,) = writer.fig.axes
        drawn.append([np.array(ln.get_data_3d(), dtype=float).T for ln in ax.get_lines()])
        grab(writer, **kwargs)

    out = tmp_path_factory.mktemp("animation") / "roll.gif"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(PillowWriter, "grab_frame", record)
        written = animate(traj, out, fps=FPS, duration=FRAMES / FPS, speed=SPEED)
    return traj, drawn, written


def test_every_frame_draws_the_sphere_where_the_state_puts_it(frames):
    """Centre at height R above (X - a3 alpha3, Y - a3 beta3); wireframe on the sphere of radius
    R, its meridians meeting at the pole +e3 = (alpha3, beta3, gamma3); the axis along e3; the
    centre of mass at (X, Y, R + a3 gamma3); the trail: the contact points so far, on the plane."""
    traj, drawn, _ = frames
    R, a3 = traj.body.R, traj.body.a3
    assert len(drawn) == FRAMES
    contacts = []
    for lines, y in zip(drawn, traj.y, strict=True):
        e3 = np.array([y[8], y[11], y[14]])  # the body's symmetry axis in the fixed frame
        centre = np.array([y[15] - a3 * y[8], y[16] - a3 * y[11], R])
        contacts.append([centre[0], centre[1], 0.0])
        wireframe, (south, north, dot, trail) = lines[:N_WIREFRAME], lines[N_WIREFRAME:]
        for curve in wireframe:
            np.testing.assert_allclose(np.linalg.norm(curve - centre, axis=1), R,
                                       rtol=GEOMETRY_TOL)  # fmt: skip
        for meridian in wireframe[:12]:
            np.testing.assert_allclose(meridian[0], centre + R * e3, atol=GEOMETRY_TOL)
            np.testing.assert_allclose(meridian[-1], centre - R * e3, atol=GEOMETRY_TOL)
        np.testing.assert_allclose(south, [centre, centre + 1.45 * R * e3], atol=GEOMETRY_TOL)
        np.testing.assert_allclose(north, [centre, centre - 1.45 * R * e3], atol=GEOMETRY_TOL)
        np.testing.assert_allclose(dot, [[y[15], y[16], R + a3 * y[14]]], atol=GEOMETRY_TOL)
        np.testing.assert_allclose(trail, contacts, atol=GEOMETRY_TOL)


def test_the_file_holds_the_frames(frames):
    """A GIF of FRAMES frames, each of the figure's size in pixels, that differ from each other."""
    _, _, written = frames
    images = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(written))]
    assert len(images) == FRAMES
    assert images[0].shape == (6 * 80, 6 * 80, 3)  # size (6, 6) inches at 80 dpi
    assert all(np.any(a != b) for a, b in zip(images[:-1], images[1:], strict=True))
