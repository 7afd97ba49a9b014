"""``rollingtop section`` and ``rollingtop chaos``: JSON, outputs, one-line errors (exit 2)."""

import json

import numpy as np
import pytest
import xarray as xr

from ..conftest import EXAMPLES
from ..test_cli import run_cli

CHAOTIC = str(EXAMPLES / "chaotic.toml")
PAPER = str(EXAMPLES / "paper.toml")
#: An initial gamma or omega (O(1)) after the state's normalisation and projection: a few ulps.
STATE_ATOL = 1e-15


def test_section_json_figure_and_netcdf(capsys, tmp_path):
    fig, nc = tmp_path / "s.png", tmp_path / "s.nc"
    code, out, err = run_cli(capsys, "section", CHAOTIC, "-o", str(fig), "--crossings", "50",
                             "--trajectories", "3", "--netcdf", str(nc), "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert summary["crossings_found"] == 150
    assert summary["max_abs_w_tau"] <= 1e-11
    assert summary["held"] == ["energy", "area", "momentum_x", "momentum_y"]
    assert fig.stat().st_size > 0
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds["gamma3"].shape == (3, 50)


def test_chaos_json_and_time_series(capsys, tmp_path):
    nc = tmp_path / "c.nc"
    code, out, err = run_cli(capsys, "chaos", PAPER, "--t-end", "200", "--samples", "20",
                             "-o", str(nc), "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert set(summary) >= {"lyapunov", "megno", "wall_time_s", "compile_time_s"}
    assert 0 < summary["lyapunov"] < 0.05
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        assert ds["lyapunov"].shape == (20,)
        assert float(ds["lyapunov"][-1]) == pytest.approx(summary["lyapunov"])
        assert np.isfinite(ds["megno_mean"]).all()


@pytest.mark.parametrize(
    "args, message",
    [
        (["chaos", CHAOTIC, "--t-end", "-1"], "t_end"),
        (["chaos", CHAOTIC, "--samples", "0"], "samples"),
        (["chaos", CHAOTIC, "-o", "out.txt"], "unknown output format"),
        (["section", CHAOTIC, "-o", "fig.png", "--crossings", "0"], "crossings"),
        (["section", CHAOTIC, "-o", "fig.txt"], "unknown output format"),
        (["section", CHAOTIC, "-o", "fig.png", "--hold", "routh"], "routh"),
        (["section", "missing.toml", "-o", "fig.png"], "missing.toml"),
    ],
)
def test_bad_input_is_one_line_with_status_2(capsys, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *args)
    assert code == 2
    assert message in err
    assert err.count("\n") == 1
    assert not list(tmp_path.iterdir())


def test_chaos_phase_volume(capsys):
    from rollingtop.chaos.divergence import phase_volume
    from rollingtop.scenario import load_scenario

    scenario = str(EXAMPLES / "parallel_chaotic.toml")
    code, out, err = run_cli(capsys, "chaos", scenario, "--t-end", "20", "--phase-volume", "401",
                             "--json")  # fmt: skip
    assert code == 0, err
    volume = json.loads(out)["phase_volume"]
    sc = load_scenario(scenario)
    expected = phase_volume(sc.body, sc.model, sc.require_state(), t_end=20.0, samples=401)
    assert volume["mean_divergence"] == pytest.approx(expected.mean[-1], rel=1e-12)
    assert volume["dimension"] == 7
    code, _, err = run_cli(capsys, "chaos", scenario, "--phase-volume", "1")
    assert code == 2 and "--phase-volume" in err


def test_section_reports_the_motions_that_would_leave_the_plane(capsys, tmp_path):
    """A trajectory whose normal force turns negative is counted (JSON ``contact_lost``), named
    in one warning line and drawn with open circles; its minimum normal force agrees with a
    single run of simulate over the same time (an independent path through the integrator)."""
    import warnings

    from rollingtop import ContactLostWarning, simulate
    from rollingtop.scenario import load_scenario

    scenario = EXAMPLES / "parallel_chaotic.toml"
    fig, nc = tmp_path / "s.png", tmp_path / "s.nc"
    args = ["-o", str(fig), "--crossings", "20", "--trajectories", "4", "--netcdf", str(nc)]
    code, out, err = run_cli(capsys, "section", str(scenario), *args, "--json")
    assert code == 0, err
    summary = json.loads(out)
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        least = ds["min_normal_force"].values
        starts, t_last = ds["initial_state"].values, ds["t_last"].values
    assert summary["contact_lost"] == int(np.sum(least < 0)) >= 1  # measured: 1 of 4
    assert f"{summary['contact_lost']} of 4 trajectories need a negative normal force" in err
    # one line (besides a compile notice, printed where this test is the first to compile the
    # section kernels: it depends on the order of the tests and the state of the cache)
    assert len([ln for ln in err.splitlines() if not ln.startswith("rollingtop: compiling")]) == 1
    sc = load_scenario(scenario)
    for y0, t, f in zip(starts, t_last, least, strict=True):
        with warnings.catch_warnings():  # the lost contact is what is measured here
            warnings.simplefilter("ignore", ContactLostWarning)
            run = simulate(sc.body, sc.model, y0, t_end=float(t), rtol=1e-10, samples=20001)
        # the section's minimum is over the steps' ends, the run's over 20001 samples: both
        # points of the motion near its minimum (measured apart by up to 0.01), same sign here
        sampled = float(np.min(run.normal_force))
        assert sampled == pytest.approx(f, abs=0.02)
        assert (sampled < 0) == (f < 0)


def test_section_names_the_trajectories_that_stop_early(capsys, tmp_path):
    """Each trajectory stopped before its crossings is named, with its initial values, the
    crossings it found, where it stopped and why; one trajectory is "1 trajectory"."""
    fig = tmp_path / "s.png"
    args = ["section", CHAOTIC, "-o", str(fig), "--trajectories", "1", "--t-max", "60"]
    code, out, err = run_cli(capsys, *args, "--crossings", "14", "--json")
    assert code == 0, err
    (stopped,) = json.loads(out)["stopped_early"]
    # measured: the scenario's own state crosses 13 times before t = 60 (t_last: the stepper
    # ends at t_max exactly); gamma and omega as built by initial_state from the file's values
    assert stopped == {"trajectory": 0, "crossings": 13, "t_last": 60.0, "status": 0,
                       "reason": "t_max reached",
                       "gamma": pytest.approx([0.6, 0.0, 0.8], abs=STATE_ATOL),
                       "omega": pytest.approx([0.2, 0.6, 0.3], abs=STATE_ATOL)}  # fmt: skip
    code, out, err = run_cli(capsys, *args, "--crossings", "14")
    assert code == 0, err
    assert out.splitlines()[1:3] == [
        "1 trajectory stopped before 14 crossings:",
        "  trajectory 0 (gamma = [0.6, 0, 0.8], omega = [0.2, 0.6, 0.3]): 13 crossings, "
        "stopped at t = 60: t_max reached",
    ]
    code, out, err = run_cli(capsys, *args, "--crossings", "13")
    assert code == 0 and "stopped before" not in out


def test_stopped_lines_count_and_cut():
    """Plural and singular, and at most MAX_NAMED trajectories named (the rest counted)."""
    from rollingtop.cli._chaos import MAX_NAMED, _stopped_lines

    one = {"trajectory": 4, "crossings": 1, "t_last": 2.5, "status": 1,
           "reason": "max_steps reached", "gamma": [0.0, 0.6, 0.8],
           "omega": [1.0, 0.0, 0.0]}  # fmt: skip
    assert _stopped_lines([], 1) == []
    assert _stopped_lines([one], 1) == [
        "1 trajectory stopped before 1 crossing:",
        "  trajectory 4 (gamma = [0, 0.6, 0.8], omega = [1, 0, 0]): 1 crossing, stopped at "
        "t = 2.5: max_steps reached",
    ]
    lines = _stopped_lines([one] * (MAX_NAMED + 3), 1000)
    assert lines[0] == f"{MAX_NAMED + 3} trajectories stopped before 1000 crossings:"
    assert len(lines) == MAX_NAMED + 2
    assert lines[-1] == "  ... and 3 more (--json lists every one)"
