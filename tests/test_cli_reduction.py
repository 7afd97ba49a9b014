"""Command line for the reduction: equilibria, orbits, portrait (JSON contracts, errors)."""

import json
import math
import re

import pytest

from rollingtop.reduction import LevelSet, orbits, steady_motions

from .conftest import EXAMPLES, scenario_text
from .test_cli import run_cli

FIG5 = str(EXAMPLES / "fig5.toml")
#: The [level]'s energy, a window's end: O(1) values after a few roundings (relative).
ROUND_OFF = 1e-15


def test_equilibria_json(capsys, paper_body):
    code, out, err = run_cli(capsys, "equilibria", FIG5, "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    eq = data["equilibria"]
    assert [e["type"] for e in eq] == ["center", "saddle", "center"]
    assert [e["gamma3"] for e in eq] == sorted(e["gamma3"] for e in eq)
    expected = steady_motions(LevelSet(paper_body, 1.0, 0.5, -2.0))
    # the command runs steady_motions on the same level: the same numbers, exact is the claim
    for e, m in zip(eq, expected, strict=True):
        assert e["U"] == m.U and e["gamma3"] == m.gamma3
    assert data["level"] == {"M3": 1.0, "C1": 0.5, "C2": -2.0, "model": "meridian", "pole": None}


def test_orbits_json_uses_h_from_level_and_option(capsys, paper_body):
    code, out, _ = run_cli(capsys, "orbits", FIG5, "--json")
    data = json.loads(out)
    assert code == 0 and data["level"]["h"] == 4.0
    # h + M3^2/(2 I3) + m g R = 4 + 1 + 1
    assert data["level"]["energy"] == pytest.approx(6.0, rel=ROUND_OFF)
    assert len(data["orbits"]) == 2
    assert data["orbits"][0]["gamma3_min"] < data["orbits"][1]["gamma3_min"]
    code, out, _ = run_cli(capsys, "orbits", FIG5, "--h", "5.0", "--json")
    got = json.loads(out)["orbits"]
    ref = orbits(LevelSet(paper_body, 1.0, 0.5, -2.0), 5.0)
    # the command runs orbits on the same level: the same quadrature, exact is the claim
    assert [o["period"] for o in got] == [o.period for o in ref]


def test_orbits_from_initial_state(capsys):
    """Without [level], the level set and h are those of the initial state."""
    code, out, _ = run_cli(capsys, "orbits", str(EXAMPLES / "paper.toml"), "--json")
    data = json.loads(out)
    assert code == 0 and data["level"]["M3"] == pytest.approx(1.0)
    assert data["level"]["h"] == pytest.approx(0.4849)
    (o,) = data["orbits"]
    assert o["gamma3_min"] < 0.8 < o["gamma3_max"]  # the initial gamma3 lies on the orbit


@pytest.mark.parametrize("suffix", [".png", ".svg", ".pdf"])
def test_portrait_writes_each_format(capsys, tmp_path, suffix):
    out_file = tmp_path / f"fig5{suffix}"
    code, out, err = run_cli(
        capsys,
        "portrait",
        FIG5,
        "-o",
        str(out_file),
        "--h-levels",
        "3.4,4,5,5.935716542281,6.5",
        "--no-contact",
    )
    assert code == 0, err
    head = out_file.read_bytes()[:8]
    assert {
        ".png": head.startswith(b"\x89PNG"),
        ".svg": b"<?xml" in head,
        ".pdf": head.startswith(b"%PDF"),
    }[suffix]
    assert out_file.stat().st_size > 5000
    assert "saddle" in out and "center" in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["orbits", FIG5, "--h", "1.0"], "h is below the minimum of the effective potential"),
        (["equilibria", str(EXAMPLES / "parallel.toml")], "parallel model has no reduction"),
        (["rotation", str(EXAMPLES / "parallel.toml")], "parallel model has no reduction"),
        (
            ["rotation", str(EXAMPLES / "rough.toml"), "--c2-range", "0,1"],
            "the rough model's is --axis-range",
        ),
        (["bifurcation", FIG5, "--axis-range", "0,1"], "--axis-range: another reduced model's"),
        (["bifurcation", str(EXAMPLES / "parallel.toml")], "parallel model has no reduction"),
        (["portrait", FIG5, "-o", "x.gif"], "unknown output format '.gif'"),
        (["portrait", FIG5, "-o", "x.png", "--h-levels", "a,b"], "expected comma-separated"),
    ],
)
def test_reduction_errors(capsys, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *args)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and message in err
    assert list(tmp_path.iterdir()) == []


def test_level_table_errors(capsys, tmp_path):
    bad = [
        (
            scenario_text(initial=None, level="M3 = 1.0\nC1 = 0.5\nh = 1.0"),
            r"\[level\] is missing C2",
        ),
        (scenario_text(level="M3 = 1.0\nC1 = 0.5\nC2 = 0.0\nE = 3"), "unknown key level.E"),
        (scenario_text(level="M3 = 1.0\nC1 = 0.5\nC2 = 0.0\nbranch = 2"), "branch = 2"),
        (
            scenario_text(initial=None, level="M3 = 1.0\nC1 = 0.5\nC2 = -2.0\nh = 1.0"),
            "h is below the minimum",
        ),
    ]
    for text, message in bad:
        (tmp_path / "s.toml").write_text(text)
        code, _, err = run_cli(capsys, "simulate", str(tmp_path / "s.toml"))
        assert code == 2 and re.search(message, err), err
    (tmp_path / "s.toml").write_text(
        scenario_text(initial=None, level="M3 = 1.0\nC1 = 0.5\nC2 = -2.0")
    )
    code, _, err = run_cli(capsys, "simulate", str(tmp_path / "s.toml"))
    assert code == 2 and "no initial state" in err


