"""Full state <-> reduced variables and integrals: exact round trips."""

import math

import numpy as np
import pytest

from rollingtop import initial_state
from rollingtop.dynamics.state import constraint_residuals
from rollingtop.reduction import (
    LevelSet,
    LevelSetError,
    euler_angles,
    reduce_state,
    reduced_integrals,
    state_from_level,
)

ROUND_TRIP = 1e-12  # issue 3: round trips exact to 1e-12


def random_states(body, rng, n=40):
    for _ in range(n):
        gamma = rng.normal(size=3)
        gamma /= np.linalg.norm(gamma)
        a = rng.normal(size=3)
        alpha = a - (a @ gamma) * gamma
        yield initial_state(body, "meridian", gamma=gamma, omega=rng.normal(size=3) * 2,
                            alpha=alpha / np.linalg.norm(alpha), position=rng.normal(size=2),
                            free={"v_tau": rng.normal()})  # fmt: skip


def test_full_reduced_full_round_trip(paper_body, rng):
    for y in random_states(paper_body, rng):
        ints = reduced_integrals(paper_body, y)
        red = reduce_state(y)
        ang = euler_angles(y)
        level = LevelSet(paper_body, float(ints["M3"]), float(ints["C1"]), float(ints["C2"]))
        back = state_from_level(level, float(ints["h"]), float(red["gamma3"]),
                                branch=1 if red["w_tau"] >= 0 else -1, phi=float(ang["phi"]),
                                psi=float(ang["psi"]), position=y[15:17])  # fmt: skip
        np.testing.assert_allclose(back, y, rtol=0, atol=ROUND_TRIP * max(1, np.abs(y).max()))


def test_state_from_level_lands_on_the_level(paper_body):
    level = LevelSet(paper_body, M3=1.0, C1=0.5, C2=-2.0)
    for g3, branch in ((0.2, 1), (-0.4, -1), (0.93, 1)):
        h = float(level.U(math.acos(g3))) + 0.7
        y = state_from_level(level, h, g3, branch=branch, phi=0.4, psi=-1.1, position=(2, 3))
        assert np.max(np.abs(constraint_residuals(paper_body, "meridian", y))) < 1e-15
        ints = reduced_integrals(paper_body, y)
        for name, value in (("M3", 1.0), ("C1", 0.5), ("C2", -2.0), ("h", h)):
            assert float(ints[name]) == pytest.approx(value, abs=ROUND_TRIP), name
        red, ang = reduce_state(y), euler_angles(y)
        assert float(red["gamma3"]) == pytest.approx(g3, abs=1e-15)
        assert np.sign(red["w_tau"]) == branch
        assert float(ang["phi"]) == pytest.approx(0.4) and float(ang["psi"]) == pytest.approx(-1.1)
        np.testing.assert_allclose(y[6:15].reshape(3, 3) @ y[6:15].reshape(3, 3).T, np.eye(3),
                                   atol=1e-15)  # fmt: skip


def test_state_from_level_refuses_forbidden_region(paper_body):
    level = LevelSet(paper_body, M3=1.0, C1=0.5, C2=-2.0)
    with pytest.raises(LevelSetError, match="below the effective potential"):
        state_from_level(level, 3.0, 0.0)
    with pytest.raises(LevelSetError, match="strictly inside"):
        state_from_level(level, 10.0, 1.0)
