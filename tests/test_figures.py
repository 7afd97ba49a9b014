"""Pictures: every figure command writes a non-empty file of the requested format; the
animation has duration x fps frames."""

import imageio_ffmpeg
import pytest
from PIL import Image, ImageSequence

from .conftest import EXAMPLES
from .test_cli import run_cli

MAGIC = {".png": b"\x89PNG", ".svg": b"<?xml", ".pdf": b"%PDF"}


@pytest.mark.parametrize(
    ("command", "scenario", "extra"),
    [
        ("path", "fig5.toml", ["--periods", "8"]),
        ("plot", "pole.toml", ["--t-end", "10"]),
        ("compare", "paper.toml", ["--t-end", "10"]),
    ],
)
@pytest.mark.parametrize("suffix", [".png", ".svg", ".pdf"])
def test_figure_commands(capsys, tmp_path, command, scenario, extra, suffix):
    out = tmp_path / f"fig{suffix}"
    code, stdout, err = run_cli(capsys, command, str(EXAMPLES / scenario), "-o", str(out), *extra)
    assert code == 0, err
    assert out.read_bytes().startswith(MAGIC[suffix]) and out.stat().st_size > 5000
    assert f"wrote {out}" in stdout
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary file left


@pytest.mark.parametrize(("suffix", "fps", "duration"), [(".gif", 8, 1.5), (".mp4", 10, 1.2)])
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
