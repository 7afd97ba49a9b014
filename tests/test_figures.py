"""Figure commands: each writes the library's figure of the scenario and options it is given (the
PNG holds the figure's pixels; the figure shows that motion); the animation has duration x fps
frames. What each figure plots is held to independent values in tests/plot/."""

import imageio_ffmpeg
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image, ImageSequence

from rollingtop import SphericalTop
from rollingtop.reduction import LevelSet, orbits

from .conftest import EXAMPLES, PAPER_BODY
from .test_cli import run_cli

#: Mean absolute difference per channel (0..255) between the written PNG and the figure drawn
#: again (measured: 0, PNG is lossless).
IMAGE_TOL = 0.05
#: Relative change of the energy over the plotted motions (paper.toml integrates at rtol 1e-10:
#: measured 1.0e-10; pole.toml at 1e-12).
ENERGY_DRIFT = 1e-9


@pytest.fixture
def saved(monkeypatch):
    """The figures the command line saves, in order (they are saved as well)."""
    figures = []
    savefig = Figure.savefig

    def record(fig, *args, **kwargs):
        figures.append(fig)
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return figures


def run_figure(capsys, tmp_path, saved, command, scenario, *extra):
    """Run a figure command to a PNG; the written pixels must be the saved figure's."""
    out = tmp_path / "fig.png"
    code, stdout, err = run_cli(capsys, command, str(EXAMPLES / scenario), "-o", str(out), *extra)
    assert code == 0, err
    assert f"wrote {out}" in stdout
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary file left
    (fig,) = saved
    fig.set_dpi(200)  # save_figure's default
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    pixels = np.asarray(Image.open(out).convert("RGBA")).astype(int)
    expected = np.asarray(canvas.buffer_rgba())
    assert pixels.shape == expected.shape
    assert np.mean(np.abs(pixels - expected)) < IMAGE_TOL
    return fig


def line(ax, label):
    (found,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
    return np.column_stack([np.asarray(d, dtype=float) for d in found.get_data()])


def test_path_command_draws_the_periods_asked_for(capsys, tmp_path, saved):
    """--periods 8 on the Fig. 5 level: eight periods of the reduction's orbit, the CoM once per
    period on the predicted circle."""
    fig = run_figure(capsys, tmp_path, saved, "path", "fig5.toml", "--periods", "8")
    ax = fig.axes[0]
    fig5 = LevelSet(SphericalTop(**PAPER_BODY), M3=1.0, C1=0.5, C2=-2.0)
    (orbit,) = [
        o for o in orbits(fig5, 4.0) if o.gamma3_min < 0
    ]  # the scenario starts at the lowest
    assert f"t = 0 .. {8 * orbit.period:g} " in ax.get_title()
    dots = line(ax, "CoM once per period (min of $\\gamma_3$)")
    assert len(dots) in (7, 8)  # t = T, 2T, ..., and 8T unless round-off puts it past t_end
    circle = line(ax, "predicted circle")
    centre = circle[:-1].mean(axis=0)
    radius = np.hypot(*(circle[0] - centre))
    np.testing.assert_allclose(np.hypot(*(dots - centre).T), radius, rtol=1e-9)


def test_plot_command_integrates_to_t_end(capsys, tmp_path, saved):
    """--t-end 10 on the south pole case: gamma3 from t = 0 to 10, reaching the pole gamma3 = 1,
    with the energy conserved."""
    fig = run_figure(capsys, tmp_path, saved, "plot", "pole.toml", "--t-end", "10")
    ax1, ax2, _ = fig.axes
    (g3,) = ax1.get_lines()
    t, gamma3 = (np.asarray(d, dtype=float) for d in g3.get_data())
    assert (t[0], t[-1]) == (0.0, 10.0)
    assert 1 - gamma3.max() < 1e-5
    assert np.max(line(ax2, "energy")[:, 1]) < ENERGY_DRIFT


def test_compare_command_runs_every_model_from_the_scenarios_state(capsys, tmp_path, saved):
    fig = run_figure(capsys, tmp_path, saved, "compare", "paper.toml", "--t-end", "10")
    paths, energy, *_ = fig.axes
    for model in ("meridian", "smooth", "rough"):
        np.testing.assert_array_equal(line(paths, model)[0], (0.0, 0.0))  # paper.toml's position
        change = line(energy, f"{model} (conserved)")
        assert change[-1, 0] == 10.0
        assert np.max(np.abs(change[:, 1])) < ENERGY_DRIFT


@pytest.mark.parametrize(
    ("suffix", "fps", "duration"),
    [(".gif", 8, 1.5), pytest.param(".mp4", 10, 1.2, marks=pytest.mark.slow)],
)
def test_animation_frame_count(capsys, tmp_path, suffix, fps, duration):
    out = tmp_path / f"roll{suffix}"
    code, stdout, err = run_cli(capsys, "animate", str(EXAMPLES / "paper.toml"), "-o", str(out),
                                "--fps", str(fps), "--duration", str(duration), "--speed",
                                "2")  # fmt: skip
    assert code == 0, err
    expected = round(fps * duration)
    if suffix == ".gif":
        frames = sum(1 for _ in ImageSequence.Iterator(Image.open(out)))
    else:
        frames, _ = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert frames == expected
    assert f"({expected} frames)" in stdout


def test_animation_refuses_bad_options(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for args, message in (
        (["-o", "roll.avi"], "unknown output format '.avi'"),
        (["-o", "roll.gif", "--fps", "0"], "--fps"),
        (["-o", "roll.gif", "--camera", "drone"], "--camera"),
    ):
        code, out, err = run_cli(capsys, "animate", str(EXAMPLES / "paper.toml"), *args)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_animation_looks(capsys, tmp_path):
    """Each device renders (frames counted); the command line names the library's looks."""
    from rollingtop.cli._figures import LOOKS as CLI_LOOKS
    from rollingtop.plot.looks import LOOKS

    assert CLI_LOOKS == tuple(LOOKS)
    for look in ("roller", "shell", "skates"):
        out = tmp_path / f"{look}.gif"
        args = ["-o", str(out), "--fps", "4", "--duration", "0.5", "--look", look]
        code, stdout, err = run_cli(capsys, "animate", str(EXAMPLES / "paper.toml"), *args)
        assert code == 0, err
        assert sum(1 for _ in ImageSequence.Iterator(Image.open(out))) == 2


def test_animation_devices_need_the_meridian_model(capsys, tmp_path, monkeypatch):
    """Refused in one line, exit 2, before anything is integrated or written."""
    import rollingtop.cli._figures as figures

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(figures, "run_scenario", lambda *a, **k: pytest.fail("integrated"))
    for look in ("roller", "shell", "skates"):
        code, out, err = run_cli(capsys, "animate", str(EXAMPLES / "smooth.toml"), "-o",
                                 "roll.gif", "--look", look)  # fmt: skip
        assert code == 2 and "constraint of model 'meridian'" in err
        assert len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_animation_shell_refuses_a_pole_passage(capsys, tmp_path):
    code, out, err = run_cli(capsys, "animate", str(EXAMPLES / "pole.toml"), "-o",
                             str(tmp_path / "roll.gif"), "--look", "shell", "--duration", "2",
                             "--fps", "4")  # fmt: skip
    assert code == 2 and "a shell would spin infinitely fast" in err
    assert len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
