"""The parameter atlas on Dask (rollingtop.atlas): the same cells as in-process and as an
independent count of steady motions, resumable, atomic, and bad specs refused in one line."""

import json
import math
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
import xarray as xr

from rollingtop import SphericalTop
from rollingtop.atlas import (
    AtlasError,
    atlas,
    atlas_spec_from_dict,
    classify_in_process,
)
from rollingtop.reduction import LevelSet, steady_motions

from .conftest import local_cluster
from .reduction.test_models import _mp_potential
from .test_cli import run_cli

BODY = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}


def spec_dict(axes, level=None):
    return {"body": dict(BODY), "contact": {"model": "meridian"},
            "level": level or {"M3": 1.0, "C1": 0.5, "C2": -2.0}, "axes": axes}  # fmt: skip


SMALL = {"a3": [0.05, 0.2], "C2": {"start": -3.0, "stop": 0.0, "num": 4}, "C1": [0.0, 0.5, 1.0]}


@pytest.fixture(scope="module")
def client():
    from distributed import Client

    with local_cluster(2) as cluster, Client(cluster) as c:
        yield c


def test_cells_match_steady_motions():
    """Each classified cell's counts equal those of steady_motions (an independent search on a
    finer grid) for the same body and level."""
    spec = atlas_spec_from_dict(spec_dict(SMALL))
    ds = classify_in_process(spec)
    assert list(ds["n_steady"].dims) == ["a3", "C2", "C1"]
    for a3 in SMALL["a3"]:
        for c2 in ds["C2"].values:
            for c1 in SMALL["C1"]:
                cell = ds.sel(a3=a3, C2=c2, C1=c1)
                if c1 == 1.0:  # the pole line C1 = M3
                    assert int(cell["status"]) == 2 and int(cell["n_steady"]) == -1
                    continue
                body = SphericalTop(**{**BODY, "a3": a3})
                motions = steady_motions(LevelSet(body, 1.0, c1, float(c2)))
                assert int(cell["status"]) == 0
                assert int(cell["n_steady"]) == len(motions)
                assert int(cell["n_centres"]) == sum(m.type == "center" for m in motions)
                assert int(cell["n_saddles"]) == sum(m.type == "saddle" for m in motions)
                centres = [m for m in motions if m.type == "center"]
                for k, m in enumerate(centres):
                    assert float(cell["rotation_centre"][k]) == pytest.approx(
                        m.precession_rate / m.frequency, rel=1e-12)  # fmt: skip


def test_dask_equals_in_process(client, tmp_path):
    spec = atlas_spec_from_dict(spec_dict(SMALL))
    expected = classify_in_process(spec)
    seen = []
    ds = atlas(spec, tmp_path / "a.nc", client=client, chunk=5,
               progress=lambda done, n: seen.append((done, n)))  # fmt: skip
    assert ds.identical(expected)
    with xr.open_dataset(tmp_path / "a.nc") as f:
        assert f["n_steady"].equals(expected["n_steady"])
        assert f["rotation_centre"].equals(expected["rotation_centre"])
    assert seen[-1] == (spec.size, spec.size)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.nc"]  # partial folder removed


def test_zarr_output(client, tmp_path):
    spec = atlas_spec_from_dict(spec_dict({"C2": [-2.0, -1.0]}))
    atlas(spec, tmp_path / "a.zarr", client=client)
    with xr.open_zarr(tmp_path / "a.zarr") as f:
        assert f["n_steady"].values.tolist() == [3, 1]


def test_an_interrupted_run_resumes_without_recomputing(client, tmp_path):
    spec = atlas_spec_from_dict(spec_dict(SMALL))
    out = tmp_path / "a.nc"

    def stop_after_two_chunks(done, n):
        if done >= 10:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atlas(spec, out, client=client, chunk=5, progress=stop_after_two_chunks)
    assert not out.exists()
    saved = sorted((tmp_path / "a.nc.partial").glob("chunk-*.npz"))
    assert len(saved) >= 2
    first = []
    ds = atlas(spec, out, client=client, chunk=5, progress=lambda d, n: first.append(d))
    assert first[0] == 5 * len(saved)  # the saved chunks count as done from the start
    assert ds.identical(classify_in_process(spec))
    assert out.exists() and not (tmp_path / "a.nc.partial").exists()


