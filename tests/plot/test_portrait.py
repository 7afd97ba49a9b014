"""The phase portrait of paper Fig. 5: every plotted point against docs/model.md's
one-degree-of-freedom formulas written with mpmath (tests/reduction/plain.py), and the shading
against the NumPy reference's normal force."""

import matplotlib.colors as mcolors
import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.plot import phase_portrait
from rollingtop.reduction import LevelSet, state_from_level

from ..conftest import PAPER_BODY
from ..dynamics import reference
from ..reduction import plain

#: Fig. 5's level set (Kilin & Ivanova 2023): M3 = 1, C1 = 0.5, C2 = -2.
M3, C1, C2 = 1.0, 0.5, -2.0
#: Energies drawn; the separatrix's (the saddle's U) is added, found here by mpmath.
H_LEVELS = (3.5, 4.0, 5.0, 6.5, 12.0)
#: h = U + rho w_tau^2 / 2 along each plotted orbit, relative (measured: 2e-14).
ENERGY_RTOL = 1e-12
#: Plotted steady motions against mpmath's roots of U'(gamma3), and U on the lower panel.
ROOT_TOL, U_RTOL = 1e-10, 1e-12


def energy(body, g3, w):
    return float(plain.U(body, M3, C1, C2, g3) + plain.rho(body, g3) * w * w / 2)


def du(body, g3):
    return mp.diff(lambda x: plain.U(body, M3, C1, C2, x), g3)


@pytest.fixture(scope="module")
def portrait():
    body = SphericalTop(**PAPER_BODY)
    with mp.workdps(30):
        saddle = mp.findroot(lambda g: du(body, g), (0.4, 0.6), solver="anderson")
        saddle_h = float(plain.U(body, M3, C1, C2, saddle))
    levels = sorted((*H_LEVELS, saddle_h))
    return body, levels, (saddle, saddle_h), phase_portrait(LevelSet(body, M3, C1, C2), levels)


def test_orbits_lie_on_their_energy_levels(portrait):
    """Each orbit is a closed curve on which U(gamma3) + rho(gamma3) w_tau^2 / 2 is one of the
    requested h; the separatrix (crimson) is the saddle's level and passes through the saddle;
    orbits are coloured in the order of h."""
    body, levels, (saddle, saddle_h), fig = portrait
    ax = fig.axes[0]
    drawn = {}
    for ln in ax.get_lines():
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        if len(x) < 10:
            continue  # markers and legend entries
        h = np.array([energy(body, g, w) for g, w in zip(x[::10], y[::10], strict=True)])
        (level,) = [u for u in levels if abs(h[0] - u) < ENERGY_RTOL * abs(u)]
        np.testing.assert_allclose(h, level, rtol=ENERGY_RTOL)
        np.testing.assert_allclose([x[0], y[0]], [x[-1], y[-1]], atol=1e-12)  # closed
        drawn.setdefault(level, []).append(ln)
    assert sorted(drawn) == levels
    separatrix = drawn[saddle_h]
    assert [mcolors.same_color(ln.get_color(), "crimson") for ln in separatrix] == [True]
    x, y = (np.asarray(d, float) for d in separatrix[0].get_data())
    assert np.min(np.hypot(x - float(saddle), y)) < 1e-2  # 400 points a branch: 3e-3 apart there
    hues = [mcolors.rgb_to_hsv(mcolors.to_rgb(drawn[h][0].get_color()))[0] for h in H_LEVELS]
    assert hues == sorted(hues, reverse=True)  # viridis: from purple to yellow as h grows


def test_steady_motions_are_the_critical_points_of_U(portrait):
    """Centres (dots) where U' = 0 and U'' > 0, the saddle (cross) where U'' < 0; the lower panel
    is U(gamma3) with the requested levels as horizontal lines."""
    body, levels, _, fig = portrait
    ax, axu = fig.axes
    marks = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 1]
    assert [ln.get_marker() for ln in marks] == ["o", "x", "o"]
    with mp.workdps(30):
        for ln in marks:
            (x,), (y,) = ln.get_data()
            root = mp.findroot(lambda g: du(body, g), (x - 1e-6, x + 1e-6), solver="anderson")
            assert (x, y) == (pytest.approx(float(root), abs=ROOT_TOL), 0)
            u2 = mp.diff(lambda g: plain.U(body, M3, C1, C2, g), root, 2)
            assert (u2 > 0) == (ln.get_marker() == "o")
    curve, *hlines = axu.get_lines()
    g, U = (np.asarray(d, float) for d in curve.get_data())
    expected = [float(plain.U(body, M3, C1, C2, gg)) for gg in g[::25]]
    np.testing.assert_allclose(U[::25], expected, rtol=U_RTOL)
    assert [ln.get_ydata()[0] for ln in hlines] == levels


def test_shading_is_where_the_normal_force_is_negative(portrait):
    """Points of the plane well inside the shaded region have a negative normal reaction by the
    NumPy reference, points well outside a positive one."""
    body, _, _, fig = portrait
    ax = fig.axes[0]
    (shade,) = ax.collections
    (region,) = shade.get_paths()
    level = LevelSet(body, M3, C1, C2)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    inside = []
    for g3 in np.linspace(x0 + 0.02, x1 - 0.02, 9):
        for w in np.linspace(y0, y1, 11)[1:-1]:
            h = energy(body, g3, w)
            y = state_from_level(level, h, g3, branch=1 if w >= 0 else -1)
            N, _ = reference.reactions("meridian", body.params, y)
            if abs(N) > 0.05 * body.m * body.g:  # away from the boundary N = 0
                assert region.contains_point((g3, w)) == (N < 0), (g3, w, N)
                inside.append(N < 0)
    assert any(inside) and not all(inside)
