"""The curves of a phase portrait as data (rollingtop.reduction.curves), against docs/model.md's
one-degree-of-freedom formulas written with mpmath (tests/reduction/plain.py); computed without
matplotlib; the figures draw exactly these."""

import json
import subprocess
import sys

import mpmath as mp
import numpy as np
import pytest

from rollingtop import RollingTopError, SphericalTop
from rollingtop._figures import DRAWERS, TRAJECTORY_KINDS, draw
from rollingtop._html import html_view
from rollingtop.reduction import LevelSet, orbits, steady_motions
from rollingtop.reduction.curves import (
    default_h_levels,
    level_curves,
    on_a_saddle,
    orbit_curve,
    portrait_curves,
)

from ..conftest import PAPER_BODY, ROOT
from . import plain

#: Fig. 5's level set (Kilin & Ivanova 2023).
M3, C1, C2 = 1.0, 0.5, -2.0
#: U + rho w_tau^2 / 2 along each curve against its h, relative (measured: 2e-14).
ENERGY_RTOL = 1e-12
#: A curve's ends against the turning points of rollingtop.reduction.orbits (the same numbers).
TURNING_ATOL = 1e-14

BODY = SphericalTop(**PAPER_BODY)


def _energy(g3, w):
    return float(plain.U(BODY, M3, C1, C2, g3) + plain.rho(BODY, g3) * w * w / 2)


@pytest.fixture(scope="module")
def fig5():
    return LevelSet(BODY, M3, C1, C2)


def test_every_curve_lies_on_its_energy_and_closes(fig5):
    levels = default_h_levels(fig5)
    found = portrait_curves(fig5, levels)
    assert len(found.curves) >= len(levels)  # the separatrix level has two lobes
    x_lo, x_hi, w_top = found.window
    for c in found.curves:
        h = [_energy(g, w) for g, w in zip(c.x[::20], c.w[::20], strict=True)]
        np.testing.assert_allclose(h, c.h, rtol=ENERGY_RTOL)
        np.testing.assert_allclose([c.x[0], c.w[0]], [c.x[-1], c.w[-1]], atol=1e-12)
        assert x_lo <= np.nanmin(c.x) and np.nanmax(c.x) <= x_hi
        assert np.nanmax(np.abs(c.w)) < w_top
    saddles = {m.U for m in steady_motions(fig5) if m.type == "saddle"}
    assert saddles and all(on_a_saddle(u, saddles) for u in saddles)
    assert {c.h for c in found.curves if c.separatrix} == saddles


def test_a_curve_runs_between_the_orbits_turning_points(fig5):
    """The one turning-point search: a curve's ends are rollingtop.reduction.orbits' turning
    points (w_tau = 0 there), which mpmath's root of h = U confirms."""
    h = 4.0
    for orbit in orbits(fig5, h):
        x, w = orbit_curve(fig5, h, orbit, n=50)
        assert x[0] == pytest.approx(orbit.gamma3_max, abs=TURNING_ATOL)
        assert x[49] == pytest.approx(orbit.gamma3_min, abs=TURNING_ATOL)
        assert abs(w[0]) < 1e-6 and abs(w[49]) < 1e-6
        with mp.workdps(30):
            near = (x[49] - 1e-6, x[49] + 1e-6)  # a bracket: U - h changes sign across it
            root = mp.findroot(lambda g: plain.U(BODY, M3, C1, C2, g) - h, near, solver="anderson")
        assert float(root) == pytest.approx(x[49], abs=1e-12)


def test_no_motion_is_no_curve_and_a_refusal_for_a_portrait(fig5):
    u_min = min(m.U for m in steady_motions(fig5))
    assert level_curves(fig5, u_min - 1.0) == []
    with pytest.raises(RollingTopError, match="no motion"):
        portrait_curves(fig5, [u_min - 1.0])


def test_the_curves_and_the_explorers_views_need_no_matplotlib():
    """Issue 37: the numerics compute the figures' data; importing them, computing a level's
    curves and the explorer's level view imports no plotting."""
    script = (
        "import sys, json\n"
        "from rollingtop.explore.view import default_scenario, level_view, state_from_scenario\n"
        "from rollingtop.reduction import LevelSet\n"
        "from rollingtop.reduction.curves import portrait_curves, default_h_levels\n"
        "from rollingtop import SphericalTop\n"
        f"b = SphericalTop(**{PAPER_BODY!r})\n"
        "lv = LevelSet(b, 1.0, 0.5, -2.0)\n"
        "portrait_curves(lv, default_h_levels(lv))\n"
        "level_view(state_from_scenario(default_scenario()))\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.startswith(('matplotlib', "
        "'rollingtop.plot')))))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[-1]) == []


def test_every_drawer_is_named_right():
    """The drawers rollingtop._figures names exist in rollingtop.plot, and a trajectory's kinds
    are rollingtop.plot.paths.PANELS'."""
    import importlib

    from rollingtop.plot.paths import PANELS

    for kind, where in DRAWERS.items():
        module, function = where.split(":")
        assert callable(getattr(importlib.import_module(module), function)), kind
    assert set(TRAJECTORY_KINDS) == set(PANELS)
    assert all(DRAWERS[k].endswith(PANELS[k].__name__) for k in TRAJECTORY_KINDS)
    with pytest.raises(RollingTopError, match="no figure of kind 'pie'"):
        draw("pie", None)


def test_a_type_without_a_view_is_named():
    with pytest.raises(LookupError, match="no HTML view is registered for object"):
        html_view(object())
