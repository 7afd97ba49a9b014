"""Ensembles: the parallel kernel gives the single-run results, on any number of threads."""

import json

import numpy as np
import pytest
import xarray as xr

from rollingtop import (
    ScenarioError,
    SphericalTop,
    initial_state,
    load_scenario,
    simulate,
    simulate_ensemble,
)
from rollingtop._compiled import for_model
from rollingtop.ensemble import grid_table, states_from_table
from rollingtop.reduction import LevelSet, orbits
from rollingtop.scenario import InitialConditions, IntegrationOptions, LevelSpec, Scenario

from .conftest import EXAMPLES, PAPER_BODY
from .test_cli import run_cli

SAME_RUN = 1e-12  # the ensemble runs the single-run stepper: identical up to round-off


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(EXAMPLES / "paper.toml").with_overrides(t_end=20.0, rtol=1e-11)


def test_grid_and_table(scenario):
    cols = grid_table("omega3=1.5:2.5:3,v_tau=-0.2:0.2:2")
    assert list(cols) == ["omega3", "v_tau"] and len(cols["omega3"]) == 6
    states = states_from_table(scenario, cols)
    assert states.shape == (6, 18)
    np.testing.assert_allclose(states[:, 5], np.repeat([1.5, 2.0, 2.5], 2))
    with pytest.raises(ScenarioError, match="unknown column foo"):
        states_from_table(scenario, {"foo": [1.0]})
    with pytest.raises(ScenarioError, match="expected name=start:stop:count"):
        grid_table("omega3=1:2")
    with pytest.raises(Exception, match="ensemble row 2: .*gamma .* is not a unit vector"):
        states_from_table(scenario, {"gamma3": [0.8, 0.9]})


@pytest.mark.parametrize("threads", [1, 2])
def test_ensemble_equals_single_runs(scenario, threads):
    cols = grid_table("omega3=1.5:2.5:3,v_tau=-0.2:0.2:3")
    states = states_from_table(scenario, cols)
    opts = scenario.integration
    res = simulate_ensemble(
        scenario.body,
        "meridian",
        states,
        t_end=opts.t_end,
        rtol=opts.rtol,
        atol=opts.resolved_atol,
        threads=threads,
    )
    assert res.samples is None  # memory: only the final states unless asked
    assert res.threads == threads and np.all(res.status == 0)
    for k in (0, 4, 8):
        y = states[k]
        ic = InitialConditions(gamma=y[12:15], omega=y[3:6], alpha=y[6:9], v=y[0:3])
        single = simulate(Scenario(scenario.body, "meridian", ic, opts))
        np.testing.assert_allclose(res.final[k], single.y[-1], rtol=0, atol=SAME_RUN)
        assert res.steps[k] == single.stats["steps"]
        assert res.integrals["F6"]["drift"][k] == pytest.approx(
            single.integrals["F6"][-1] - single.integrals["F6"][0], abs=1e-12
        )
    s = res.summary()
    assert s["n"] == 9 and s["failed"] == 0
    assert all(v < 1e-9 for v in s["max_rel_drift"].values())
    # the rows ran through the single run's compiled loop, with its argument types: one compile
    assert len(for_model("meridian").stepper.run_rows.signatures) == 1


def test_samples_bodies_and_pole_cases(paper_body):
    """Several bodies at once, samples kept on request, and a pole case integrated through the
    pole inside the parallel kernel."""
    level = LevelSet(paper_body, 1.0, 1.0, -0.3)
    h = float(level.U(0.0)) + 0.5
    (orbit,) = orbits(level, h=h)
    assert orbit.pole_passage  # the reduction says this orbit goes through gamma3 = 1
    pole_scenario = Scenario(
        paper_body,
        "meridian",
        None,
        IntegrationOptions(t_end=10.0, rtol=1e-12, samples=11),
        level=LevelSpec(1.0, 1.0, -0.3, h=h),
    )
    pole = pole_scenario.y0
    other = SphericalTop(**(PAPER_BODY | {"a3": 0.2}))
    plain = initial_state(
        other, "meridian", gamma=(0, 0.6, 0.8), omega=(0.7, -0.3, 2.0), free={"v_tau": 0.25}
    )
    res = simulate_ensemble(
        [paper_body, other], "meridian", [pole, plain], t_end=10.0, rtol=1e-12, samples=11
    )
    assert res.samples.shape == (2, 11, 18) and np.all(res.status == 0)
    # the parallel kernel follows the single-run path through the pole (1e-9: both at
    # rtol 1e-12 with the same stepper, only the driver differs) and stays inside the orbit's
    # turning points from quadrature, reaching the pole region at some sample
    np.testing.assert_allclose(res.samples[0], simulate(pole_scenario).y, rtol=0, atol=1e-9)
    gamma3 = res.samples[0, :, 14]
    assert gamma3.min() >= orbit.gamma3_min - 1e-9 and gamma3.max() <= 1.0
    assert gamma3.max() > 0.99
    assert abs(res.integrals["F6"]["drift"][0]) < 1e-10  # through the pole
    assert abs(res.integrals["energy"]["drift"][1]) < 1e-10
    with pytest.raises(ScenarioError, match="2 bodies for 1 states"):
        simulate_ensemble([paper_body, other], "meridian", [plain], t_end=1.0)
    with pytest.raises(ScenarioError, match="state 1 violates the constraint contact"):
        simulate_ensemble(paper_body, "meridian", [plain], t_end=1.0)  # made for another body


