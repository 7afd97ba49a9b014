"""Basins of attraction (rollingtop.basins, ``rollingtop basins``): each labelled start,
integrated again for longer in this process, still ends at its attractor; the labels cover the
grid; bad input is one line."""

import json

import numpy as np
import pytest

from rollingtop import ScenarioError
from rollingtop.basins import ATTRACTED, basin_map
from rollingtop.chaos import periodic_orbits, poincare_section
from rollingtop.chaos._section_map import SectionMap, on_level, section_coordinates
from rollingtop.chaos.level import held_integrals, level_values
from rollingtop.scenario import load_scenario

from .conftest import EXAMPLES
from .test_cli import run_cli

#: One worker runs this module: its fixture finds the attractors and the map once.
pytestmark = pytest.mark.xdist_group("basins")

GRID = 6
CROSSINGS = 150
#: A labelled start run again for this many crossings (beyond the map's).
LONGER = 400


@pytest.fixture(scope="module")
def example():
    sc = load_scenario(EXAMPLES / "parallel.toml")
    found = periodic_orbits(sc.body, sc.model, sc.require_state(), grid=0)
    ds = basin_map(sc.body, sc.model, sc.require_state(), found=found, grid=GRID,
                   crossings=CROSSINGS, workers=1)  # fmt: skip
    return sc, found, ds


def test_every_labelled_start_ends_at_its_attractor_when_run_longer(example):
    sc, found, ds = example
    label = ds["label"].values
    attractors = [o for o in found if o.type == "attracting"]
    assert len(json.loads(ds.attrs["attractors"])) == len(attractors)
    assert label.shape == (GRID, GRID)
    assert set(np.unique(label)) <= {-3, -2, -1, *range(len(attractors))}
    assert np.any(label >= 0)
    names = held_integrals(sc.body, sc.model, None)
    target = level_values(sc.body, sc.model, sc.require_state(), names)
    P = SectionMap(sc.body, sc.model, names, 1e-10)
    checked = 0
    for k in range(len(attractors)):
        cells = np.argwhere(label == k)
        for i, j in cells[:2]:
            g3, w_n = ds["gamma3"].values[i], ds["w_n"].values[j]
            x = on_level(P, target, float(g3), float(w_n))[int(ds.attrs["sheet"])]
            run = poincare_section(sc.body, sc.model, P.states(x[None]), crossings=LONGER,
                                   rtol=1e-10)  # fmt: skip
            end = section_coordinates(sc.model, run["crossing_state"].values[0, -1])
            gap = np.min(np.max(np.abs(attractors[k].points - end), axis=-1))
            assert gap < ATTRACTED, (k, i, j, gap)
            checked += 1
    assert checked >= 2
    off = np.argwhere(label == -3)
    for i, j in off[:5]:  # not on the level: that sheet has no state there
        g3, w_n = ds["gamma3"].values[i], ds["w_n"].values[j]
        assert len(on_level(P, target, float(g3), float(w_n))) <= int(ds.attrs["sheet"])


def test_the_command_draws_and_counts(capsys, tmp_path):
    out = tmp_path / "basins.png"
    code, stdout, err = run_cli(capsys, "basins", str(EXAMPLES / "parallel.toml"), "-o",
                                str(out), "--grid", "3", "--crossings", "20", "--trajectories",
                                "4", "--settle", "60", "--workers", "1", "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(stdout)
    assert sum(summary["counts"].values()) == 9 and out.stat().st_size > 0
    assert set(summary) >= {"model", "level", "attractors", "counts", "grid", "sheet"}


def test_bad_input_is_one_line(capsys, tmp_path):
    sc = load_scenario(EXAMPLES / "parallel.toml")
    with pytest.raises(ScenarioError, match="one more integral"):
        basin_map(sc.body, "meridian", sc.require_state())
    with pytest.raises(ScenarioError, match="sheet = 2"):
        basin_map(sc.body, sc.model, sc.require_state(), sheet=2)
    for args in (("--grid", "1"), ("--sheet", "2"), ("--workers", "0")):
        code, out, err = run_cli(capsys, "basins", str(EXAMPLES / "parallel.toml"), "-o",
                                 str(tmp_path / "b.png"), *args)  # fmt: skip
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    code, out, err = run_cli(capsys, "basins", str(EXAMPLES / "fig5.toml"), "-o",
                             str(tmp_path / "b.png"))  # fmt: skip
    assert code == 2 and "one more integral" in err and not (tmp_path / "b.png").exists()


def test_the_library_refuses_what_the_command_line_cannot_send():
    """basin_map's own checks (click's ranges keep these from the command line): a float or
    bool sheet, a worker count beyond four per core; each before any orbit search."""
    import os

    sc = load_scenario(EXAMPLES / "parallel.toml")
    y = sc.require_state()
    for sheet in (1.0, np.float64(0.0), True):
        with pytest.raises(ScenarioError, match="sheet"):
            basin_map(sc.body, sc.model, y, sheet=sheet)
    with pytest.raises(ScenarioError, match="per core"):
        basin_map(sc.body, sc.model, y, workers=4 * (os.cpu_count() or 1) + 1)
