"""The reduction's objects in a notebook (rollingtop.reduction._display): every number a view
(``_repr_html_``) shows against the object's own attributes and a computation written here (the
extrema of U on a fine grid, a period by scipy's adaptive quadrature), and every ``.plot()``
against the data it draws. The lists of steady motions and orbits stay lists."""

import json
import math
import pickle

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.axes import Axes
from scipy.integrate import quad

from rollingtop import SphericalTop
from rollingtop.reduction import LevelSet, Orbits, SteadyMotions, orbits, steady_motions
from rollingtop.reduction.bifurcation import bifurcation_diagram
from rollingtop.reduction.classify import classify_models
from rollingtop.reduction.curves import default_h_levels

from ..conftest import GAMMA0, OMEGA0, PAPER_BODY
from ..html_view import num, read

matplotlib.use("Agg")

#: Fig. 5's level set (Kilin & Ivanova 2023): M3 = 1, C1 = 0.5, C2 = -2, and examples/fig5.toml's h.
M3, C1, C2, H = 1.0, 0.5, -2.0, 4.0
#: A value shown to d significant digits against the value itself: half a unit in the last one.
DIGITS = {6: 5e-6, 10: 5e-10, 12: 5e-12, 3: 5e-3}
#: Points of the grid of theta on which the extrema of U are counted here.
GRID = 400_001
#: scipy's adaptive quadrature of the period against the package's Gauss-Legendre one.
PERIOD_RTOL = 1e-9
#: h = U + rho w_tau^2 / 2 along a drawn orbit (both round-off of the same formulas).
ENERGY_RTOL = 1e-10


def close(shown, value, digits):
    return math.isclose(num(shown), value, rel_tol=DIGITS[digits], abs_tol=1e-300)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def body():
    return SphericalTop(**PAPER_BODY)


@pytest.fixture(scope="module")
def fig5(body):
    return LevelSet(body, M3, C1, C2)


@pytest.fixture(scope="module")
def levels(body, fig5):
    """Fig. 5's level, its south pole level, and the paper's state's level under the smooth,
    rough and rubber models (as compare-classification reads them)."""
    others = {c.model: c.level for c in classify_models(body, GAMMA0, OMEGA0, n=3)}
    return {"fig5": fig5, "pole": LevelSet(body, M3, M3, C2),
            **{m: others[m] for m in ("smooth", "rough", "rubber")}}  # fmt: skip


def extrema(level):
    """``theta`` of the local minima and maxima of ``U`` on a fine grid of the level's domain."""
    lo, hi = level.theta_domain
    theta = np.linspace(lo, hi, GRID)[1:-1]
    with np.errstate(all="ignore"):
        U = np.asarray(level.U(theta), dtype=float)
    ok = np.isfinite(U)
    theta, U = theta[ok], U[ok]
    d = np.sign(np.diff(U))
    turn = np.flatnonzero(d[:-1] * d[1:] < 0) + 1
    minima = theta[turn[d[turn - 1] < 0]]
    maxima = theta[turn[d[turn - 1] > 0]]
    return minima, maxima


# ---- the lists -----------------------------------------------------------------------------
def test_steady_motions_and_orbits_are_lists_that_know_their_level(fig5):
    motions, found = steady_motions(fig5), orbits(fig5, H)
    assert isinstance(motions, SteadyMotions) and isinstance(motions, list)
    assert isinstance(found, Orbits) and isinstance(found, list)
    assert motions.level is fig5 and found.level is fig5 and found.h == H
    assert motions == list(motions) and found == list(found)
    # the JSON of the commands is made of the items: the same bytes from a plain list
    assert json.dumps([m.to_dict() for m in motions]) == json.dumps(
        [m.to_dict() for m in list(motions)])  # fmt: skip
    again = pickle.loads(pickle.dumps(found))
    assert again == found and again.level == fig5 and again.h == H
    assert pickle.loads(pickle.dumps(motions)).level == fig5


def test_the_mirrored_and_no_spin_levels_give_the_lists_too(body):
    near_north = LevelSet(body, M3, -0.999, C2)  # computed on its mirror image
    assert steady_motions(near_north).level is near_north
    no_spin = LevelSet(body, 0.0, 0.0, 0.5)
    h = max(m.U for m in steady_motions(no_spin)) + 0.1
    found = orbits(no_spin, h)
    assert isinstance(found, Orbits) and found.level is no_spin and found.h == h


# ---- the views -----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["fig5", "pole", "smooth", "rough", "rubber"])
def test_a_level_shows_its_integrals_body_and_steady_motions(levels, name):
    level = levels[name]
    view = read(level._repr_html_())
    assert view.title == f"rollingtop.reduction.{type(level).__name__}"
    assert view.subtitle.startswith(f"{level.model} model")
    (shown,) = view.records("level")
    for k, v in level.values().items():
        assert close(shown[k], v, 6)
    assert shown["pole case"] == (level.pole or "none")
    (shown,) = view.records("body")
    assert {k: num(v) for k, v in shown.items()} == pytest.approx(level.body.to_dict(), 1e-5)
    minima, maxima = extrema(level)
    n = len(minima) + len(maxima)
    (line,) = view.texts
    assert line.startswith(f"{n} steady motion{'s' if n != 1 else ''}: {len(minima)} centre")
    assert f"{len(maxima)} saddle" in line


