"""Trajectory: derived quantities, summary, NetCDF and CSV export, atomic writes."""

import json
import os

import numpy as np
import pytest
import xarray as xr

from rollingtop import OutputError, load_scenario, simulate
from rollingtop.dynamics.integrals import natural_scales

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


# ---- in a notebook -------------------------------------------------------------------------
def test_repr_is_one_short_line(traj):
    text = repr(traj)
    assert text == f"<Trajectory: meridian model, t = 0 .. 5, {len(traj.t)} samples>"


def test_html_view_shows_each_integrals_drift(traj):
    """Every first integral's initial value and its largest drift, absolute and relative to the
    integral's natural size, as recomputed here from the samples; the body, the run, the contact."""
    from .html_view import num, read

    view = read(traj._repr_html_())
    assert view.title == "rollingtop.Trajectory" and view.subtitle.startswith("meridian model")
    (body,) = view.records("body")
    assert {k: num(v) for k, v in body.items()} == pytest.approx(traj.body.to_dict(), rel=1e-5)
    (motion,) = view.records("motion")
    assert int(motion["samples"]) == len(traj.t) == 51 and num(motion["t_end"]) == traj.t[-1]
    assert int(motion["steps"]) == traj.stats["steps"]
    rows = {row["integral"]: row for row in view.records("first integrals along the samples")}
    assert set(rows) == set(traj.integrals) == {"energy", "lagrange", "jellett", "area", "F6"}
    for name, values in traj.integrals.items():
        drift = float(np.max(np.abs(values - values[0])))
        row = rows[name]
        assert num(row["initial"]) == pytest.approx(values[0], rel=5e-6)
        assert num(row["max |I - I0|"]) == pytest.approx(drift, rel=5e-3)
        size = natural_scales(traj.body, traj.y, (name,))[name]  # tested in test_integrals
        assert size >= np.max(np.abs(values))
        assert num(row["max |I - I0| / size"]) == pytest.approx(drift / size, rel=5e-3)
        assert drift / size < 1e-8  # rtol 1e-10 over 5 time units
    (contact,) = view.records("contact")
    least = min(np.min(traj.normal_force), traj.step_reactions["min_normal_force"])
    assert num(contact["min normal force"]) == pytest.approx(least, rel=5e-6)
    assert contact["contact lost at"] == "–"


def test_plot_draws_each_panel_of_the_command_lines_figures(traj):
    """``path``: the contact point's and the centre of mass's paths (``rollingtop path``);
    ``gamma3``, ``drift``, ``reactions``: the panels of ``rollingtop plot``."""
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes

    from rollingtop import RollingTopError

    def line(ax, label):
        (found,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
        return np.column_stack(found.get_data()).astype(float)

    try:
        ax = traj.plot()
        assert isinstance(ax, Axes)
        np.testing.assert_array_equal(line(ax, "contact point"), traj.contact_point)
        np.testing.assert_array_equal(line(ax, "centre of mass"), traj.position)
        ax = traj.plot(kind="drift")
        for name, values in traj.integrals.items():
            drift = np.abs(values - values[0]) / np.max(np.abs(values))
            np.testing.assert_allclose(line(ax, name)[:, 1], np.maximum(drift, 1e-17), rtol=1e-12)
        assert ax.get_yscale() == "log" and ax.get_xlabel() == "t"
        _, given = plt.subplots()
        assert traj.plot(ax=given, kind="gamma3") is given
        (g3,) = given.get_lines()
        np.testing.assert_array_equal(g3.get_ydata(), traj.gamma[:, 2])
        ax = traj.plot(kind="reactions")
        np.testing.assert_allclose(line(ax, "normal force N")[:, 1], traj.normal_force)
        with pytest.raises(RollingTopError, match="kind = 'energy': one of 'path'"):
            traj.plot(kind="energy")
    finally:
        plt.close("all")
