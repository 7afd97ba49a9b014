"""Effective potential and level sets against docs/model.md's formulas evaluated with mpmath."""

import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.reduction import LevelSet, LevelSetError

from ..conftest import PAPER_BODY
from . import plain

FIG5 = dict(M3=1.0, C1=0.5, C2=-2.0)  # paper, Fig. 5
U_RTOL = 1e-13  # potential: double precision vs mpmath (30 digits)
DU_RTOL = 1e-9  # derivatives vs mpmath numerical differentiation


@pytest.fixture
def fig5(paper_body):
    return LevelSet(paper_body, **FIG5)


def test_potential_matches_model_md(fig5, paper_body):
    with mp.workdps(30):
        for g3 in np.linspace(-0.98, 0.98, 41):
            expected = plain.U(paper_body, 1, 0.5, -2, g3)
            assert fig5.U_gamma3(g3) == pytest.approx(float(expected), rel=U_RTOL)


def test_derivatives_match_mpmath(fig5, paper_body):
    with mp.workdps(30):
        for g3 in (-0.9, -0.5, 0.1, 0.5, 0.93):
            theta = math.acos(g3)

            def u_theta(t):
                return plain.U(paper_body, 1, 0.5, -2, mp.cos(t))

            d1 = mp.diff(u_theta, mp.acos(mp.mpf(g3)))
            d2 = mp.diff(u_theta, mp.acos(mp.mpf(g3)), 2)
            assert float(fig5.dU(theta)) == pytest.approx(float(d1), rel=DU_RTOL, abs=1e-12)
            assert float(fig5.d2U(theta)) == pytest.approx(float(d2), rel=DU_RTOL)


def test_reduced_quantities_match_eq_3_8(fig5, paper_body):
    g3 = 0.3
    s = math.sqrt(1 - g3**2)
    theta = math.acos(g3)
    assert fig5.w_n(theta) == pytest.approx((1 * g3 - 0.5) / (0.3 * s), rel=1e-14)
    I1v = (1 * (1 - 0.5 * g3) + 0.1 * (g3 - 0.5)) / s - 2 + 0.1 * math.acos(g3)
    assert fig5.v_tau(theta) == pytest.approx(I1v / 0.3, rel=1e-14)
    assert fig5.psi_dot(theta) == pytest.approx(-fig5.w_n(theta) / s, rel=1e-14)


@pytest.mark.parametrize(("C1", "pole", "theta0"), [(1.0, "south", 0.0), (-1.0, "north", math.pi)])
def test_pole_cases_are_regular(paper_body, C1, pole, theta0):
    """C1 = +-M3: recognised, snapped, and U, U', w_n finite through the pole; off the pole the
    snapped formulas equal the general ones (which lose nothing there)."""
    level = LevelSet(paper_body, M3=1.0, C1=C1 * (1 + 1e-14), C2=-0.3)
    assert level.pole == pole and level.C1 == C1
    with np.errstate(all="raise"):
        for t in (theta0 - 0.2, theta0, theta0 + 0.2):
            assert np.isfinite([level.U(t), level.dU(t), level.d2U(t), level.w_n(t)]).all()
    with mp.workdps(30):
        for t in (0.3, 0.7) if pole == "south" else (math.pi - 0.3, math.pi - 0.7):
            exact = plain.U(paper_body, 1, C1, -0.3, mp.cos(t))  # model sheet, C1 = +-M3 exactly
            assert level.U(t) == pytest.approx(float(exact), rel=U_RTOL)
            d1 = mp.diff(lambda x: plain.U(paper_body, 1, C1, -0.3, mp.cos(x)), t)
            assert level.dU(t) == pytest.approx(float(d1), rel=DU_RTOL)
    # at the pole U is docs/model.md's limit: only the v_tau term and gravity remain
    I1v = -0.3 + (1.0 * paper_body.a3 * theta0)
    expected = paper_body.m * I1v**2 / (2 * paper_body.I1**2) + paper_body.m * paper_body.g * (
        paper_body.a3 * math.cos(theta0)
    )
    assert level.U(theta0) == pytest.approx(expected, rel=1e-14)


def test_bad_levels(paper_body):
    with pytest.raises(LevelSetError, match="C2 = nan must be finite"):
        LevelSet(paper_body, M3=1.0, C1=0.5, C2=float("nan"))
    with pytest.raises(LevelSetError, match="M3 = '1' must be a number"):
        LevelSet(paper_body, M3="1", C1=0.5, C2=0.0)
    with pytest.raises(LevelSetError, match="dynamically symmetric"):
        LevelSet(SphericalTop(**PAPER_BODY, I2=0.4), M3=1.0, C1=0.5, C2=0.0)
