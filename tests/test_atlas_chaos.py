"""The chaos atlas (rollingtop.atlas._chaos, issue 39 item 3): the oblique family over its
angle. Each cell against the chaos tools called directly on the same body, angle and state;
the phase-volume rate against Kozlov's criterion at the family's ends; the spec refused in one
line; a chunk of the other kind is foreign; the command end to end in a real process."""

import json
import subprocess
import sys

import numpy as np
import pytest

from rollingtop import SphericalTop, initial_state
from rollingtop.atlas import AtlasError, atlas_spec_from_dict, classify_in_process
from rollingtop.atlas._chaos import CHAOS_FIELDS, chaos_cells
from rollingtop.atlas._store import _chunk_fits
from rollingtop.chaos.divergence import phase_volume
from rollingtop.chaos.level import level_states
from rollingtop.chaos.lyapunov import chaos_indicators
from rollingtop.contact.oblique import oblique

#: One pytest-xdist worker runs this module (its fixture classifies the two angles once).
pytestmark = pytest.mark.xdist_group("atlas-chaos")

BODY = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}
STATE = {"gamma": [0.0, 0.6, 0.8], "omega": [0.7, -0.3, 2.0], "v_slip": 0.25}
T_END = 40.0


def chaos_dict(axes, **contact):
    return {
        "body": dict(BODY),
        "contact": {"model": "oblique", **contact},
        "initial": dict(STATE),
        "chaos": {"t_end": T_END, "seeds": 2},
        "axes": axes,
    }


@pytest.fixture(scope="module")
def two_angles():
    spec = atlas_spec_from_dict(chaos_dict({"angle": [0.0, 0.8]}))
    return spec, classify_in_process(spec)


def test_a_cell_is_what_the_tools_give_for_its_angle(two_angles):
    """The cell at angle 0.8: MEGNO and Lyapunov of the seeds that finish, the seeds that
    reach the vertical, the volume rate (all exactly the tools' numbers)."""
    spec, ds = two_angles
    assert spec.kind == "chaos" and spec.models == ("oblique",)
    assert ds.attrs["kind"] == "chaos" and list(ds["megno"].dims) == ["angle"]
    body = SphericalTop(**BODY)
    model = oblique(0.8)
    f = spec.fixed  # the state as the spec keeps it (the scenario's, normalised)
    y0 = initial_state(
        body,
        model,
        gamma=[f["gamma1"], f["gamma2"], f["gamma3"]],
        omega=[f["omega1"], f["omega2"], f["omega3"]],
        free={"v_slip": STATE["v_slip"]},
    )
    megno, lyap, vertical, first = [], [], 0, False
    for k, y in enumerate(level_states(body, model, y0, 2, seed=0)):
        try:
            s = chaos_indicators(body, model, y, t_end=T_END, samples=100, max_steps=200_000)
        except Exception as exc:
            assert "vertical" in str(exc) or "max_steps" in str(exc)
            vertical += 1
            continue
        first = first or k == 0
        megno.append(s.summary()["megno"])
        lyap.append(s.summary()["lyapunov"])
    cell = ds.sel(angle=0.8)
    assert int(cell["status"]) == 0
    assert int(cell["n_vertical"]) == vertical and int(cell["n_finished"]) == len(megno)
    if megno:
        assert float(cell["megno"]) == pytest.approx(float(np.median(megno)), rel=1e-12)
        assert float(cell["lyapunov"]) == pytest.approx(max(lyap), rel=1e-12)
    assert int(cell["n_failed"]) == 0
    if first:  # the rate only along a motion that stays away from the vertical
        rate = phase_volume(body, model, y0, t_end=T_END, samples=2001, max_steps=200_000)
        assert float(cell["volume_rate"]) == pytest.approx(rate.mean[-1], rel=1e-12)
    else:
        assert np.isnan(float(cell["volume_rate"]))


