"""simulate() without a file: typed objects in, the same trajectory as from a scenario out; and
the numerics a scenario calls (initial conditions, a state on a level)."""

import numpy as np
import pytest

from rollingtop import (
    MODELS,
    InitialStateError,
    IntegrationOptions,
    initial_state,
    load_scenario,
    simulate,
    simulate_models,
)
from rollingtop.dynamics.start import InitialConditions
from rollingtop.reduction import LevelSet, reduced_integrals
from rollingtop.reduction.start import level_of_state, reduced_energy, start_on_level

from .conftest import EXAMPLES, FREE, GAMMA0, OMEGA0

OPTIONS = IntegrationOptions(t_end=1.0, rtol=1e-11, samples=11)


@pytest.mark.parametrize("example", ["paper", "smooth", "rough", "rubber"])
def test_body_model_state_options_match_the_scenario(example):
    """simulate(body, model, state, options) runs exactly what simulate(scenario) runs: the same
    computation, so the same trajectory to the last bit."""
    sc = load_scenario(EXAMPLES / f"{example}.toml")
    from_file = simulate(sc, options=OPTIONS)
    assert sc.initial is not None and sc.y0 is not None
    from_objects = simulate(sc.body, sc.model, sc.initial, OPTIONS)
    np.testing.assert_array_equal(from_objects.y, from_file.y)
    assert from_objects.model is sc.model and from_objects.t[-1] == 1.0
    from_array = simulate(sc.body, sc.model.name, sc.y0, OPTIONS)  # a name does as well
    np.testing.assert_array_equal(from_array.y, from_file.y)


def test_keyword_options_replace_single_values(paper_body):
    ic = InitialConditions(gamma=GAMMA0, omega=OMEGA0, free=FREE["meridian"])
    traj = simulate(paper_body, "meridian", ic, t_end=0.5, samples=6)
    # the samples are linspace(0, t_end, samples) itself: copied, so exact
    np.testing.assert_array_equal(traj.t, np.linspace(0.0, 0.5, 6))
    assert traj.rtol == IntegrationOptions().rtol
    traj = simulate(paper_body, "meridian", ic, OPTIONS, rtol=1e-9)
    assert traj.rtol == 1e-9 and traj.atol == pytest.approx(1e-11) and traj.t[-1] == 1.0


def test_a_state_off_the_constraints_is_refused(paper_body):
    y0 = initial_state(paper_body, "meridian", gamma=GAMMA0, omega=OMEGA0, free=FREE["meridian"])
    with pytest.raises(InitialStateError, match="violates the constraint .* of model 'rough'"):
        simulate(paper_body, "rough", y0, OPTIONS)
    with pytest.raises(InitialStateError, match="state must be 18 finite numbers"):
        simulate(paper_body, "meridian", y0[:17], OPTIONS)
    with pytest.raises(TypeError, match="a body needs a model and a state"):
        simulate(paper_body, "meridian")
    with pytest.raises(TypeError, match="the scenario holds the state"):
        simulate(EXAMPLES / "paper.toml", state=y0)


def test_simulate_models_reports_progress_per_model():
    """Each model's run reports its own times, rising from 0 to t_end."""
    seen: dict[str, list[float]] = {}
    runs = simulate_models(
        EXAMPLES / "paper.toml",
        t_end=0.5,
        progress=lambda name, t: seen.setdefault(name, []).append(t),
    )
    takes_it = [name for name, m in MODELS.items() if not m.own_inertia]  # no shell: not the pair
    assert list(runs) == takes_it == list(seen)
    for times in seen.values():
        assert times == sorted(times) and times[-1] == 0.5


def test_start_on_level_is_the_scenarios_state():
    """examples/fig5.toml starts on its [level]; the same numerics without the file."""
    sc = load_scenario(EXAMPLES / "fig5.toml")
    level = LevelSet(sc.body, 1.0, 0.5, -2.0)
    y = start_on_level(level, 4.0)
    np.testing.assert_array_equal(y, sc.y0)  # the scenario calls start_on_level: the same bits
    back = level_of_state(sc.body, y, "meridian")
    assert (back.M3, back.C1, back.C2) == pytest.approx((1.0, 0.5, -2.0), abs=1e-12)
    assert reduced_energy(sc.body, y, "meridian") == pytest.approx(4.0, abs=1e-12)
    # reduced_energy is reduced_integrals' h: one computation, exact
    assert reduced_energy(sc.body, y, "meridian") == float(reduced_integrals(sc.body, y)["h"])


def test_initial_conditions_round_trip(paper_body):
    y = initial_state(paper_body, "smooth", gamma=GAMMA0, omega=OMEGA0, free=FREE["smooth"])
    ic = InitialConditions.from_state(y)
    assert all(type(x) is float for x in ic.gamma + ic.omega)
    np.testing.assert_allclose(ic.state(paper_body, "smooth"), y, rtol=0, atol=1e-15)


def test_the_meridian_default_of_the_level_helpers_is_deprecated():
    """Issue 37, item 6: level_of_state / reduced_energy without a model assume the meridian
    model and say so; with the model's name they are the model's own (the same numbers)."""
    sc = load_scenario(EXAMPLES / "fig5.toml")
    for helper in (level_of_state, reduced_energy):
        with pytest.warns(DeprecationWarning, match="model='meridian'"):
            old = helper(sc.body, sc.y0)
        new = helper(sc.body, sc.y0, "meridian")
        if helper is level_of_state:
            old, new = (old.M3, old.C1, old.C2), (new.M3, new.C1, new.C2)
        assert old == new  # the same computation: exact
