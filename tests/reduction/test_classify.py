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
    assert [c.model for c in found] == ["meridian", "smooth", "rough", "rubber"]
    # rubber rolling starts from omega's horizontal part (the paper's state spins about gamma)
    assert found[3].note == "omega projected onto (omega, gamma) = 0"
    np.testing.assert_allclose(found[3].state[3:6] @ found[3].state[12:15], 0.0, atol=1e-15)
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
    and the saddles' its local maxima, found by brute force on 200001 points of theta (an
    independent search: no root finding)."""
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
            here = cv.points[cv.points[:, 0] == x]
            for kind, inner in ((1.0, (U[1:-1] < U[:-2]) & (U[1:-1] < U[2:])),
                                (-1.0, (U[1:-1] > U[:-2]) & (U[1:-1] > U[2:]))):  # fmt: skip
                brute = np.sort(U[1:-1][inner])  # local minima: centres; maxima: saddles
                found = np.sort(here[here[:, 3] == kind, 2])
                assert brute.size == found.size
                np.testing.assert_allclose(found, brute, atol=BRUTE_U, rtol=BRUTE_U)
                compared += found.size
    assert compared >= 15


def test_compare_classification_command(capsys, tmp_path):
    out_png = tmp_path / "cc.png"
    code, out, err = run_cli(capsys, "compare-classification", str(EXAMPLES / "paper.toml"),
                             "-o", str(out_png), "--json", "--points", "11")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert [m["model"] for m in data["models"]] == ["meridian", "smooth", "rough", "rubber"]
    for m in data["models"]:
        assert {"gamma3_min", "gamma3_max", "period", "delta_psi"} <= set(m["orbit"])
        assert len(m["critical"]["x"]) == 11
    assert out_png.stat().st_size > 10_000
    code, out, err = run_cli(capsys, "compare-classification", str(EXAMPLES / "paper.toml"),
                             "-o", str(tmp_path / "x.png"), "--points", "1")  # fmt: skip
    assert code == 2 and "--points 1" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("name", ["smooth", "rough"])
def test_a_rotation_grid_cell_is_the_full_systems_precession(name):
    """rotation_grid: N of a cell is Delta psi / 2 pi of the full system (solve_ivp on
    tests/dynamics/reference.py) over one period of gamma3, to 1e-8."""
    from rollingtop.reduction import state_from_level
    from rollingtop.reduction.classify import rotation_grid
    from rollingtop.scenario import load_scenario

    from .test_models import _full_run

    sc = load_scenario(EXAMPLES / f"{name}.toml")
    level = sc.level_set()
    grid = rotation_grid(level, resolution=5)
    i, j = 2, 2  # the middle column: the scenario's own level
    assert grid.x[j] == pytest.approx(level.values()[grid.axis])
    N = grid.N[i, j, 0]
    assert math.isfinite(N)
    (o, *_) = [o for o in orbits(level, float(grid.h[i])) if o.kind == "periodic"]
    y0 = state_from_level(
        level, float(grid.h[i]), o.gamma3_min + 1e-4 * (o.gamma3_max - o.gamma3_min)
    )
    sol = _full_run(name, sc.body, y0, 3.2 * o.period)
    t0, t1 = sol.t_events[0][:2]
    ys = sol.sol(np.linspace(t0, t1, 400))
    psi = np.unwrap(np.arctan2(ys[11], ys[8]))
    assert N == pytest.approx((psi[-1] - psi[0]) / (2 * math.pi), abs=1e-8)


def test_rotation_of_another_reduced_model_on_the_command_line(capsys, tmp_path):
    code, out, err = run_cli(capsys, "rotation", str(EXAMPLES / "rough.toml"), "--json",
                             "--resolution", "5", "-o", str(tmp_path / "r.png"))  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert data["model"] == "rough" and data["axis"] == "jellett"
    assert len(data["N"]) == 5 and len(data["N"][0]) == 5 and data["N_range"] is not None
    assert sum(data["classes"].values()) == sum(
        v is not None for row in data["N"] for cell in row for v in cell
    )


def test_a_vertical_spin_is_classified_by_every_model(capsys, tmp_path):
    """A vertical spin is a pole level of every integrable model: compare-classification
    classifies each (Routh's sphere's since issue 36: its pole levels are reduced), with no
    refusal; rubber rolling keeps none of the spin."""
    path = tmp_path / "vertical.toml"
    path.write_text("""
[body]
R = 1.0
m = 1.0
g = 1.0
a3 = 0.1
I1 = 0.3
I3 = 0.5
[initial]
gamma = [0.0, 0.0, 1.0]
omega = [0.0, 0.0, 3.0]
""")
    code, out, err = run_cli(capsys, "compare-classification", str(path), "-o",
                             str(tmp_path / "v.png"), "--json", "--points", "5")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert [m["model"] for m in data["models"]] == ["meridian", "smooth", "rough", "rubber"]
    assert data["refused"] == {}
    assert data["models"][2]["level"]["pole"] == "south"
    # rubber rolling cannot spin about the vertical: its part of omega is the rest at the pole
    rubber = data["models"][3]
    assert rubber["level"]["rubber_spin"] == 0.0 and rubber["orbit"] is None  # snapped to 0
    assert "omega projected" in rubber["note"]


@pytest.mark.parametrize("omega", [[1e-7, 1.8, 2.4000001], [1e-6, 3e-13, 4e-13]],
                         ids=["almost_along_gamma", "slow"])  # fmt: skip
def test_rubber_rolling_takes_the_horizontal_part_of_any_omega(paper_body, omega):
    """omega almost along gamma, or slow: its projection onto (omega, gamma) = 0 is admitted
    (residual at round-off of what is left), and a model that refuses a state never stops the
    others."""
    from rollingtop.reduction.classify import classify_models

    refused: dict[str, str] = {}
    found = classify_models(paper_body, [0.0, 0.6, 0.8], omega, n=3, refused=refused)
    rubber = [c for c in found if c.model == "rubber"]
    assert "rubber" not in refused and len(rubber) == 1
    w, g = rubber[0].state[3:6], rubber[0].state[12:15]
    assert abs(w @ g) <= 1e-9 * np.linalg.norm(w)
