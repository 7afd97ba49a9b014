"""Rotation numbers (rollingtop.reduction.rotation) against independent sources: mpmath
quadrature of docs/model.md's plain formulas, the small-oscillation and separatrix limits, and the
full equations of motion for the classes of motion (a closed path closes, a drifting one
drifts)."""

import json
import math

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.reduction import LevelSet, orbits, state_from_level, steady_motions
from rollingtop.reduction import rotation as rot

from ..conftest import EXAMPLES, PAPER_BODY
from ..test_cli import run_cli
from . import plain

PAPER = SphericalTop(**PAPER_BODY)
FIG5 = LevelSet(PAPER, 1.0, 0.5, -2.0)
#: The quadrature of psi' over a period (graded Gauss) against mpmath's tanh-sinh: 1e-10.
N_TOL = 1e-10


def n_mpmath(b, M3, C1, C2, h, g_lo, g_hi):
    """Delta psi / 2 pi = (2 / 2 pi) int psi'(gamma3) dgamma3 / |gamma3'| with
    psi' = -w_n / s = -(M3 gamma3 - C1) / (I1 s^2) (docs/model.md)."""

    def f(g):
        s2 = 1 - g**2
        psi_dot = -(M3 * g - C1) / (b.I1 * s2)
        return psi_dot / mp.sqrt(2 * s2 * (h - plain.U(b, M3, C1, C2, g)) / plain.rho(b, g))

    return 2 * mp.quad(f, [g_lo, g_hi]) / (2 * mp.pi)


@pytest.mark.parametrize("h", [3.3, 4.0, 7.0])
def test_rotation_number_matches_mpmath(h):
    with mp.workdps(25):
        for o in orbits(FIG5, h):
            n, err = rot.rotation_number(FIG5, h, o)
            ends = plain.turning_points(PAPER, 1.0, 0.5, -2.0, h, [o.gamma3_min, o.gamma3_max])
            ref = n_mpmath(PAPER, 1.0, 0.5, -2.0, h, *sorted(ends))
            assert n == pytest.approx(float(ref), abs=N_TOL)
            assert err < 1e-8


def test_rotation_number_tends_to_precession_over_frequency_at_a_centre():
    for m in steady_motions(FIG5):
        if m.type != "center":
            continue
        limit = rot.centre_rotation_number(m)
        h = m.U + 1e-9 * abs(m.U)
        (o,) = [o for o in orbits(FIG5, h) if o.gamma3_min <= m.gamma3 <= o.gamma3_max]
        # N(h) - N(centre) = O(h - U_c): 1e-9 relative here
        assert rot.rotation_number(FIG5, h, o)[0] == pytest.approx(limit, abs=1e-7)


def test_rotation_number_diverges_logarithmically_at_the_separatrix():
    """dN / d ln|h - h_s| = -k psi'_s / (2 pi lambda): k = 1 for a well orbit, which passes the
    saddle once a period, k = 2 for the orbit over both wells."""
    (s,) = [m for m in steady_motions(FIG5) if m.type == "saddle"]
    slope = -s.precession_rate / (2 * math.pi * s.growth_rate)

    def ns(h):
        return [rot.rotation_number(FIG5, h, o)[0] for o in orbits(FIG5, h) if o.kind == "periodic"]

    d1, d2 = 1e-6, 1e-8
    below1, below2 = ns(s.U - d1), ns(s.U - d2)
    for a, b in zip(below1, below2, strict=True):
        assert (a - b) / math.log(d1 / d2) == pytest.approx(slope, rel=0.02)
    (above1,), (above2,) = ns(s.U + d1), ns(s.U + d2)
    assert (above1 - above2) / math.log(d1 / d2) == pytest.approx(2 * slope, rel=0.02)


def test_classify_rotation():
    assert rot.classify_rotation(0.0) == {"class": "drifting", "p": 0, "q": 1}
    assert rot.classify_rotation(-2.0)["class"] == "drifting"
    assert rot.classify_rotation(1 / 11) == {"class": "closed", "p": 1, "q": 11}
    assert rot.classify_rotation(0.0932)["class"] == "quasi-periodic"
    assert rot.classify_rotation(1e-6)["class"] == "quasi-periodic"


