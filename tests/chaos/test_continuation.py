"""Continuation of periodic orbits (rollingtop.chaos.continuation, ``rollingtop continue``).

The core (rollingtop.chaos._arclength) reproduces published period-doubling values of textbook
maps: the logistic map's first two (r = 3 and r = 1 + sqrt(6); May 1976, *Nature* 261, 459) with
the switch onto the doubled branch, the Henon map's fixed point (a = 3 (1 - b)^2 / 4; Henon
1976, *Commun. Math. Phys.* 50, 69), and a family with an integral held through its unfolding
parameter. On the companion model's example level it follows the attracting 3-cycle across a
fold, and an orbit of the branch closes under an independent integration.
"""

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop.chaos import _arclength as arc
from rollingtop.chaos import continue_orbit, periodic_orbits
from rollingtop.chaos._section_map import section_coordinates, section_state
from rollingtop.chaos.continuation import body_with
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES
from ..dynamics import reference
from ..test_cli import run_cli

pytestmark = pytest.mark.xdist_group("periodic")

#: A located period doubling of an exact map against its closed form (differences at step
#: 1e-6 of maps exact to round-off; the regula falsi's stopping rule).
PD_TOL = 1e-6
#: The unfolding parameters stay 0 to this (round-off of the integrals' differences).
UNFOLDING_TOL = 1e-7
#: An orbit of the branch after one period of SciPy's DOP853 on the reference equations
#: (rtol = atol = 1e-12), in section coordinates.
CLOSURE_TOL = 1e-7


class Logistic:
    n, m = 1, 0

    def iterate(self, X, lam, K):
        for _ in range(K):
            X = lam * X * (1 - X)
        return X, np.full(len(X), float(K))

    def integrals(self, X, lam):
        return np.zeros((len(X), 0))

    def target(self, lam):
        return np.zeros(0)


class Henon(Logistic):
    n, b = 2, 0.3

    def iterate(self, X, lam, K):
        x, y = X[:, 0], X[:, 1]
        for _ in range(K):
            x, y = 1 - lam * x * x + y, self.b * x
        return np.stack([x, y], axis=-1), np.full(len(X), float(K))


class LogisticWithIntegral:
    """``(x1, x2) -> ((lam + x2) x1 (1 - x1), x2)``: ``x2`` is an integral, held at 0.1, so the
    period doubling is at ``lam = 2.9``."""

    n, m = 2, 1

    def iterate(self, X, lam, K):
        x1, x2 = X[:, 0], X[:, 1]
        for _ in range(K):
            x1 = (lam + x2) * x1 * (1 - x1)
        return np.stack([x1, x2], axis=-1), np.full(len(X), float(K))

    def integrals(self, X, lam):
        return X[:, 1:2]

    def target(self, lam):
        return np.array([0.1])


def _follow(fm, u0, K, bounds, ds):
    e = np.zeros(len(u0))
    e[-1] = 1.0
    start = arc.correct(fm, u0, e, K)
    assert start is not None
    return arc.continue_branch(fm, start, K, bounds, orient=e, ds=ds, ds_max=4 * ds, max_points=200)


