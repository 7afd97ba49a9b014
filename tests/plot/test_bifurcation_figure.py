"""The bifurcation figure's thumbnails: each region's level curve, closed at its turning points,
on docs/model.md's energy (mpmath, tests/reduction/plain.py), and filling its panel."""

import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.plot.bifurcation import THUMB_MARGIN, bifurcation_figure
from rollingtop.reduction.bifurcation import bifurcation_diagram

from ..conftest import PAPER_BODY
from ..reduction import plain

PAPER = SphericalTop(**PAPER_BODY)
#: h = U + rho w_tau^2 / 2 along each drawn orbit, relative.
ENERGY_RTOL = 1e-10
#: The orbits' extent over the panel's, along each axis: at least this (margins THUMB_MARGIN).
FILL = 1.0 / (1.0 + 2.5 * THUMB_MARGIN)


@pytest.fixture(scope="module")
def thumbnails():
    diagram = bifurcation_diagram(PAPER, 1.0, 0.5)
    fig = bifurcation_figure(diagram)
    by_name = {r.name: r for r in diagram.regions}
    axes = {ax.get_title()[0]: ax for ax in fig.axes if ax.get_title()[:2].rstrip(":") in by_name}
    return by_name, axes


def test_a_thumbnail_per_region_each_orbit_on_its_level(thumbnails):
    regions, axes = thumbnails
    assert sorted(axes) == sorted(regions) == ["A", "B", "C", "D"]
    for name, ax in axes.items():
        r = regions[name]
        orbits = [line for line in ax.get_lines() if len(line.get_xdata()) > 2]
        # Fig. 5's level: A and D one orbit, B two, C one around both centres
        assert len(orbits) == {"A": 1, "B": 2, "C": 1, "D": 1}[name]
        for line in orbits:
            g3, w = line.get_xdata(), line.get_ydata()
            assert (g3[0], w[0]) == (g3[-1], w[-1]) and w[0] == 0.0  # closed at a turning point
            for x, y in zip(g3[::37], w[::37], strict=True):
                U = float(plain.U(PAPER, 1.0, 0.5, r.C2, x))
                h = U + float(plain.rho(PAPER, x)) * y * y / 2
                assert h == pytest.approx(r.h, rel=ENERGY_RTOL)


def test_each_orbit_fills_its_panel(thumbnails):
    """The axes fit the orbits (region A's orbit, gamma3 in about [0.924, 0.936], is no longer
    a sliver at the edge of [-1, 1])."""
    _, axes = thumbnails
    for name, ax in axes.items():
        orbits = [line for line in ax.get_lines() if len(line.get_xdata()) > 2]
        x = np.concatenate([line.get_xdata() for line in orbits])
        y = np.concatenate([line.get_ydata() for line in orbits])
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 <= x.min() and x.max() <= x1 and y0 <= y.min() and y.max() <= y1
        assert np.ptp(x) / (x1 - x0) >= FILL and np.ptp(y) / (y1 - y0) >= FILL, name
    assert 0.9 < axes["A"].get_xlim()[0] < axes["A"].get_xlim()[1] < 0.95