def test_partial_results_of_another_spec_are_not_reused(client, tmp_path):
    spec = atlas_spec_from_dict(spec_dict(SMALL))
    (tmp_path / "a.nc.partial").mkdir()
    (tmp_path / "a.nc.partial" / "spec.json").write_text(json.dumps({"digest": "other"}))
    with pytest.raises(AtlasError, match="another spec"):
        atlas(spec, tmp_path / "a.nc", client=client)


@pytest.mark.parametrize(
    ("axes", "message"),
    [
        ({}, "missing or empty table"),
        ({"a3": []}, "axes.a3 is empty"),
        ({"foo": [1.0]}, "unknown axis"),
        ({"C2": {"start": 0.0, "stop": 1.0}}, "must be a list or"),
        ({"C2": {"start": 0.0, "stop": 1.0, "num": 0}}, "num = 0"),
        ({"C2": [math.inf]}, "axes.C2 = inf"),
        ({"C2": "x"}, "must be a list"),
    ],
)
def test_bad_axes(axes, message):
    with pytest.raises(AtlasError, match=message):
        atlas_spec_from_dict(spec_dict(axes))


def test_non_symmetric_body_is_refused():
    data = spec_dict({"C2": [0.0]})
    data["body"]["I2"] = 0.35
    with pytest.raises(AtlasError, match="symmetric"):
        atlas_spec_from_dict(data)


def test_inadmissible_bodies_are_cells_not_errors():
    """I3 > 2 I1 breaks the triangle inequality: status 1, not a failure of the whole atlas."""
    ds = classify_in_process(atlas_spec_from_dict(spec_dict({"I3": [0.5, 0.7]})))
    assert ds["status"].values.tolist() == [0, 1]


def _spec_file(tmp_path, axes_toml):
    text = ("[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
            '[contact]\nmodel = "meridian"\n[level]\nM3 = 1.0\nC1 = 0.5\nC2 = -2.0\n'
            f"[axes]\n{axes_toml}\n")  # fmt: skip
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


@pytest.mark.slow
def test_cli_atlas_on_the_embedded_cluster(capsys, tmp_path, monkeypatch):
    """The default: an embedded local cluster of worker processes; it leaves nothing in the
    temporary folder (Dask's ``dask-scratch-space`` stayed there)."""
    import tempfile

    temp = tmp_path / "temp"
    temp.mkdir()
    monkeypatch.setenv("TMPDIR", str(temp))
    monkeypatch.setattr(tempfile, "tempdir", str(temp))
    spec = _spec_file(tmp_path, "C2 = [-2.0, -1.0]\nC1 = [0.0, 0.5]")
    out = tmp_path / "a.nc"
    code, stdout, err = run_cli(capsys, "atlas", str(spec), "-o", str(out), "--workers", "2",
                                "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["dims"] == {"C2": 2, "C1": 2} and summary["classified"] == 4
    with xr.open_dataset(out) as f:
        assert f["n_steady"].values.tolist() == [[3, 3], [1, 1]]
    assert list(temp.iterdir()) == []


@pytest.mark.slow
def test_the_embedded_cluster_stays_quiet_until_its_close_has_ended(monkeypatch):
    """A record Dask logs after ``LocalCluster``'s own ``silence_logs`` has ended (inside its
    close, before its IO loop stops) does not reach Dask's handlers (CI: the scheduler's
    "Batched Comm Closed" of a killed worker and its traceback, after a Ctrl-C); the handlers'
    levels are restored afterwards."""
    import io
    import logging

    from distributed.deploy.spec import SpecCluster

    from rollingtop.atlas._run import _client

    seen = io.StringIO()
    handler = logging.StreamHandler(seen)  # as Dask's own handlers, which write to stderr

    close = SpecCluster._close

    async def close_then_log(self, *args, **kwargs):
        await close(self, *args, **kwargs)
        logging.getLogger("distributed.batched").info("logged after the cluster's close")

    monkeypatch.setattr(SpecCluster, "_close", close_then_log)
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.INFO)  # Dask's default, whatever ran before
    logger.addHandler(handler)
    try:
        with _client(None, 1, None, 10.0):
            pass
        assert seen.getvalue() == "" and handler.level == logging.NOTSET
        logging.getLogger("distributed.batched").info("logged after the run")
        assert seen.getvalue() == "logged after the run\n"
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


