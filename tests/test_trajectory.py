"""Trajectory: derived quantities, summary, NetCDF and CSV export, atomic writes."""

import json
import os

import numpy as np
import pytest
import xarray as xr

from rollingtop import OutputError, load_scenario, simulate

from .conftest import EXAMPLES


@pytest.fixture(scope="module")
def traj():
    return simulate(load_scenario(EXAMPLES / "paper.toml"), t_end=5.0, samples=51)


def test_contact_point_is_the_lowest_point(traj):
    """Contact point = CoM + r in the fixed frame, r = -R gamma - a (body frame)."""
    body = traj.body
    for y, cp in zip(traj.y[::10], traj.contact_point[::10], strict=True):
        Q = y[6:15].reshape(3, 3)  # rows alpha, beta, gamma: body -> fixed components
        r = -body.R * y[12:15] - np.array([0, 0, body.a3])
        r_fixed = Q @ r
        np.testing.assert_allclose(cp, y[15:17] + r_fixed[:2], atol=1e-14)
        # the CoM height equals -(r, gamma): the contact point lies on the plane z = 0
        assert r_fixed[2] == pytest.approx(-(body.R + body.a3 * y[14]), abs=1e-14)


def test_summary_contract(traj):
    s = traj.summary()
    assert set(s) == {"model", "t_end", "final", "integrals", "constraints", "reactions", "stats"}
    assert set(s["final"]) == {
        "t",
        "v",
        "omega",
        "alpha",
        "beta",
        "gamma",
        "position",
        "contact_point",
    }
    for row in s["integrals"].values():
        assert {"initial", "final", "max_abs_drift"} <= set(row)
    assert {"max_abs_residual", "orthonormality_max_error"} <= set(s["constraints"])
    assert {"min_normal_force", "max_friction_ratio"} <= set(s["reactions"])
    assert {"steps", "rejected_steps", "rhs_evals", "wall_time_s"} <= set(s["stats"])
    json.dumps(s, allow_nan=False)
    np.testing.assert_allclose(s["final"]["v"], traj.y[-1, 0:3])
    assert s["t_end"] == 5.0 and s["model"] == "meridian"


def test_netcdf_round_trip(traj, tmp_path):
    path = traj.save(tmp_path / "run.nc")
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        np.testing.assert_array_equal(ds["t"].values, traj.t)
        np.testing.assert_array_equal(ds["gamma"].values, traj.gamma)
        np.testing.assert_array_equal(ds["F6"].values, traj.integrals["F6"])
        assert ds.attrs["model"] == "meridian"
        assert ds.attrs["body_a3"] == 0.1
        assert ds["v"].attrs["units"] == "L T-1"
        assert json.loads(ds.attrs["summary_json"])["t_end"] == 5.0
    assert not list(tmp_path.glob(".*tmp"))


def test_csv_round_trip(traj, tmp_path):
    path = traj.save(tmp_path / "run.csv")
    lines = path.read_text().splitlines()
    header = [line for line in lines if not line.startswith("#")][0].split(",")
    assert header[:4] == ["t", "v1", "v2", "v3"] and "energy" in header
    data = np.loadtxt(
        path, delimiter=",", comments="#", skiprows=1 + sum(line.startswith("#") for line in lines)
    )
    np.testing.assert_array_equal(data[:, 0], traj.t)
    np.testing.assert_array_equal(data[:, header.index("gamma3")], traj.gamma[:, 2])
    assert "# model = meridian" in lines


def test_failed_write_leaves_nothing(traj, tmp_path, monkeypatch):
    target = tmp_path / "run.nc"
    target.write_text("previous")

    real_write = os.write

    def broken(fd, data):  # part of the file goes out, then the run is interrupted
        real_write(fd, bytes(data[:7]))
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "write", broken)
    with pytest.raises(KeyboardInterrupt):
        traj.save(target)
    assert target.read_text() == "previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


@pytest.mark.parametrize(
    ("name", "message"),
    [("run.txt", "unknown output format '.txt'"), ("missing/run.nc", "does not exist")],
)
def test_bad_output_path(traj, tmp_path, name, message):
    with pytest.raises(OutputError, match=message):
        traj.save(tmp_path / name)
