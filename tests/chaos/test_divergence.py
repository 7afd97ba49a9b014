"""Phase volume along motions (rollingtop.chaos.divergence).

The divergence's time integral is held to the volume ratio of the flow map on the constraint
manifold, computed independently from nearby trajectories of the plain integrator; its time
average tends to 0 on the paper's model (invariant measure) and drifts on a chaotic motion of
the companion model.
"""

import math

import numpy as np
import pytest

from rollingtop import ScenarioError, SphericalTop, initial_state
from rollingtop._compiled._kernel import new_workspace
from rollingtop.chaos.divergence import (
    _moved,
    _project,
    _tangent_basis,
    manifold_divergence,
    phase_volume,
)
from rollingtop.contact import get_model
from rollingtop.integrate import integrate

from ..conftest import FREE, GAMMA0, OMEGA0, PAPER_BODY

PAPER = SphericalTop(**PAPER_BODY)
#: ln of the volume ratio over t = 2: the integral of the divergence (trapezoid, 2001 samples)
#: against the Gram determinant of the flow map by central differences (offset 1e-6, rtol 1e-12).
VOLUME_ATOL = 1e-5
#: |mean divergence| of the paper's model at t = 1000 (measured 2.0e-4, ~ 1/t: the integral
#: stays bounded, 0.2).
MEAN_INTEGRABLE = 1e-3
#: Mean divergence of the chaotic parallel motion at t = 5000 (measured -0.026; the integral
#: stays within -22..-44 through the motion's regular phase up to t ~ 2000, then falls to -131).
MEAN_CHAOTIC = -0.01


def _paper():
    return initial_state(PAPER, "meridian", gamma=GAMMA0, omega=OMEGA0, free=FREE["meridian"])


def _chaotic():
    return initial_state(PAPER, "parallel", gamma=(0.0, math.sqrt(0.19), 0.9),
                         omega=(2.0, -0.2, 3.0), free={"v_nu": 0.1})  # fmt: skip


def _log_volume_ratio(model, y0, t, e=1e-6):
    """ln sqrt(det G), G the Gram matrix of the flow map's images of an orthonormal basis of the
    tangent space at y0 (central differences of the plain integrator, projected starts)."""
    code = model.kernel_code(PAPER, y0)
    ws = new_workspace()
    basis = _tangent_basis(code, PAPER.params, y0, ws)
    columns = []
    for b in basis.T:
        ends = []
        for sign in (1.0, -1.0):
            start = _moved(y0, b, sign * e)
            _project(code, PAPER.params, start, y0[17] - math.atan2(y0[11], y0[8]), ws)
            ends.append(integrate(code, PAPER.params, start, [0.0, t], rtol=1e-12,
                                  atol=1e-14).y[-1])  # fmt: skip
        columns.append((ends[0][:15] - ends[1][:15]) / (2 * e))
    A = np.array(columns).T
    return 0.5 * np.linalg.slogdet(A.T @ A)[1]


@pytest.mark.parametrize("name,state", [("meridian", _paper), ("parallel", _chaotic)])
def test_integrated_divergence_is_the_volume_ratio_of_the_flow(name, state):
    model = get_model(name)
    y0 = state()
    pv = phase_volume(PAPER, model, y0, t_end=2.0, samples=2001)
    assert pv.mean[-1] * 2.0 == pytest.approx(_log_volume_ratio(model, y0, 2.0), abs=VOLUME_ATOL)
    assert abs(pv.mean[-1]) > 10 * VOLUME_ATOL  # the check sees a nonzero ratio


def test_the_paper_model_keeps_phase_volume_on_average():
    pv = phase_volume(PAPER, "meridian", _paper(), t_end=1000.0, samples=20001)
    assert pv.dimension == 7
    assert abs(pv.mean[-1]) < MEAN_INTEGRABLE
    assert np.max(np.abs(pv.divergence)) > 0.1  # the divergence itself is not zero


@pytest.mark.slow
def test_a_chaotic_parallel_motion_contracts_phase_volume():
    pv = phase_volume(PAPER, "parallel", _chaotic(), t_end=5000.0, samples=50001)
    assert pv.dimension == 7
    assert pv.mean[-1] < MEAN_CHAOTIC


def test_bad_input_is_refused():
    with pytest.raises(ScenarioError, match="t_end"):
        phase_volume(PAPER, "meridian", _paper(), t_end=-1.0)
    with pytest.raises(ScenarioError, match="violates a constraint"):
        manifold_divergence(PAPER, "parallel", _paper())


def test_a_motion_drawn_into_the_vertical_is_bounded_by_max_steps():
    """The oblique model at phi = 5 pi/6 draws this motion into the vertical, where it crawls
    through the regularised passage in tiny steps (without a bound, minutes): ``max_steps``
    ends it in one line instead."""
    from rollingtop._errors import IntegrationError
    from rollingtop.contact.oblique import oblique

    model = oblique(5 * np.pi / 6)
    y0 = initial_state(PAPER, model, gamma=[0.0, 0.6, 0.8], omega=[0.7, -0.3, 2.0],
                       free={"v_slip": 0.25})  # fmt: skip
    with pytest.raises(IntegrationError, match="max_steps = 20000"):
        phase_volume(PAPER, model, y0, t_end=100.0, samples=2001, max_steps=20_000)
