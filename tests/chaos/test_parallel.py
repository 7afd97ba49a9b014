"""Chaos in the companion (``parallel``) model, located with its Poincare section: a motion with
a positive maximal exponent by two independent estimates, next to a regular one on the same
body (``examples/section_parallel.toml``), and the paper's model from the same state."""

import math

import numpy as np
import pytest

from rollingtop import SphericalTop, initial_state
from rollingtop.chaos import chaos_indicators

from ..conftest import PAPER_BODY
from .test_lyapunov import _two_trajectory_exponent

PAPER = SphericalTop(**PAPER_BODY)
GAMMA = (0.0, math.sqrt(1.0 - 0.81), 0.9)
OMEGA = (2.0, -0.2, 3.0)
#: A chaotic motion's exponent at t = 3000 is at least this (measured 0.016-0.019 by the tangent
#: dynamics at rtol 1e-10 / 1e-12 and t = 3000 / 5000, 0.026 by two nearby trajectories renormalised
#: every 50 time units); a quasi-periodic one is below it (measured 2.6e-3 ~ ln t / t).
CHAOTIC_EXPONENT = 8e-3
#: Mean MEGNO of a quasi-periodic motion at t = 3000 (measured 1.954; 2 in the limit).
MEGNO_TOL_REGULAR = 0.1
#: Two estimates of a finite-time exponent in a chaotic layer with slow transport: they agree
#: to within this factor at t = 3000.
EXPONENT_FACTOR = 2.5


def _state(model, **free):
    return initial_state(PAPER, model, gamma=GAMMA, omega=OMEGA, free=free)


def test_a_chaotic_motion_of_the_parallel_model():
    r = chaos_indicators(PAPER, "parallel", _state("parallel", v_nu=0.1), t_end=3000.0)
    assert r.lyapunov[-1] > CHAOTIC_EXPONENT
    assert r.megno_mean[-1] > 10.0  # ~ lambda t / 2: grows without bound
    assert max(r.integral_drift().values()) < 1e-6


def test_the_same_body_rolling_from_rest_at_the_contact_is_regular_under_both_models():
    """The contact point at rest (v = -w x r satisfies both models' constraints: the same state):
    quasi-periodic under parallel, and under the integrable paper's model."""
    r_contact = -PAPER.R * np.array(GAMMA) - np.array([0.0, 0.0, PAPER.a3])
    v = -np.cross(OMEGA, r_contact)
    for model in ("parallel", "meridian"):
        y0 = initial_state(PAPER, model, gamma=GAMMA, omega=OMEGA, v=v)
        r = chaos_indicators(PAPER, model, y0, t_end=3000.0)
        assert abs(r.megno_mean[-1] - 2.0) < MEGNO_TOL_REGULAR, model
        assert r.lyapunov[-1] < CHAOTIC_EXPONENT, model


def test_the_parallel_exponent_by_two_nearby_trajectories():
    """Measured: 0.0156 (tangent dynamics) and 0.0145 (Benettin, renormalised every 10)."""
    y0 = _state("parallel", v_nu=0.1)
    lam = chaos_indicators(PAPER, "parallel", y0, t_end=3000.0).lyapunov[-1]
    from rollingtop.chaos.lyapunov import initial_tangent
    from rollingtop.contact import get_model

    other = _two_trajectory_exponent(PAPER, get_model("parallel"), y0, initial_tangent(), 3000.0,
                                     dt=10.0)  # fmt: skip
    assert other > CHAOTIC_EXPONENT
    assert 1.0 / EXPONENT_FACTOR < other / lam < EXPONENT_FACTOR


def test_the_readme_states_what_the_chaos_command_measures():
    """README: 'the finite-time maximal Lyapunov exponent ... is 0.018 at t = 3000 and the mean
    MEGNO 24' (a finite-time exponent of a chaotic motion: its digits move with the last bits
    of the compiled code), for examples/parallel_chaotic.toml."""
    from pathlib import Path

    from rollingtop.scenario import load_scenario

    root = Path(__file__).resolve().parents[2]
    readme = " ".join((root / "README.md").read_text().split())
    sc = load_scenario(root / "examples" / "parallel_chaotic.toml")
    r = chaos_indicators(sc.body, sc.model, sc.require_state(), t_end=sc.integration.t_end)
    assert f"is {r.lyapunov[-1]:.2g} at `t = 3000`" in readme
    assert f"the mean MEGNO {r.megno_mean[-1]:.0f} and growing" in readme


def test_the_tangent_dynamics_stops_at_the_vertical_in_one_line():
    """A motion that reaches the vertical (seed-0 state of tests/contact/test_parallel.py, at
    t = 8.6105): the flow has no derivative there; the indicators are refused past it, and a map
    marks the point with its status."""
    from rollingtop import IntegrationError
    from rollingtop._compiled._tangent import REACHED_VERTICAL
    from rollingtop.chaos import indicator_map

    from ..contact.test_parallel import BODY, _generic_state

    y0 = _generic_state()
    assert chaos_indicators(BODY, "parallel", y0, t_end=8.0).lyapunov[-1] > 0
    with pytest.raises(IntegrationError, match="reaches the vertical after t = 8.6"):
        chaos_indicators(BODY, "parallel", y0, t_end=20.0)
    ds = indicator_map(BODY, "parallel", np.array([y0, y0]), t_end=20.0)
    assert list(ds["status"].values) == [REACHED_VERTICAL] * 2
    assert "reached the vertical" in ds.attrs["status_names"]
