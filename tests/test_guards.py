"""Issue 27's table, the cases fixed so far: each ends with one error line and exit 2, in a real
process (no traceback), and leaves no file behind."""

import subprocess
import sys

import pytest

from .conftest import EXAMPLES


def _scenario(tmp_path, name, **replace):
    text = (EXAMPLES / f"{name}.toml").read_text()
    for old, new in replace.items():
        text = text.replace(old, new)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            lambda d: [
                "chaos",
                str(EXAMPLES / "parallel_chaotic.toml"),
                "--samples",
                "99999999999",
            ],
            "needs about 30.6 TiB of memory",
        ),  # fmt: skip
        (
            lambda d: ["chaos", str(EXAMPLES / "parallel_chaotic.toml"), "--samples", "1000000000"],
            "needs about 312.9 GiB of memory",
        ),  # fmt: skip
        (
            lambda d: [
                "bifurcation",
                _scenario(d, "fig5", **{"I1 = 0.3": "I1 = 1e300", "I3 = 0.5": "I3 = 1.5e300"}),
            ],
            "too large for double precision",
        ),  # fmt: skip
        (
            lambda d: ["stability", _scenario(d, "paper", **{"R = 1.0": "R = 1e300"})],
            "overflows double precision",
        ),
    ],
    ids=["chaos_745_GiB", "chaos_24_GB", "bifurcation_I_1e300", "stability_R_1e300"],
)
def test_a_size_or_an_overflow_is_one_line(tmp_path, args, message):
    argv = args(tmp_path)  # writes its scenario first
    before = set(tmp_path.iterdir())
    proc = subprocess.run([sys.executable, "-m", "rollingtop", *argv], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in proc.stderr
    assert set(tmp_path.iterdir()) == before


def test_a_wide_window_and_a_runaway_time_scale_are_one_line(tmp_path):
    """bifurcation --h-range -1e308,1e308 (a grid whose spacing overflows: pcolormesh's
    traceback) and simulate with g = 1e50 (1.5e26 periods of its pendulum rate in t_end = 50:
    it ran for hours) end at once with one line; no figure is written."""
    cases = [
        (["bifurcation", str(EXAMPLES / "fig5.toml"), "--h-range", "-1e308,1e308", "-o",
          "b.png"], "h range (-1e+308, 1e+308) must be finite and increasing, and its width"),
        (["bifurcation", str(EXAMPLES / "fig5.toml"), "--c2-range", "-1e308,1e308"],
         "C2 range"),
        (["simulate", _scenario(tmp_path, "paper", **{"g = 1.0": "g = 1e50"}), "-o", "r.nc"],
         "more than max_steps = 100000000 steps"),
    ]  # fmt: skip
    for argv, message in cases:
        before = set(tmp_path.iterdir())
        proc = subprocess.run([sys.executable, "-m", "rollingtop", *argv], cwd=tmp_path,
                              capture_output=True, text=True, timeout=120)  # fmt: skip
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], proc.stderr
        assert set(tmp_path.iterdir()) == before


def test_section_writes_its_figure_and_its_data_both_or_neither(tmp_path):
    """section -o sec.png --netcdf out/sec.nc where the NetCDF cannot be written (its folder
    read-only): one line naming the NetCDF, exit 1, and no PNG left behind (it was)."""
    import os

    if os.geteuid() == 0:  # root writes into a read-only folder: a missing folder instead
        target = tmp_path / "missing" / "sec.nc"
    else:
        (tmp_path / "out").mkdir()
        (tmp_path / "out").chmod(0o500)
        target = tmp_path / "out" / "sec.nc"
    before = set(tmp_path.iterdir())
    proc = subprocess.run([sys.executable, "-m", "rollingtop", "section",
                           str(EXAMPLES / "section_parallel.toml"), "-o", "sec.png",
                           "--netcdf", str(target), "--trajectories", "2", "--crossings", "3"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)  # fmt: skip
    assert proc.returncode in (1, 2), proc.stderr
    lines = [ln for ln in proc.stderr.strip().splitlines() if "error" in ln]
    assert len(lines) == 1 and "sec.nc" in lines[0], proc.stderr
    assert set(tmp_path.iterdir()) == before and not (tmp_path / "sec.png").exists()


def test_write_together_publishes_all_or_nothing(tmp_path):
    """rollingtop.io.write_together: a second writer that fails (ENOSPC) leaves neither file nor
    any temporary behind, and an existing file unchanged; both succeed: both published."""
    import errno

    from rollingtop.io import WriteFailed, write_together

    first, second = tmp_path / "a.png", tmp_path / "b.nc"
    second.write_bytes(b"old")

    def full(tmp):
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(WriteFailed, match="b.nc"):
        write_together([(first, lambda tmp: tmp.write_bytes(b"png")), (second, full)])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.nc"]
    assert second.read_bytes() == b"old"
    write_together([(first, lambda tmp: tmp.write_bytes(b"png")),
                    (second, lambda tmp: tmp.write_bytes(b"new"))])  # fmt: skip
    assert first.read_bytes() == b"png" and second.read_bytes() == b"new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.nc"]
