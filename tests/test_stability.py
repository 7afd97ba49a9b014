"""Vertical spins (rollingtop.stability) and the steady rollings' linearisation.

Each threshold is checked three ways: the linearisation's eigenvalues (bisection) against the
model's closed form, the meridian closed form against ``U''`` at the pole of the pole level
computed with mpmath on docs/model.md's plain ``U`` (tests/reduction/plain.py), and simulation of
the full equations on both sides of it.
"""

import json
import math
import re

import mpmath as mp
import numpy as np
import pytest

from rollingtop import InitialConditions, IntegrationOptions, SphericalTop, simulate
from rollingtop.contact import MODELS as REGISTRY
from rollingtop.reduction import LevelSet, steady_motions
from rollingtop.stability import (
    StabilityError,
    vertical_spin_eigenvalues,
    vertical_spins,
)

from .conftest import EXAMPLES, PAPER_BODY, scenario_text
from .reduction import plain
from .test_cli import run_cli

#: Every registered model: a new one is held to its vertical-spin threshold by simulation.
MODELS = tuple(REGISTRY)
#: The models that allow a spin about the vertical axis (rubber rolling forbids it:
#: ``ContactModel.has_vertical_spin``); every other one is held to its refusal.
SPINNING = tuple(name for name, m in REGISTRY.items() if m.has_vertical_spin)
NOT_SPINNING = tuple(name for name, m in REGISTRY.items() if not m.has_vertical_spin)
PAPER = SphericalTop(**PAPER_BODY)
BODIES = [
    PAPER,
    SphericalTop(R=1.0, m=2.0, g=9.81, a3=-0.3, I1=0.5, I3=0.7),
    SphericalTop(R=0.5, m=1.5, g=1.0, a3=0.2, I1=0.4, I3=0.3),
]
#: Bisection on eigenvalues from central differences (step 1e-6): the threshold to ~1e-9.
THRESHOLD_RTOL = 1e-8


def _analysed(model):
    """Whether the model's vertical spin has a linearisation (the parallel model refuses: its
    constraint direction is undefined at the vertical and the state there does not determine
    the motion)."""
    try:
        vertical_spin_eigenvalues(PAPER, model, 1.0)
    except StabilityError:
        return False
    return True


#: The spinning models whose vertical spin has a linearisation.
ANALYSED = [m for m in SPINNING if _analysed(m)]


@pytest.mark.parametrize("model", ANALYSED)
@pytest.mark.parametrize("body", range(len(BODIES)))
def test_threshold_from_eigenvalues_equals_closed_form(model, body):
    b = BODIES[body]
    spins = vertical_spins(b, model)
    assert [v.pole for v in spins] == ["south", "north"]
    for v in spins:
        assert v.com_above_centre == ((1 if v.pole == "south" else -1) * b.a3 > 0)
        if not v.com_above_centre:
            assert v.omega3_critical == 0.0
            assert v.omega3_closed_form in (0.0, None)
        else:
            assert v.omega3_critical > 0
            if v.omega3_closed_form is not None:
                assert v.omega3_critical == pytest.approx(v.omega3_closed_form,
                                                          rel=THRESHOLD_RTOL)  # fmt: skip


def test_smooth_plane_is_lagranges_top_about_the_centre_of_mass():
    """I3^2 w3^2 = 4 I1 m g a3 (the sleeping-top condition with l = a3)."""
    (south, _) = vertical_spins(PAPER, "smooth")
    expected = 2 * math.sqrt(PAPER.I1 * PAPER.m * PAPER.g * PAPER.a3) / PAPER.I3
    assert south.omega3_critical == pytest.approx(expected, rel=THRESHOLD_RTOL)


@pytest.mark.parametrize("body", [0, 2])
def test_meridian_threshold_is_where_u_pole_curvature_vanishes(body):
    """On the pole level (C1 = M3, C2 = 0) U(theta) is smooth through theta = 0; the critical
    M3 is the root of U''(0) (mpmath on the plain U, 30 digits)."""
    b = BODIES[body]
    (south, _) = vertical_spins(b, "meridian")

    def curvature(M3):
        return mp.diff(lambda t: plain.U(b, M3, M3, 0, mp.cos(t)), mp.mpf("1e-3"), 2)

    with mp.workdps(30):
        # U'' at theta = 1e-3 differs from U''(0) by O(1e-6): refine from the closed form
        M3 = mp.findroot(curvature, b.I3 * south.omega3_closed_form)
    assert south.omega3_closed_form == pytest.approx(float(M3) / b.I3, rel=1e-5)