def test_the_volume_rate_is_kozlovs_criterion_at_the_ends(two_angles):
    """At angle 0 (the paper's constraint, an invariant measure: the time average of the
    divergence is a total derivative over t_end, small) against angle 0.8 (no density of
    gamma3: verify --search), where phase volume drifts: |rate(0)| < 1/4 |rate(0.8)|."""
    _, ds = two_angles
    r0 = float(ds["volume_rate"].sel(angle=0.0))
    r1 = float(ds["volume_rate"].sel(angle=0.8))
    assert abs(r0) < 0.25 * abs(r1), (r0, r1)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"axes": {"angle": [0.1]}, "contact": {"model": "parallel"}}, "oblique model's"),
        ({"axes": {"C2": [0.0]}}, "has no reduction"),
        ({"chaos": {"t_end": -1.0}}, "chaos.t_end = -1 must be in"),
        ({"chaos": {"seeds": 0}}, "chaos.seeds = 0 must be in"),
        ({"chaos": {"t_end": 1.0, "foo": 2}}, "unknown keys foo"),
        ({"chaos": 3}, "must be a table"),
        ({"initial": None}, "needs an \\[initial\\] table"),
        ({"level": {"M3": 1.0}}, "leave out \\[level\\]"),
        ({"axes": {"angle": [0.1], "model": ["meridian"]}}, "leave out the model axis"),
    ],
)
def test_a_bad_chaos_spec_is_refused_in_one_line(change, message):
    data = chaos_dict({"angle": [0.1, 0.2]})
    for key, value in change.items():
        if value is None:
            del data[key]
        else:
            data[key] = value
    with pytest.raises(AtlasError, match=message):
        atlas_spec_from_dict(data)


def test_an_inadmissible_body_is_its_cells_status():
    spec = atlas_spec_from_dict(chaos_dict({"I3": [0.5, 0.7]}, angle=0.5))
    out = chaos_cells(spec.fixed, ("I3",), np.array([[0.7]]))
    assert int(out["status"][0]) == 1 and np.isnan(out["megno"][0])


def test_a_chunk_of_the_other_kind_is_foreign(two_angles):
    _, ds = two_angles
    part = {k: ds[k].values for k in CHAOS_FIELDS}
    assert _chunk_fits(part, 2, "chaos")
    assert not _chunk_fits(part, 2, "reduction")
    assert not _chunk_fits({**part, "megno": part["megno"].astype(np.int16)}, 2, "chaos")


@pytest.mark.slow
def test_the_command_writes_a_chaos_atlas(tmp_path):
    spec = tmp_path / "chaos.toml"
    spec.write_text(
        "[body]\n"
        + "".join(f"{k} = {v}\n" for k, v in BODY.items())
        + '[contact]\nmodel = "oblique"\n[initial]\n'
        + "gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nv_slip = 0.25\n"
        + f"[chaos]\nt_end = {T_END}\nseeds = 2\n[axes]\nangle = [0.0, 0.8]\n"
    )
    out = tmp_path / "c.nc"
    run = subprocess.run(
        [sys.executable, "-m", "rollingtop", "atlas", str(spec), "-o", str(out), "--json"],
        capture_output=True,
        text=True,
        check=False,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    assert summary["cells"] == summary["classified"] == 2
    assert set(summary["counts"]) == {
        "n_finished",
        "n_vertical",
        "n_failed",
        "n_periodic",
        "n_attracting",
    }
    assert set(summary["ranges"]) == {"megno", "lyapunov", "volume_rate"}
    assert out.exists()


def test_a_cell_drawn_into_the_vertical_is_counted_not_a_failure():
    """phi = 5 pi/6: the initial state's motion is drawn into the vertical and crawls there
    (tests/chaos/test_divergence.py): its volume rate is NaN, the seeds that reach the vertical
    are counted, and the cell is computed (status 0) in seconds, not minutes."""
    spec = atlas_spec_from_dict(chaos_dict({"angle": [5 * np.pi / 6]}))
    out = chaos_cells(spec.fixed, ("angle",), spec.cells())
    assert int(out["status"][0]) == 0
    assert np.isnan(out["volume_rate"][0])
    assert int(out["n_vertical"][0]) >= 1
    assert int(out["n_vertical"][0]) + int(out["n_finished"][0]) == 2
    assert int(out["n_failed"][0]) == 0