@pytest.mark.parametrize(
    ("example", "expected"),
    [
        ("shell_rotor.toml", {"energy", "lagrange", "jellett", "F6"}),
        # a3 = 0, I3 = I1: the particular integral (the slip along nu) is monitored too
        ("parallel_balanced.toml", {"energy", "jellett", "slip_nu"}),
        ("rubber.toml", None),
    ],
)
def test_new_models_match_single_runs(example, expected):
    """The ensemble integrates every registered model as a single run does, and monitors the
    integrals the model claims for the body (its particular ones included), as a trajectory does."""
    sc = load_scenario(EXAMPLES / example).with_overrides(t_end=3.0, rtol=1e-11)
    single = simulate(sc)
    names = set(single.integrals)
    if expected is not None:
        assert names == expected
    res = simulate_ensemble(sc.body, sc.model, [sc.y0, sc.y0], t_end=3.0, rtol=1e-11,
                            atol=sc.integration.resolved_atol)  # fmt: skip
    assert set(res.integrals) == names and np.all(res.status == 0)
    np.testing.assert_allclose(res.final[1], single.y[-1], rtol=0, atol=SAME_RUN)
    for name in names:
        ref = single.integrals[name][-1] - single.integrals[name][0]
        assert res.integrals[name]["drift"][0] == pytest.approx(ref, abs=1e-12), name
        assert abs(ref) < 1e-9, name


def test_cli_ensemble(capsys, tmp_path):
    out = tmp_path / "ens.nc"
    csv = tmp_path / "ic.csv"
    csv.write_text("# two states\nomega3,v_tau\n2.0,0.1\n2.2,0.2\n")
    code, stdout, err = run_cli(
        capsys,
        "ensemble",
        str(EXAMPLES / "paper.toml"),
        "--initial",
        str(csv),
        "--t-end",
        "5",
        "--samples",
        "6",
        "-o",
        str(out),
        "--json",
    )
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["n"] == 2 and summary["failed"] == 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["final_state"].shape == (2, 18) and ds["samples"].shape == (2, 6, 18)
        np.testing.assert_allclose(ds["input_omega3"].values, [2.0, 2.2])
    code, _, err = run_cli(capsys, "ensemble", str(EXAMPLES / "paper.toml"))
    assert code == 2 and "exactly one of --initial" in err
    code, _, err = run_cli(capsys, "ensemble", str(EXAMPLES / "paper.toml"), "--grid", "x=1:2:2")
    assert code == 2 and "unknown column x" in err


def test_grid_and_samples_checked_before_allocating(paper_body):

    cols = grid_table("omega3=1:3:3,v_tau=0:1:2")
    assert cols["omega3"].tolist() == [1, 1, 2, 2, 3, 3] and cols["v_tau"].tolist() == [0, 1] * 3
    with pytest.raises(ScenarioError, match=r"--grid \(10000000000 trajectories\) needs about"):
        grid_table("omega3=1:3:100000,v_tau=0:1:100000")  # 1e10 rows: refused, not allocated
    with pytest.raises(ScenarioError, match="count is too large"):
        grid_table("omega3=1:3:" + "9" * 5000)
    with pytest.raises(ScenarioError, match="must be finite"):
        grid_table("omega3=nan:3:2")
    y = initial_state(paper_body, "meridian", gamma=(0, 0.6, 0.8), omega=(0, 0, 2.0))
    with pytest.raises(ScenarioError, match=r"\(1 trajectories of 10000000000 samples\)"):
        simulate_ensemble(paper_body, "meridian", [y], t_end=1.0, samples=10**10)


def test_threads_reduced_to_what_numba_may_use(paper_body):
    import numba

    y = initial_state(paper_body, "meridian", gamma=(0, 0.6, 0.8), omega=(0, 0, 2.0))
    res = simulate_ensemble(paper_body, "meridian", [y], t_end=0.01, threads=10_000)
    assert res.threads == numba.config.NUMBA_NUM_THREADS


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("omega3\n1e400\n", "'1e400' is not a finite number"),
        ("omega3\nnan\n", "'nan' is not a finite number"),
        ("omega3,omega3\n1,2\n", "the header names a column twice"),
        ("omega3\n" + "x" * 10_000 + "\n", r"line 2: 'x{77}…' is not a number"),
    ],
)
def test_bad_tables(tmp_path, text, message):
    from rollingtop.ensemble import read_table

    (tmp_path / "t.csv").write_text(text)
    with pytest.raises(ScenarioError, match=message):
        read_table(tmp_path / "t.csv")
