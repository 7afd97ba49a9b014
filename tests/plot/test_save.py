"""Saving a figure: the format follows the suffix, and a PNG holds the figure's own pixels."""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from rollingtop.plot import save_figure

MAGIC = {".png": b"\x89PNG", ".svg": b"<?xml", ".pdf": b"%PDF"}
#: Mean absolute difference per channel (0..255) between two images held to be the same
#: (measured: 0, PNG is lossless); recolouring the curve alone changes it by ~1.
IMAGE_TOL = 0.05


def figure():
    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    t = np.linspace(0, 2 * np.pi, 50)
    ax.plot(t, np.sin(t), color="crimson")
    ax.set_title("sin")
    return fig


def rendered(fig, dpi):
    """The figure drawn by Agg at ``dpi``, RGBA pixels."""
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


@pytest.mark.parametrize("suffix", list(MAGIC))
def test_format_follows_the_suffix(tmp_path, suffix):
    out = save_figure(figure(), tmp_path / f"fig{suffix.upper()}")
    assert out.read_bytes().startswith(MAGIC[suffix])
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary file left


def test_png_holds_the_figures_pixels(tmp_path):
    fig = figure()
    out = save_figure(fig, tmp_path / "fig.png", dpi=100)
    pixels = np.asarray(Image.open(out).convert("RGBA"))
    expected = rendered(fig, 100)
    assert pixels.shape == expected.shape == (200, 300, 4)
    assert np.mean(np.abs(pixels.astype(int) - expected)) < IMAGE_TOL
    # and the comparison sees a change: the curve in another colour
    fig.axes[0].get_lines()[0].set_color("navy")
    assert np.mean(np.abs(pixels.astype(int) - rendered(fig, 100))) > 10 * IMAGE_TOL