@pytest.mark.parametrize(
    ("extra", "axes", "message"),
    [
        ([], "C2 = []", "axes.C2 is empty"),
        (["--scheduler", "tcp://127.0.0.1:1"], "C2 = [0.0]", "cannot reach the Dask scheduler"),
        (["--workers", "0"], "C2 = [0.0]", "--workers 0"),
    ],
)
def test_cli_atlas_errors(capsys, tmp_path, extra, axes, message):
    spec = _spec_file(tmp_path, axes)
    code, out, err = run_cli(capsys, "atlas", str(spec), "-o", str(tmp_path / "a.nc"), *extra)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and message in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.toml"]


def test_a_folder_that_is_not_a_zarr_store_is_not_replaced(tmp_path):
    (tmp_path / "a.zarr").mkdir()
    (tmp_path / "a.zarr" / "precious.txt").write_text("keep me")
    spec = atlas_spec_from_dict(spec_dict({"C2": [0.0]}))
    with pytest.raises(AtlasError, match="not a Zarr store"):
        atlas(spec, tmp_path / "a.zarr")
    assert (tmp_path / "a.zarr" / "precious.txt").read_text() == "keep me"


def test_too_many_local_workers_are_refused(tmp_path):
    import os

    spec = atlas_spec_from_dict(spec_dict({"C2": [0.0]}))
    with pytest.raises(AtlasError, match="per core"):
        atlas(spec, tmp_path / "a.nc", workers=100 * (os.cpu_count() or 1))
    assert list(tmp_path.iterdir()) == []


# ---- a model axis (issue 24): each model's level of one initial state ----------------------

STATE = {"gamma": [0.0, 0.6, 0.8], "omega": [0.7, -0.3, 2.0]}
MODEL_AXES = {"model": ["meridian", "smooth", "rough", "rubber"], "a3": [-0.2, 0.1],
              "I3": [0.5, 0.7]}  # fmt: skip


def state_spec_dict(axes, model="meridian"):
    return {"body": dict(BODY), "contact": {"model": model}, "initial": dict(STATE),
            "axes": axes}  # fmt: skip


def test_a_model_axis_classifies_each_models_level_of_the_state(client, tmp_path):
    """Each cell's counts and centres are those of compare-classification's construction
    (classify_models: the same state under each model, rubber's omega projected), computed here
    independently of the atlas; the Dask run equals the in-process one and the NetCDF keeps the
    model names; an inadmissible body is a cell (status 1), whatever the model."""
    from rollingtop.reduction.classify import classify_models

    spec = atlas_spec_from_dict(state_spec_dict(MODEL_AXES))
    assert spec.models == ("meridian", "smooth", "rough", "rubber")
    expected = classify_in_process(spec)
    ds = atlas(spec, tmp_path / "m.nc", client=client, chunk=3)
    assert ds.identical(expected)
    with xr.open_dataset(tmp_path / "m.nc") as f:
        assert f["model"].values.tolist() == MODEL_AXES["model"]
        assert f["n_steady"].equals(expected["n_steady"])
    for a3 in MODEL_AXES["a3"]:
        body = SphericalTop(**{**BODY, "a3": a3})
        classes = {c.model: c for c in classify_models(body, STATE["gamma"], STATE["omega"],
                                                       n=3)}  # fmt: skip
        for model in MODEL_AXES["model"]:
            cell = ds.sel(model=model, a3=a3, I3=0.5)
            motions = classes[model].steady
            assert int(cell["status"]) == 0
            assert int(cell["n_steady"]) == len(motions)
            assert int(cell["n_centres"]) == sum(m.type == "center" for m in motions)
            centres = [m for m in motions if m.type == "center"]
            for k, m in enumerate(centres):
                assert float(cell["centre_gamma3"][k]) == pytest.approx(m.gamma3, abs=1e-12)
                assert float(cell["rotation_centre"][k]) == pytest.approx(
                    m.precession_rate / m.frequency, rel=1e-12)  # fmt: skip
            assert (int(cell["n_folds"]) >= 0) == (model == "meridian")
            assert int(ds.sel(model=model, a3=a3, I3=0.7)["status"]) == 1  # I3 > 2 I1
            if model != "meridian":  # each centre: a minimum of U written again in mpmath
                U, _ = _mp_potential(classes[model].level)
                for k in range(int(cell["n_centres"])):
                    theta = mp.acos(float(cell["centre_gamma3"][k]))
                    assert abs(mp.diff(U, theta)) < 1e-9 * max(1.0, abs(U(theta)))
                    assert mp.diff(U, theta, 2) > 0


