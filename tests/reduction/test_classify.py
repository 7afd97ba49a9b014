"""The side-by-side classification (rollingtop.reduction.classify) against brute force: the
critical values are the minima and maxima of U found on a dense grid, and each model's orbit is
its own reduction's."""

import json
import math

import numpy as np
import pytest

from rollingtop import ScenarioError
from rollingtop.reduction import LevelSetError, orbits, reduction_of
from rollingtop.reduction.classify import AXES, classify_models, critical_values

from ..conftest import EXAMPLES
from ..test_cli import run_cli

BRUTE_U = 1e-7  # a dense grid's minimum of U against the centre's critical value


@pytest.fixture(scope="module")
def classes():
    from rollingtop.scenario import load_scenario

    sc = load_scenario(EXAMPLES / "paper.toml")
    y0 = sc.require_state()
    return classify_models(sc.body, y0[12:15], y0[3:6], n=21, own=("meridian", y0)), y0


def test_every_reduced_model_is_classified_with_its_own_level(classes):
    found, y0 = classes
    assert [c.model for c in found] == ["meridian", "smooth", "rough"]
    for c in found:
        reduction = reduction_of(c.model)
        assert c.level.values() == pytest.approx(
            reduction.level_of_state(c.level.body, c.state).values(), abs=1e-14
        )
        assert c.h == pytest.approx(reduction.reduced_energy(c.level.body, c.state), abs=1e-14)
        # the orbit through the state is one of the level's own, and holds the state
        assert c.orbit in orbits(c.level, c.h)
        assert c.orbit.gamma3_min <= c.state[14] <= c.orbit.gamma3_max
        assert c.critical.axis == AXES[c.model]
    np.testing.assert_array_equal(found[0].state, y0)  # the scenario's own model: its state


def test_critical_values_are_the_extrema_of_U_on_a_dense_grid(classes):
    """At each grid value of the axis, the centres' critical values are the local minima of U
    found by brute force on 200001 points of theta (an independent search: no root finding)."""
    found, _ = classes
    theta = np.linspace(1e-3, math.pi - 1e-3, 200001)
    compared = 0
    for c in found:
        cv = critical_values(c.level, n=7)
        reduction = reduction_of(c.model)
        for x in cv.x:
            try:
                level = reduction.level(c.level.body, {**c.level.values(), cv.axis: float(x)})
            except (LevelSetError, ScenarioError):  # a pole level the model does not reduce
                continue
            U = np.asarray(level.U(theta))
            inner = (U[1:-1] < U[:-2]) & (U[1:-1] < U[2:])
            brute = np.sort(U[1:-1][inner])
            centres = np.sort(cv.points[(cv.points[:, 0] == x) & (cv.points[:, 3] == 1.0), 2])
            assert brute.size == centres.size
            np.testing.assert_allclose(centres, brute, atol=BRUTE_U, rtol=BRUTE_U)
            compared += centres.size
    assert compared >= 15


def test_compare_classification_command(capsys, tmp_path):
    out_png = tmp_path / "cc.png"
    code, out, err = run_cli(capsys, "compare-classification", str(EXAMPLES / "paper.toml"),
                             "-o", str(out_png), "--json", "--points", "11")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert [m["model"] for m in data["models"]] == ["meridian", "smooth", "rough"]
    for m in data["models"]:
        assert {"gamma3_min", "gamma3_max", "period", "delta_psi"} <= set(m["orbit"])
        assert len(m["critical"]["x"]) == 11
    assert out_png.stat().st_size > 10_000
    code, out, err = run_cli(capsys, "compare-classification", str(EXAMPLES / "paper.toml"),
                             "-o", str(tmp_path / "x.png"), "--points", "1")  # fmt: skip
    assert code == 2 and "--points 1" in err and len(err.strip().splitlines()) == 1