def test_a_level_without_isolated_steady_motions_says_why(body):
    """A balanced body without spin: U is constant, steady_motions refuses the level, and the
    view shows the refusal instead of a count."""
    from dataclasses import replace

    level = LevelSet(replace(body, a3=0.0), 0.0, 0.0, 0.5)
    (line,) = read(level._repr_html_()).texts
    assert line.startswith("U is constant (U = ") and "none is isolated" in line


def test_steady_motions_show_each_motion(fig5):
    motions = steady_motions(fig5)
    view = read(motions._repr_html_())
    assert view.subtitle.startswith("3 steady motions: 2 centres, 1 saddle on M3 = 1")
    rows = view.records("")
    assert len(rows) == len(motions) == 3
    minima, maxima = extrema(fig5)
    found = sorted([*np.cos(minima), *np.cos(maxima)])
    for row, m, g3 in zip(rows, motions, found, strict=True):
        assert close(row["gamma3"], m.gamma3, 6) and close(row["U"], m.U, 6)
        assert row["gamma3"] and abs(num(row["gamma3"]) - g3) < 1e-4  # the grid's spacing
        assert row["type"] == m.type and close(row["psi'"], m.precession_rate, 6)
        if m.type == "center":
            assert close(row["period"], 2 * math.pi / m.frequency, 6)
        else:
            assert row["period"] == "–"
        assert row["linearly stable"] == ("yes" if m.linearly_stable else "no")


def test_orbits_show_their_turning_points_and_periods(fig5, body):
    found = orbits(fig5, H)
    view = read(found._repr_html_())
    assert view.subtitle == "2 orbits on M3 = 1, C1 = 0.5, C2 = -2 at h = 4"
    (level,) = view.records("level")
    energy = H + M3**2 / (2 * body.I3) + body.m * body.g * body.R  # docs/model.md: h -> E
    assert close(level["energy E"], energy, 6) and close(level["h"], H, 6)
    for row, o in zip(view.records(""), found, strict=True):
        assert close(row["gamma3_min"], o.gamma3_min, 10)
        assert close(row["gamma3_max"], o.gamma3_max, 10)
        assert close(row["period"], o.period, 12) and row["kind"] == "periodic"
        # the period by scipy's adaptive quadrature, theta = c + d sin(phi) between the turns
        c, d = (o.theta_min + o.theta_max) / 2, (o.theta_max - o.theta_min) / 2

        def dt(phi, c=c, d=d):
            theta = c + d * math.sin(phi)
            gap = H - float(fig5.U(theta))
            return math.sqrt(float(fig5.rho(theta)) / (2 * max(gap, 1e-300))) * d * math.cos(phi)

        period = 2 * quad(dt, -math.pi / 2, math.pi / 2, epsabs=0, epsrel=1e-12, limit=200)[0]
        assert num(row["period"]) == pytest.approx(period, rel=PERIOD_RTOL)


def test_a_diagram_shows_its_folds_and_regions(body):
    diagram = bifurcation_diagram(body, M3, C1, resolution=(61, 61))
    text = repr(diagram)
    assert "\n" not in text and text.startswith("<BifurcationDiagram: M3 = 1, C1 = 0.5; 1 fold, ")
    view = read(diagram._repr_html_())
    assert view.subtitle.endswith(f"{len(diagram.branches)} branches of critical values, 1 fold, "
                                  f"{len(diagram.regions)} regions")  # fmt: skip
    (window,) = view.records("window")
    assert close(window["C2 from"], diagram.C2_grid[0], 6) and window["grid"] == "61 x 61"
    (fold,) = view.records("folds")
    (f,) = diagram.folds
    assert close(fold["C2"], f.C2, 6) and close(fold["h"], f.h, 6)
    # the fold is where the number of steady motions changes (3 below it, 1 above)
    below, above = (LevelSet(body, M3, C1, f.C2 + s) for s in (-1e-3, 1e-3))
    assert [len(steady_motions(lv)) for lv in (below, above)] == [3, 1]
    for row, r in zip(view.records("regions"), diagram.regions, strict=True):
        assert row["region"] == r.name and row["a level in it holds"] == r.label
        assert close(row["C2"], r.C2, 6) and int(row["grid cells"]) == r.cells
        # the representative level holds as many periodic orbits as the label says
        periodic = [o for o in orbits(LevelSet(body, M3, C1, r.C2), r.h) if o.kind == "periodic"]
        assert r.label.startswith(f"{len(periodic)} orbit")