def test_a_model_other_than_the_meridian_one_is_an_atlas_of_its_own():
    """No model axis: the scenario's model (rough), its level from the state."""
    spec = atlas_spec_from_dict(state_spec_dict({"a3": [0.1]}, model="rough"))
    assert spec.models == ("rough",)
    assert int(classify_in_process(spec)["status"].values[0]) == 0


@pytest.mark.parametrize(
    ("axes", "model", "initial", "message"),
    [
        ({"model": ["meridian", "parallel"]}, "meridian", True, "not a model the atlas"),
        ({"model": ["shell-rotor"]}, "meridian", True, "not a model the atlas"),
        ({"model": ["rough", "rough"]}, "meridian", True, "twice"),
        ({"model": "rough"}, "meridian", True, "non-empty list"),
        ({"model": ["rough"], "C2": [0.0]}, "meridian", True, "takes body keys and model"),
        ({"model": ["rough"]}, "meridian", False, "needs an \\[initial\\] table"),
        ({"C2": [0.1]}, "parallel", True, "parallel model has no reduction"),
        ({"model": ["rubber"]}, ["rubber"], True, "must be a model name"),
    ],
)
def test_bad_model_axes_are_refused_in_one_line(axes, model, initial, message):
    data = state_spec_dict(axes, model=model)
    if not initial:
        del data["initial"]
    with pytest.raises(AtlasError, match=message):
        atlas_spec_from_dict(data)


# ---- in a notebook: ds.rollingtop ----------------------------------------------------------
def test_the_accessor_shows_the_cells_and_their_counts():
    """The summary's counts against np.unique of the cells, as ``rollingtop atlas`` prints
    them; the axes and the fixed values (the axes' keys left out)."""
    from .html_view import num, read

    ds = classify_in_process(atlas_spec_from_dict(spec_dict(SMALL)))
    classified = ds["status"].values == 0
    view = read(ds.rollingtop._repr_html_())
    assert view.subtitle == f"{ds['status'].size} cells (2 x 4 x 3), models: meridian"
    shown = {(r["variable"], int(r["value"])): int(r["cells"])
             for r in view.records("classified cells")}  # fmt: skip
    for name in ("n_steady", "n_centres", "n_saddles", "n_folds"):
        values, n = np.unique(ds[name].values[classified], return_counts=True)
        expected = {(name, int(v)): int(c) for v, c in zip(values, n, strict=True)}
        assert {k: v for k, v in shown.items() if k[0] == name} == expected
        assert ds.rollingtop.counts()[name] == {k[1]: v for k, v in expected.items()}
    cells = {r["status"]: int(r["cells"]) for r in view.records("cells")}
    assert cells == {"classified": int(classified.sum()),
                     "pole level (C1 = +-M3)": int((ds["status"].values == 2).sum())}  # fmt: skip
    axes = {r["axis"]: r for r in view.records("axes")}
    assert list(axes) == ["a3", "C2", "C1"] and int(axes["C2"]["values"]) == 4
    assert num(axes["C2"]["from"]) == -3.0 and num(axes["C2"]["to"]) == 0.0
    (fixed,) = view.records("fixed")
    assert {k: num(v) for k, v in fixed.items()} == {**{k: v for k, v in BODY.items()
                                                        if k != "a3"}, "M3": 1.0}  # fmt: skip


def test_the_accessor_plots_a_count_over_two_axes_the_others_held():
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes

    from rollingtop import RollingTopError

    ds = classify_in_process(atlas_spec_from_dict(spec_dict(SMALL)))
    try:
        ax = ds.rollingtop.plot()  # the last two axes, a3 held at its middle value
        assert isinstance(ax, Axes) and (ax.get_xlabel(), ax.get_ylabel()) == ("C2", "C1")
        assert ax.get_title().endswith("at a3 = 0.2")
        (mesh,) = ax.collections
        cells = ds.sel(a3=0.2)
        expected = np.where(cells["status"].values == 0, cells["n_steady"].values, -9).T
        np.testing.assert_array_equal(np.ma.filled(mesh.get_array(), -9), expected)
        _, given = plt.subplots()
        assert ds.rollingtop.plot(given, "n_centres", x="C1", a3=0.05, C2=-1.0) is given
        (curve,) = given.get_lines()
        cells = ds.sel(a3=0.05, C2=-1.0)
        expected = np.where(cells["status"].values == 0, cells["n_centres"].values, np.nan)
        np.testing.assert_array_equal(curve.get_xdata(), ds["C1"].values)
        np.testing.assert_array_equal(curve.get_ydata(), expected)
        with pytest.raises(RollingTopError, match="'I3': not an axis of the atlas"):
            ds.rollingtop.plot(I3=0.5)
    finally:
        plt.close("all")