@pytest.mark.parametrize("name", ["smooth", "rough"])
def test_orbits_json_of_the_other_reduced_models(capsys, name):
    """Issue 24: `orbits --json` on a scenario with only [initial] lists exactly one orbit
    through the initial gamma3, under the model's own level (its integrals by name); its
    numbers are held to the full system in tests/reduction/test_models.py."""
    from rollingtop.reduction import reduction_of
    from rollingtop.scenario import load_scenario

    path = str(EXAMPLES / f"{name}.toml")
    code, out, err = run_cli(capsys, "orbits", path, "--json")
    assert code == 0, err
    data = json.loads(out)
    sc = load_scenario(path)
    names = reduction_of(name).names
    assert data["level"]["model"] == name and set(names) <= set(data["level"])
    g3 = sc.require_state()[14]
    through = [o for o in data["orbits"] if o["gamma3_min"] <= g3 <= o["gamma3_max"]]
    assert len(through) == 1 and through[0]["kind"] == "periodic"
    assert {"gamma3_min", "gamma3_max", "period", "period_error", "delta_psi"} <= set(through[0])
    code, out, err = run_cli(capsys, "equilibria", path, "--json")
    assert code == 0 and all({"gamma3", "type", "U", "frequency"} <= set(e)
                             for e in json.loads(out)["equilibria"])  # fmt: skip


@pytest.mark.parametrize("name", ["smooth", "rough"])
def test_bifurcation_of_the_other_reduced_models(capsys, tmp_path, name):
    """`bifurcation` on a smooth or rough scenario: the critical values along the model's axis
    integral; each point is a critical point of that level's U (dU = 0, an independent check
    through the level's derivative) and the counts are the points per column."""
    from rollingtop.reduction import reduction_of
    from rollingtop.scenario import load_scenario

    path = str(EXAMPLES / f"{name}.toml")
    out_png = tmp_path / "b.png"
    code, out, err = run_cli(capsys, "bifurcation", path, "--json", "-o", str(out_png),
                             "--axis-range", "-1.5,1.5")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert data["model"] == name and out_png.stat().st_size > 10_000
    assert data["x"][0] == -1.5 and data["x"][-1] == 1.5
    sc = load_scenario(path)
    reduction = reduction_of(name)
    base = sc.level_set().values()
    points = data["points"]
    for x, count in zip(data["x"], data["count"], strict=True):
        mine = [p for p in points if p[0] == x]
        assert count == (len(mine) if count >= 0 else -1)
    for x, gamma3, U, _ in points[::40]:
        level = reduction.level(sc.body, {**base, data["axis"]: x})
        theta = math.acos(gamma3)
        assert abs(float(level.dU(theta))) < 1e-8 * max(1.0, abs(U))
        assert float(level.U(theta)) == pytest.approx(U, rel=1e-12, abs=1e-12)


def test_bifurcation_of_a_shell_rotor_level_without_its_axis(capsys, tmp_path):
    """The shell-rotor pair's axis is C2, as the paper's: a [level] without it is scanned around
    0 over twice the size of its other integrals (not refused), and the figure marks no level
    value; each point is a critical point of that C2's U, computed again here."""
    from rollingtop.reduction import ShellRotorLevel, reduction_of
    from rollingtop.scenario import load_scenario

    text = (EXAMPLES / "shell_rotor.toml").read_text()
    head = text[: text.index("\n[initial]") + 1]
    path = tmp_path / "pair.toml"
    path.write_text(head + "[level]\nM3 = 1.5\njellett = 0.4\n")
    code, out, err = run_cli(capsys, "bifurcation", str(path), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["model"] == "shell-rotor" and data["axis"] == "C2"
    assert data["fixed"] == {"M3": 1.5, "jellett": 0.4}
    # 2 * max(|M3|, |jellett|)
    assert data["x"][0] == pytest.approx(-3.0, rel=ROUND_OFF)
    assert data["x"][-1] == pytest.approx(3.0, rel=ROUND_OFF)
    body = load_scenario(str(path)).body
    assert reduction_of("shell-rotor").names == ("M3", "jellett", "C2")
    for x, gamma3, U, _ in data["points"][::60]:
        level = ShellRotorLevel(body, M3=1.5, C2=x, jellett=0.4)
        theta = math.acos(gamma3)
        assert abs(float(level.dU(theta))) < 1e-8 * max(1.0, abs(U))
        assert float(level.U(theta)) == pytest.approx(U, rel=1e-12, abs=1e-12)
    # equilibria needs the whole level: refused in one line naming C2
    code, out, err = run_cli(capsys, "equilibria", str(path))
    assert code == 2 and "missing C2" in err and len(err.strip().splitlines()) == 1