@pytest.fixture(scope="module")
def small_map():
    rmap = rot.rotation_map(PAPER, 1.0, 0.5, C2_range=(-2.2, -0.3), h_range=(0.0, 10.0),
                            resolution=(15, 15))  # fmt: skip
    return rmap, rot.class_examples(PAPER, rmap)


def test_resonance_points_have_integer_rotation_numbers(small_map):
    rmap, _ = small_map
    assert rmap.resonances
    assert any(r["q"] == 1 for r in rmap.resonances)
    for r in rmap.resonances[:8]:
        level = LevelSet(PAPER, 1.0, 0.5, r["C2"])
        n = rot.rotation_numbers(level, r["h"])[r["orbit"]]
        assert n == pytest.approx(r["p"] / r["q"], abs=1e-9)
        # N is the fraction p/q itself, correctly rounded either way: exact
        assert r["N"] == r["p"] / r["q"] and r["q"] <= rot.CURVE_DENOMINATOR


def _full_run(example, periods, samples):
    from rollingtop import InitialConditions, IntegrationOptions, simulate

    level = LevelSet(PAPER, 1.0, 0.5, example["C2"])
    o = [o for o in orbits(level, example["h"]) if o.kind == "periodic"][example["orbit"]]
    y0 = state_from_level(level, example["h"], math.cos(o.start_theta))
    ic = InitialConditions(gamma=y0[12:15], omega=y0[3:6], alpha=y0[6:9], v=y0[0:3])
    opts = IntegrationOptions(t_end=periods * o.period, rtol=1e-12, atol=1e-14, samples=samples)
    return simulate(PAPER, "meridian", ic, opts)


def test_closed_class_closes_in_the_full_equations(small_map):
    """N = p/q: after q periods the centre of mass is back where it started (the full
    simulation, not the reduction), while after fewer periods it is not."""
    _, examples = small_map
    ex = examples["closed"]
    q = ex["q"]
    tr = _full_run(ex, q, q + 1)  # samples at whole periods
    pos = tr.y[:, 15:17]
    size = np.max(np.abs(pos - pos[0]))
    assert np.linalg.norm(pos[-1] - pos[0]) < 1e-6 * size
    assert np.min(np.linalg.norm(pos[1:-1] - pos[0], axis=1)) > 1e-2 * size


def test_drifting_class_drifts_in_the_full_equations(small_map):
    """N an integer: the once-per-period positions advance by the same step."""
    _, examples = small_map
    tr = _full_run(examples["drifting"], 4, 5)
    steps = np.diff(tr.y[:, 15:17], axis=0)
    assert np.linalg.norm(steps[0]) > 0.1
    np.testing.assert_allclose(steps, np.repeat(steps[:1], 4, axis=0), atol=1e-5)


def test_cli_rotation_json(capsys):
    code, out, err = run_cli(capsys, "rotation", str(EXAMPLES / "fig5.toml"), "--json",
                             "--resolution", "9")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert {"N_range", "resonances", "classes", "centres"} <= set(summary)
    assert len(summary["centres"]) == 2


def test_cli_rotation_bad_resolution(capsys):
    code, out, err = run_cli(capsys, "rotation", str(EXAMPLES / "fig5.toml"), "--resolution", "1")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1


def test_cli_rotation_empty_window_is_one_line(capsys):
    code, out, err = run_cli(capsys, "rotation", str(EXAMPLES / "fig5.toml"), "--h-range=-100,-99",
                             "--resolution", "3")  # fmt: skip
    assert code == 2 and out == "" and "no periodic orbit" in err
    assert len(err.strip().splitlines()) == 1


def test_rotation_map_on_a_pole_level():
    """C1 = M3: orbits above the pole's energy pass through the pole; N is defined there too and
    the map holds what rotation_numbers gives (the same computation: to the last bit)."""
    rmap = rot.rotation_map(PAPER, 1.0, 1.0, C2_range=(-0.5, 0.5), h_range=(0.2, 1.5),
                            resolution=(5, 5))  # fmt: skip
    n0 = rmap.N[:, :, 0]
    assert np.isfinite(n0).sum() >= 10
    i, j = np.argwhere(np.isfinite(n0))[-1]
    level = LevelSet(PAPER, 1.0, 1.0, float(rmap.C2_grid[j]))
    assert rot.rotation_numbers(level, float(rmap.h_grid[i]))[0] == n0[i, j]
    assert any(o.pole_passage for o in orbits(level, float(rmap.h_grid[i])))