def test_the_accessor_names_the_models_on_a_model_axis():
    import matplotlib.pyplot as plt

    spec = atlas_spec_from_dict({
        "body": dict(BODY), "contact": {"model": "meridian"},
        "initial": {"gamma": [0.0, 0.6, 0.8], "omega": [0.7, -0.3, 0.4]},
        "axes": {"model": ["meridian", "rough"], "a3": [-0.05, 0.1]},
    })  # fmt: skip
    ds = classify_in_process(spec)
    try:
        ax = ds.rollingtop.plot(x="model", y="a3")
        assert [t.get_text() for t in ax.get_xticklabels()] == ["meridian", "rough"]
        (mesh,) = ax.collections
        np.testing.assert_array_equal(mesh.get_array(), ds["n_steady"].values.T)
        ax = ds.rollingtop.plot(x="a3", model="rough")
        assert ax.get_title().endswith("at model = rough")
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(),
                                      ds["n_steady"].sel(model="rough").values)  # fmt: skip
    finally:
        plt.close("all")


def test_a_dataset_that_is_no_atlas_is_refused_by_the_accessor():
    with pytest.raises(AtlasError, match="not an atlas of rollingtop.atlas"):
        xr.Dataset({"x": ("t", [1.0])}).rollingtop  # noqa: B018


def test_a_cell_the_analysis_cannot_classify_is_marked_whatever_the_axis_order():
    """Issue 27: I1 = 1e300 or C2 = 1e20 (levels beyond doubles) are status 3 in their cells,
    not a failed atlas; a3 = [1.5, 0.5] runs as [0.5, 1.5] does (the inadmissible body is its
    cell, status 1); the classified cells equal a LevelSet's steady motions."""
    ds = classify_in_process(atlas_spec_from_dict(spec_dict({"I1": [0.3, 1e300],
                                                             "C2": [-2.0, 1e20]})))  # fmt: skip
    status = ds["status"].values
    assert status[0, 0] == 0 and (status[0, 1], status[1, 0], status[1, 1]) == (3, 3, 3)
    assert ds["n_steady"].values[0, 0] == len(steady_motions(LevelSet(SphericalTop(**BODY),
                                                                      1.0, 0.5, -2.0)))  # fmt: skip
    assert np.all(ds["n_steady"].values[status == 3] == -1)
    for order in ([1.5, 0.5], [0.5, 1.5]):
        ds = classify_in_process(atlas_spec_from_dict(spec_dict({"a3": order})))
        by_a3 = dict(zip(ds["a3"].values.tolist(), ds["status"].values.ravel().tolist(),
                         strict=True))  # fmt: skip
        assert by_a3 == {1.5: 1, 0.5: 0}