def test_the_logistic_maps_first_two_period_doublings():
    fm = Logistic()
    branch = _follow(fm, np.array([0.6, 2.6]), 1, (2.5, 3.6), 0.05)
    (pd,) = [d for d in branch.detected if d.kind == "period-doubling"]
    assert pd.point.lam == pytest.approx(3.0, abs=PD_TOL) and pd.converged
    assert min(pd.bracket) <= pd.point.lam <= max(pd.bracket)
    first = arc.switch_to_doubled(fm, pd.point, 1, 1e-3)
    assert first is not None and first.lam > 3.0
    doubled = arc.continue_branch(
        fm, first, 2, (2.5, 3.6), orient=first.u - pd.point.u, ds=0.02, ds_max=0.08, max_points=200
    )
    (pd2,) = [d for d in doubled.detected if d.kind == "period-doubling"]
    assert pd2.point.lam == pytest.approx(1 + math.sqrt(6), abs=PD_TOL)
    # on the doubled branch, a 2-cycle: x and P(x) differ, P^2(x) = x
    p = doubled.points[len(doubled.points) // 2]
    once, _ = fm.iterate(p.x[None], p.lam, 1)
    twice, _ = fm.iterate(p.x[None], p.lam, 2)
    assert abs(once[0, 0] - p.x[0]) > 0.05 and abs(twice[0, 0] - p.x[0]) < 1e-10


def test_the_henon_maps_fixed_point_doubles_where_henon_says():
    fm, a = Henon(), 0.1
    x = (-(1 - fm.b) + math.sqrt((1 - fm.b) ** 2 + 4 * a)) / (2 * a)
    branch = _follow(fm, np.array([x, fm.b * x, a]), 1, (0.05, 0.6), 0.02)
    kinds = [d.kind for d in branch.detected]
    assert kinds == ["period-doubling"]
    assert branch.detected[0].point.lam == pytest.approx(3 * (1 - fm.b) ** 2 / 4, abs=PD_TOL)


class DelayedLogistic(Henon):
    """``(x, y) -> (lam x (1 - y), x)``: the fixed point ``x = y = 1 - 1/lam`` has the
    multipliers ``mu^2 - mu + (lam - 1) = 0``, a complex pair of modulus ``sqrt(lam - 1)``:
    a Neimark-Sacker point at ``lam = 2`` (its pair ``(1 +- i sqrt(3)) / 2``)."""

    def iterate(self, X, lam, K):
        x, y = X[:, 0], X[:, 1]
        for _ in range(K):
            x, y = lam * x * (1 - y), x
        return np.stack([x, y], axis=-1), np.full(len(X), float(K))


def test_a_neimark_sacker_point_is_found_and_placed_inside_its_bracket():
    fm = DelayedLogistic()
    branch = _follow(fm, np.array([1 - 1 / 1.6, 1 - 1 / 1.6, 1.6]), 1, (1.5, 2.4), 0.05)
    (ns,) = branch.detected
    assert ns.kind == "neimark-sacker" and ns.converged
    assert ns.point.lam == pytest.approx(2.0, abs=PD_TOL)
    assert min(ns.bracket) <= ns.point.lam <= max(ns.bracket)
    np.testing.assert_allclose(
        np.sort(np.angle(ns.point.multipliers)), [-np.pi / 3, np.pi / 3], atol=1e-6
    )


class Pinned(Logistic):
    """``x -> 0.5 + (2 - lam) (x - 0.5)``: the fixed point 0.5 for every ``lam``, its multiplier
    ``2 - lam`` through -1 at ``lam = 3``; the branch is a line in ``lam``, so steps of 0.1 from
    2.6 put a point on the period doubling itself."""

    def iterate(self, X, lam, K):
        for _ in range(K):
            X = 0.5 + (2 - lam) * (X - 0.5)
        return X, np.full(len(X), float(K))


def test_a_bifurcation_on_a_branch_point_is_not_lost():
    """A point within the test's noise of the period doubling does not hide it: the sign is
    compared between the points clear of the noise either side."""
    fm = Pinned()
    e = np.array([0.0, 1.0])
    start = arc.correct(fm, np.array([0.5, 2.6]), e, 1)
    branch = arc.continue_branch(
        fm, start, 1, (2.5, 3.45), orient=e, ds=0.1, ds_max=0.1, max_points=50
    )
    assert any(abs(p.lam - 3.0) < 1e-9 for p in branch.points)  # a point on it
    (pd,) = branch.detected
    assert pd.kind == "period-doubling" and pd.point.lam == pytest.approx(3.0, abs=PD_TOL)


def test_an_integral_is_held_by_its_unfolding_parameter():
    fm = LogisticWithIntegral()
    branch = _follow(fm, np.array([0.6, 0.1, 0.0, 2.5]), 1, (2.4, 3.2), 0.05)
    (pd,) = [d for d in branch.detected if d.kind == "period-doubling"]
    assert pd.point.lam == pytest.approx(2.9, abs=PD_TOL)
    assert arc.unfolding(branch.points) < UNFOLDING_TOL
    assert all(abs(p.x[1] - 0.1) < 1e-12 for p in branch.points)
    assert all(p.multipliers.size == 1 for p in branch.points)  # the level's own


@pytest.fixture(scope="module")
def three_cycle():
    sc = load_scenario(EXAMPLES / "parallel.toml")
    found = periodic_orbits(
        sc.body, sc.model, sc.require_state(), returns=3, grid=0, trajectories=8
    )
    (orbit,) = [o for o in found if o.returns == 3]
    return sc, orbit


def test_the_example_levels_three_cycle_is_followed_across_a_fold(three_cycle, tmp_path):
    """The attracting 3-cycle of examples/parallel.toml, followed in a3 from 0.1 up, meets a
    fold near a3 = 0.10190: a multiplier through +1, attracting before, a saddle after; the
    unfolding parameters stay 0; an orbit of the branch past a3 = 0.1 closes under SciPy on the
    reference equations for the body with that a3."""
    sc, orbit = three_cycle
    branch = continue_orbit(
        sc.body, sc.model, orbit, param="a3", bounds=(0.0999, 0.1025), step=0.03, max_points=20
    )
    assert branch.max_unfolding < UNFOLDING_TOL
    (fold,) = [b for b in branch.bifurcations if b.kind == "fold"]
    assert 0.1015 < fold.point.param < 0.1023 and fold.converged
    assert np.min(np.abs(fold.point.multipliers - 1.0)) < 1e-3
    before = [p for p in branch.points if p.param < fold.point.param - 1e-4]
    assert before and all(p.type == "attracting" for p in before)
    i = branch.points.index(min(branch.points, key=lambda p: abs(p.period - fold.point.period)))
    after = branch.points[i + 2 :]
    assert after and all(p.type == "saddle" for p in after)
    p = before[-1]
    body = body_with(sc.body, "a3", p.param)
    y0 = section_state(body, sc.model, p.x)
    sol = solve_ivp(
        lambda t, y: reference.rhs("parallel", body.params, y)[0],
        (0.0, p.period),
        y0,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
    )
    end = section_coordinates("parallel", sol.y[:, -1])
    np.testing.assert_allclose(end, p.x, atol=CLOSURE_TOL)
    d = branch.to_dict()
    assert set(d) >= {"param", "points", "bifurcations", "max_unfolding", "doubled"}
    assert d["bifurcations"][0]["kind"] == "fold" and len(d["bifurcations"][0]["bracket"]) == 2
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure()
    top = fig.add_subplot(2, 1, 1)
    axes = branch.plot((top, fig.add_subplot(2, 1, 2)))
    assert axes[0] is top and len(top.get_lines()) >= 2
    fig.savefig(tmp_path / "branch.png")
    assert "fold" in branch._repr_html_()


def test_continue_from_the_command_line(capsys, tmp_path):
    """A short branch of the level's 3-cycle in the energy, as JSON and as a figure; bad
    input refused in one line (exit 2)."""
    path = str(EXAMPLES / "parallel.toml")
    fast = ("--returns", "3", "--trajectories", "8", "--grid-seeds", "0")  # the 3-cycle
    fig = tmp_path / "branch.png"
    code, out, err = run_cli(
        capsys,
        "continue",
        path,
        "--orbit",
        "1",
        "--param",
        "energy",
        "--range",
        "3.26,3.30",
        "--points",
        "3",
        "--json",
        "-o",
        str(fig),
        *fast,
    )
    assert code == 0, err
    got = json.loads(out)
    assert got["param"] == "energy" and got["returns"] == 3 and fig.stat().st_size > 0
    assert 3 <= len(got["points"]) <= 5
    for p in got["points"]:
        assert 3.26 <= p["param"] <= 3.30 or p is got["points"][0] or p is got["points"][-1]
        assert set(p["initial"]) == {"gamma", "omega", "v_nu"} and p["unfolding"] < 1e-6
    for args in (
        ("--range", "x"),
        ("--range", "0.2,0.1"),
        ("--range", "5,6"),
        ("--orbit", "99", "--range", "3,4"),
    ):
        base = ["continue", path, "--param", "energy", *fast]
        if "--orbit" not in args:
            base += ["--orbit", "1"]
        code, out, err = run_cli(capsys, *base, *args)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (args, err)
        assert "Traceback" not in err