def _max_tilt(body, model, omega3, pole=1, t_end=80.0, tilt=1e-3):
    gamma = (0.0, math.sin(tilt), pole * math.cos(tilt))
    ic = InitialConditions(gamma=gamma, omega=(0.0, 0.0, omega3))
    tr = simulate(body, model, ic, IntegrationOptions(t_end=t_end, rtol=1e-10, samples=801))
    return float(np.max(np.hypot(tr.y[:, 12], tr.y[:, 13])))


def test_a_model_without_a_linearisation_refuses_in_one_line():
    for model in set(SPINNING) - set(ANALYSED):
        with pytest.raises(StabilityError, match="undefined at the vertical|not linearised"):
            vertical_spins(PAPER, model)
    assert {"meridian", "smooth", "rough"} <= set(ANALYSED)


@pytest.mark.parametrize("model", ANALYSED)
def test_simulation_falls_below_and_sleeps_above_the_threshold(model):
    """From a tilt of 1e-3: at 0.7 of the critical spin the body falls over (tilt > 0.3 within
    80 time units), at 1.3 it stays within 0.02 of the vertical."""
    (south, _) = vertical_spins(PAPER, model)
    assert _max_tilt(PAPER, model, 0.7 * south.omega3_critical) > 0.3
    assert _max_tilt(PAPER, model, 1.3 * south.omega3_critical) < 0.02


@pytest.mark.parametrize("model", ANALYSED)
def test_north_pole_threshold_by_simulation(model):
    """The mirrored body (a3 < 0) spinning on its north pole behaves the same way."""
    from dataclasses import replace

    b = replace(PAPER, a3=-PAPER.a3)
    (_, north) = vertical_spins(b, model)
    assert north.com_above_centre
    assert north.omega3_critical == pytest.approx(vertical_spins(PAPER, model)[0].omega3_critical,
                                                  rel=THRESHOLD_RTOL)  # fmt: skip
    assert _max_tilt(b, model, 0.7 * north.omega3_critical, pole=-1) > 0.3
    assert _max_tilt(b, model, 1.3 * north.omega3_critical, pole=-1) < 0.02


def test_com_below_centre_spins_stably_at_any_rate():
    """At rest on a pole (omega3 = 0, an equilibrium of every model, rubber rolling's too):
    stable with the centre of mass below the sphere's centre, unstable above it (every model
    with a linearisation there)."""
    for model in [*ANALYSED, *NOT_SPINNING]:
        ev = vertical_spin_eigenvalues(PAPER, model, 0.0, "north")
        assert np.max(np.abs(ev.real)) < 1e-6 * max(1.0, np.max(np.abs(ev)))
        ev = vertical_spin_eigenvalues(PAPER, model, 0.0, "south")
        assert np.max(ev.real) > 1e-3 * np.max(np.abs(ev)), model


@pytest.mark.parametrize("model", NOT_SPINNING or [None])
def test_a_model_without_vertical_spin_refuses_it(model, capsys, tmp_path):
    """A model that forbids the spin about the vertical axis (its spin constraint is ``w3 = 0``
    there) has no threshold to compute: one clear StabilityError naming the constraint, in
    Python and on the command line; and indeed no state with the axis vertical spins about it."""
    if model is None:
        pytest.skip("every registered model allows the vertical spin")
    from rollingtop import InitialStateError, initial_state

    spin = ", ".join(REGISTRY[model].spin_directions(np.array([0.0, 0.0, 1.0])))
    with pytest.raises(StabilityError, match=re.escape(f"no vertical spin: its constraint {spin}")):
        vertical_spins(PAPER, model)
    with pytest.raises(StabilityError, match="no vertical spin"):
        vertical_spin_eigenvalues(PAPER, model, 1.0, "south")
    with pytest.raises(InitialStateError, match="omega"):
        initial_state(PAPER, model, gamma=(0.0, 0.0, 1.0), omega=(0.0, 0.0, 1.0))
    path = tmp_path / "s.toml"
    rolling_off_a_pole = "gamma = [0.0, 0.0, 1.0]\nomega = [1.0, 0.0, 0.0]"
    path.write_text(scenario_text(model, initial=rolling_off_a_pole))
    code, out, err = run_cli(capsys, "stability", str(path))
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "no vertical spin" in err


def test_non_symmetric_body_uses_the_generic_linearisation():
    b = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I2=0.35, I3=0.5)
    (south, _) = vertical_spins(b, "smooth")
    assert south.omega3_closed_form is None and south.omega3_critical > 0
    with pytest.raises(StabilityError, match="symmetric"):
        vertical_spins(b, "meridian")