@pytest.mark.parametrize(
    "damage",
    ["truncated", "garbage", "foreign keys", "wrong length", "unknown index", "copied over"],
)
def test_a_damaged_or_foreign_chunk_is_recomputed_with_one_warning(client, tmp_path, damage):
    """Issue 27: a chunk file of the .partial folder that does not load, or does not hold what
    its chunk should, is computed again (one AtlasResumeWarning naming the folder), never a
    traceback; the result equals the in-process atlas."""
    from rollingtop.atlas import AtlasResumeWarning

    spec = atlas_spec_from_dict(spec_dict(SMALL))
    out = tmp_path / "a.nc"

    def stop_after_two_chunks(done, n):
        if done >= 10:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atlas(spec, out, client=client, chunk=5, progress=stop_after_two_chunks)
    folder = tmp_path / "a.nc.partial"
    victim = sorted(folder.glob("chunk-*.npz"))[0]
    if damage == "truncated":
        victim.write_bytes(victim.read_bytes()[:40])
    elif damage == "garbage":
        victim.write_bytes(b"\x00not a zip file" * 10)
    elif damage == "foreign keys":
        np.savez(victim, x=np.zeros(5))
    elif damage == "wrong length":  # its identity intact, its cells cut
        with np.load(victim) as z:
            np.savez(victim, **{k: z[k] if k.startswith("chunk_") else z[k][:2] for k in z.files})
    elif damage == "copied over":  # issue 36 row 4: a whole chunk file under another's name
        victim = sorted(folder.glob("chunk-*.npz"))[1]
        victim.write_bytes(sorted(folder.glob("chunk-*.npz"))[0].read_bytes())
    else:  # a chunk index beyond the spec's chunks
        victim.rename(folder / "chunk-999999.npz")
    with pytest.warns(
        AtlasResumeWarning, match=r"1 damaged or foreign chunk file\(s\) in .*a\.nc\.partial"
    ):
        ds = atlas(spec, out, client=client, chunk=5)
    assert ds.identical(classify_in_process(spec))
    assert out.exists() and not folder.exists()


def test_a_listener_that_is_no_dask_scheduler_fails_within_the_timeout(capsys, tmp_path):
    """Issue 27: a --scheduler that accepts connections and never answers (was: still waiting
    after 150 s) fails in one line after --scheduler-timeout seconds, leaving nothing behind."""
    import socket
    import time

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(8)
    port = listener.getsockname()[1]
    spec = _spec_file(tmp_path, "C2 = [0.0]")
    try:
        start = time.perf_counter()
        code, out, err = run_cli(capsys, "atlas", str(spec), "-o", str(tmp_path / "a.nc"),
                                 "--scheduler", f"tcp://127.0.0.1:{port}",
                                 "--scheduler-timeout", "1.5")  # fmt: skip
        took = time.perf_counter() - start
    finally:
        listener.close()
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "did not answer within 1.5 s" in err, err
    assert took < 10.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.toml"]


@pytest.mark.parametrize("value", ["0", "-1", "nan", "1e9"])
def test_a_bad_scheduler_timeout_is_one_line(capsys, tmp_path, value):
    spec = _spec_file(tmp_path, "C2 = [0.0]")
    code, out, err = run_cli(capsys, "atlas", str(spec), "-o", str(tmp_path / "a.nc"),
                             "--scheduler-timeout", value)  # fmt: skip
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--scheduler-timeout" in err


def test_a_store_that_cannot_be_written_is_named_and_the_cells_are_kept(client, tmp_path,
                                                                       monkeypatch):  # fmt: skip
    """Issue 27: an OSError while the Zarr store is written (a file-size limit: EFBIG) is one
    AtlasError naming the store; no store and no temporary store are left, and the finished
    cells stay in .partial so that a rerun writes without computing."""
    import errno

    import rollingtop.atlas._store as store
    from rollingtop.atlas._store import CellsKept

    spec = atlas_spec_from_dict(spec_dict(SMALL))
    out = tmp_path / "a.zarr"

    def too_large(self, *args, **kwargs):
        (Path(args[0]) / "junk").parent.mkdir(parents=True, exist_ok=True)
        (Path(args[0]) / "junk").write_text("partial")
        raise OSError(errno.EFBIG, "File too large")

    monkeypatch.setattr(xr.Dataset, "to_zarr", too_large)
    with pytest.raises(
        CellsKept,
        match=r"cannot write '.*a\.zarr': File too large; the "
        r"finished cells are kept in '.*a\.zarr\.partial'",
    ):
        atlas(spec, out, client=client, chunk=5)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.zarr.partial"]
    monkeypatch.undo()
    progress = []
    atlas(spec, out, client=client, chunk=5, progress=lambda d, n: progress.append(d))
    assert progress == [spec.size] and out.is_dir() and store is not None


def test_a_running_scheduler_passes_the_probe(tmp_path):
    """The probe of --scheduler accepts a real Dask scheduler (and the atlas runs on it)."""
    spec = atlas_spec_from_dict(spec_dict({"C2": [-2.0, 0.0]}))
    with local_cluster(1) as cluster:
        ds = atlas(spec, scheduler=cluster.scheduler_address, scheduler_timeout=5.0)
    assert ds["n_steady"].values.tolist() == [3, 1]