# ---- the figures ---------------------------------------------------------------------------
def curves(ax):
    """The drawn curves (not markers, not the h lines): (x, y) arrays."""
    out = []
    for ln in ax.get_lines():
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        if len(x) >= 10:
            out.append((x, y))
    return out


def markers(ax, marker):
    return sorted((float(ln.get_xdata()[0]), float(ln.get_ydata()[0])) for ln in ax.get_lines()
                  if ln.get_marker() == marker and len(ln.get_xdata()) == 1)  # fmt: skip


@pytest.mark.parametrize("name", ["fig5", "pole", "smooth", "rough", "rubber"])
def test_a_level_draws_its_phase_portrait(levels, name):
    level = levels[name]
    ax = level.plot()
    assert isinstance(ax, Axes) and ax.get_legend() is not None
    assert ax.get_title().startswith(f"{level.model} model")
    drawn = curves(ax)
    assert drawn
    hs = default_h_levels(level)
    for x, y in drawn:
        theta = x if level.pole else np.arccos(x)
        h = level.energy(theta, y)
        (at,) = [u for u in hs if abs(h[len(h) // 4] - u) <= ENERGY_RTOL * max(1.0, abs(u))]
        np.testing.assert_allclose(h, at, rtol=ENERGY_RTOL, atol=ENERGY_RTOL)
    motions = steady_motions(level)
    where = (lambda m: m.theta) if level.pole else (lambda m: m.gamma3)
    lo, hi = ax.get_xlim()
    centres = [(where(m), 0.0) for m in motions if m.type == "center" and lo <= where(m) <= hi]
    np.testing.assert_allclose(markers(ax, "o"), sorted(centres), atol=1e-12)


def test_the_plots_draw_on_the_axes_given(fig5, body):
    _, axes = plt.subplots(1, 4)
    diagram = bifurcation_diagram(body, M3, C1, resolution=(21, 21))
    things = (fig5, steady_motions(fig5), orbits(fig5, H), diagram)
    for ax, thing in zip(axes, things, strict=True):
        assert thing.plot(ax=ax) is ax


def test_steady_motions_draw_U_with_each_motion_at_its_energy(fig5):
    motions = steady_motions(fig5)
    ax = motions.plot()
    (U,) = [(x, y) for x, y in curves(ax) if len(x) == 1500]
    np.testing.assert_allclose(U[1], fig5.U_gamma3(U[0]), rtol=1e-13)
    centres = sorted((m.gamma3, m.U) for m in motions if m.type == "center")
    np.testing.assert_allclose(markers(ax, "o"), centres, rtol=1e-13)
    (saddle,) = [m for m in motions if m.type == "saddle"]
    assert markers(ax, "x") == [pytest.approx((saddle.gamma3, saddle.U), rel=1e-13)]
    levels = sorted(float(ln.get_ydata()[0]) for ln in ax.get_lines() if len(ln.get_xdata()) == 2)
    np.testing.assert_allclose(levels, default_h_levels(fig5), rtol=1e-13)


def test_orbits_draw_each_closed_curve_on_their_energy(fig5):
    found = orbits(fig5, H)
    ax = found.plot()
    drawn = sorted(curves(ax), key=lambda c: c[0].min())
    assert len(drawn) == len(found) == 2
    for (x, y), o in zip(drawn, found, strict=True):
        np.testing.assert_allclose(fig5.energy(np.arccos(x), y), H, rtol=ENERGY_RTOL)
        assert x.min() == pytest.approx(o.gamma3_min, abs=1e-9)
        assert x.max() == pytest.approx(o.gamma3_max, abs=1e-9)
    assert len(markers(ax, "x")) == 1  # the saddle between the wells


def test_a_diagram_draws_its_curves_folds_and_regions(body):
    diagram = bifurcation_diagram(body, M3, C1, resolution=(61, 61))
    ax = diagram.plot(mark_C2=C2)
    lines = {id(ln): ln for ln in ax.get_lines()}
    for br in diagram.branches:
        for is_centre in (True, False):
            c2 = np.where(br.centre == is_centre, br.C2, np.nan)
            assert any(np.array_equal(ln.get_xdata(), c2, equal_nan=True)
                       and np.array_equal(ln.get_ydata(), br.h, equal_nan=True)
                       for ln in lines.values())  # fmt: skip
    assert markers(ax, "o") == [(f.C2, f.h) for f in diagram.folds]
    assert sorted(t.get_text() for t in ax.texts) == sorted(r.name for r in diagram.regions)
    (mark,) = [ln for ln in ax.get_lines() if ln.get_label() == f"C2 = {C2:g}"]
    assert list(mark.get_xdata()) == [C2, C2]
    (mesh,) = ax.collections
    np.testing.assert_array_equal(np.ma.filled(mesh.get_array(), -1), diagram.region_index)