def test_steady_rolling_eigenvalues_match_u_curvature():
    """The full linearisation at each steady rolling of Fig. 5's level: two zero eigenvalues
    (the integrals) and +-sqrt(-U''/rho)."""
    level = LevelSet(PAPER, 1.0, 0.5, -2.0)
    motions = steady_motions(level)
    assert [m.type for m in motions] == ["center", "saddle", "center"]
    for m in motions:
        ev = np.array([complex(*z) for z in m.eigenvalues])
        lam = math.sqrt(abs(m.U2_theta) / PAPER.rho(m.gamma3))
        nonzero = sorted(ev, key=abs)[2:]
        assert np.allclose(sorted(np.abs(ev))[:2], 0.0, atol=1e-7)
        for z in nonzero:
            assert abs(z) == pytest.approx(lam, rel=1e-7)
            # a centre oscillates (imaginary pair), a saddle has a real pair
            assert abs(z.real if m.type == "center" else z.imag) < 1e-7 * lam
        assert m.linearly_stable == (m.type == "center")


def test_cli_stability_json(capsys):
    code, out, err = run_cli(capsys, "stability", str(EXAMPLES / "paper.toml"), "--json",
                             "--omega3", "0.2")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert summary["model"] == "meridian"
    assert [v["pole"] for v in summary["vertical_spin"]] == ["south", "north"]
    assert set(summary["vertical_spin"][0]) >= {"pole", "com_above_centre", "omega3_critical"}
    assert summary["vertical_spin"][1]["omega3_critical"] == 0.0
    assert len(summary["eigenvalues"]["south"]) == 4


def test_cli_stability_other_model_and_every_model(capsys):
    """--model NAME answers for that model; --model all for every model that takes the body
    (rollingtop.contact.models_for), a model without a vertical-spin answer with its reason."""
    from rollingtop.contact import models_for

    paper = str(EXAMPLES / "paper.toml")
    code, out, err = run_cli(capsys, "stability", paper, "--model", "rough", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["model"] == "rough"
    assert summary["vertical_spin"][0]["omega3_critical"] == pytest.approx(0.48573398, abs=1e-8)
    code, out, err = run_cli(capsys, "stability", paper, "--model", "all", "--json")
    assert code == 0, err
    every = json.loads(out)["models"]
    assert [s["model"] for s in every] == [m.name for m in models_for(PAPER)]
    assert [s["model"] for s in every] == ["meridian", "smooth", "rough", "parallel", "rubber",
                                           "oblique"]  # fmt: skip
    south = {s["model"]: s["vertical_spin"][0]["omega3_critical"]
             for s in every if "vertical_spin" in s}  # fmt: skip
    # the README's rates: 0.31 (meridian), 0.69 (smooth), 0.49 (rough)
    assert south == pytest.approx({"meridian": 0.30881101, "smooth": 0.69282032,
                                   "rough": 0.48573398}, abs=1e-8)  # fmt: skip
    refused = {s["model"]: s["refused"] for s in every if "refused" in s}
    assert set(refused) == {"parallel", "rubber", "oblique"}
    assert "has no vertical spin" in refused["rubber"]
    code, out, err = run_cli(capsys, "stability", paper, "--model", "all")
    assert code == 0 and err == ""
    rows = [line for line in out.splitlines() if "south" in line and "│" in line]
    assert [row.split("│")[1].strip() for row in rows] == ["meridian", "smooth", "rough"]
    assert "rubber: model 'rubber' has no vertical spin" in out
    code, out, err = run_cli(capsys, "stability", paper, "--model", "frob")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "unknown contact model 'frob'" in err and "or all" in err


def test_cli_stability_errors(capsys, tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(scenario_text(body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\n"
                                       "I2 = 0.35\nI3 = 0.5"))  # fmt: skip
    code, out, err = run_cli(capsys, "stability", str(path))
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "symmetric" in err
    code, out, err = run_cli(capsys, "stability", str(EXAMPLES / "paper.toml"), "--omega3", "nan")
    assert code == 2 and len(err.strip().splitlines()) == 1


def test_readme_states_the_computed_thresholds():
    """The README's sentence on vertical spins quotes these rates (rounded to 2 decimals)."""
    from .conftest import ROOT

    text = " ".join((ROOT / "README.md").read_text().split())
    rates = {
        m: vertical_spins(PAPER, m)[0].omega3_critical for m in ("meridian", "rough", "smooth")
    }
    expected = (f"{rates['meridian']:.2f} under the paper's constraint, {rates['rough']:.2f} "
                f"rolling without slipping, {rates['smooth']:.2f} on a smooth plane")  # fmt: skip
    assert expected in text


def test_threshold_does_not_depend_on_the_units():
    """g = 1e-10: the eigenvalues are tiny, the threshold still matches the closed form."""
    from dataclasses import replace

    b = replace(PAPER, g=1e-10)
    for model in ("smooth", "rough", "meridian"):
        (south, _) = vertical_spins(b, model)
        assert south.omega3_critical == pytest.approx(south.omega3_closed_form, rel=1e-6)
