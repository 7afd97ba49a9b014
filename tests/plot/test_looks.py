"""The device looks of the animation: what a frame draws, against the body's placement computed
here from the state, and the pixels of one rendered frame per look."""

import io

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from PIL import Image

from rollingtop import ContactModelError, simulate
from rollingtop.devices import roller_layout, shell_spin_angle
from rollingtop.plot._frames import frame_geometry
from rollingtop.plot.animation import frame_figure
from rollingtop.plot.looks import LOOKS, draw_shell
from rollingtop.plot.looks._roller import roller_quads
from rollingtop.plot.looks._shell import SEAM
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES

#: Geometry placed from the samples (frames on samples): exact up to round-off.
GEOMETRY_TOL = 1e-12
#: A look's own hue "is present" when at least this many pixels have it.
MIN_PIXELS = 30
#: Each look's own hue, as a test on the pixels' RGB (0..1): the wireframe's blue, the rollers'
#: amber, the rotor's blue through the shell, the skates' steel blue (drawn shaded, so hues
#: rather than colours; the floor is grey, b - r < 0.05).
OWN_HUE = {
    "plain": lambda r, g, b: b > r + 0.15,
    "roller": lambda r, g, b: r > b + 0.3,
    "shell": lambda r, g, b: b > r + 0.15,
    "skates": lambda r, g, b: b > r + 0.08,
}


@pytest.fixture(scope="module")
def paper():
    sc = load_scenario(EXAMPLES / "paper.toml")
    return simulate(sc, t_end=1.0, samples=101)


def pixels(fig: Figure) -> np.ndarray:
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return np.asarray(Image.open(buf).convert("RGB"), dtype=float) / 255


@pytest.mark.parametrize("look", sorted(LOOKS))
def test_a_frame_of_each_look_shows_the_body(paper, look):
    """Some of the frame is drawn (not blank, not all paint), and the look's own hue is there."""
    image = pixels(frame_figure(paper, 0.5, look=look, size=(4.0, 4.0), dpi=60))
    drawn = np.mean(np.any(image < 0.97, axis=-1))
    assert 0.03 < drawn < 0.6
    assert np.sum(OWN_HUE[look](*np.moveaxis(image, -1, 0))) >= MIN_PIXELS


def test_the_devices_refuse_other_models():
    sc = load_scenario(EXAMPLES / "smooth.toml")
    traj = simulate(sc, t_end=0.2, samples=3)
    for look in ("roller", "shell", "skates"):
        with pytest.raises(ContactModelError, match="constraint of model 'meridian'"):
            frame_figure(traj, 0.1, look=look)


def test_rollers_turn_about_their_own_axes():
    """Turning a roller moves its barrel about its axis only: every vertex keeps its distance
    to the axis and its position along it; the outermost ring touches the unit sphere."""
    layout = roller_layout()
    still = roller_quads(layout, np.zeros(len(layout.radius)))
    turned = roller_quads(layout, np.full(len(layout.radius), 0.7))
    for k in (0, 30, 100):
        hub = (1 - layout.radius[k]) * layout.centre[k]
        (a0, r0), (a1, r1) = (cylindrical(q[k], hub, layout.axis[k]) for q in (still, turned))
        np.testing.assert_allclose(np.sort(a1), np.sort(a0), atol=GEOMETRY_TOL)
        np.testing.assert_allclose(np.sort(r1), np.sort(r0), atol=GEOMETRY_TOL)
        assert np.max(np.linalg.norm(still[k].reshape(-1, 3), axis=1)) == pytest.approx(1.0)
        assert not np.allclose(still[k], turned[k])


def cylindrical(quads, origin, axis):
    """Position along ``axis`` and distance from it of every vertex."""
    d = quads.reshape(-1, 3) - origin
    along = d @ axis
    return along, np.linalg.norm(d - np.outer(along, axis), axis=1)


def test_the_shell_turns_by_the_angle_it_is_given(paper):
    """draw_shell takes chi from its caller: the seam (the shell's meridian at azimuth 0) is drawn
    where the rotor's frame turned by chi about e3 puts it."""
    times = paper.t[::25]
    geom = frame_geometry(paper, times)
    chi = np.linspace(0.0, 3.0, len(times))
    fig = Figure()
    ax = fig.add_subplot(projection="3d")
    draw = draw_shell(ax, geom, chi, (22.0, -60.0))
    back, front = ax.collections[-2:]
    for i in range(len(times)):
        draw(i)
        segs = [np.asarray(s) for c in (back, front) for s in c._segments3d]
        seam = [s for s, col in zip(segs, _colours(back, front), strict=True)
                if np.allclose(col[:3], to_rgb(SEAM))]  # fmt: skip
        c, s = np.cos(chi[i]), np.sin(chi[i])
        seam_dir = geom.Q[i] @ np.array([c, s, 0.0])  # the seam's equator point, fixed frame
        points = np.concatenate(seam)
        r = (points - geom.centre[i]) / geom.R
        np.testing.assert_allclose(np.linalg.norm(r, axis=1), 1.0, atol=GEOMETRY_TOL)
        # every seam point lies in the plane of e3 and the turned e1
        normal = np.cross(geom.Q[i][:, 2], seam_dir)
        assert np.max(np.abs(r @ normal)) < GEOMETRY_TOL
        assert np.max(r @ seam_dir) > 0.99  # on the side of the turned e1
    with pytest.raises(ValueError, match="chi has shape"):
        draw_shell(ax, geom, chi[:-1], (22.0, -60.0))


def _colours(*collections):
    return [c for coll in collections for c in coll.get_edgecolor()]


def test_the_shell_look_feeds_the_meridian_spin(paper, monkeypatch):
    """shell_look hands draw_shell the spin of rollingtop.devices, at the frame times."""
    from rollingtop.plot.looks import _shell

    seen = {}

    def spy(ax, geom, chi, view):
        seen["chi"], seen["t"] = chi, geom.times
        return lambda i: None

    monkeypatch.setattr(_shell, "draw_shell", spy)
    times = paper.t[::10]
    fig = Figure()
    _shell.shell_look(fig.add_subplot(projection="3d"), frame_geometry(paper, times), paper,
                      (22.0, -60.0))  # fmt: skip
    expected = shell_spin_angle(paper.t, paper.body, paper.y)[::10]
    np.testing.assert_allclose(seen["chi"], expected, atol=GEOMETRY_TOL)
