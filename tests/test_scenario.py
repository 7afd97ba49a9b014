"""Scenario files: the documented format loads, every malformed input is refused clearly."""

import os

import numpy as np
import pytest

from rollingtop import (
    BodyError,
    ContactModelError,
    InitialStateError,
    RollingTopError,
    ScenarioError,
    load_scenario,
)
from rollingtop.contact import MODELS
from rollingtop.scenario import DEFAULTS

from .conftest import EXAMPLES, scenario_text


@pytest.mark.parametrize("name", ["paper", "smooth", "rough", "rubber"])
def test_examples_load(name):
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    assert sc.model.name == {"paper": "meridian"}.get(name, name)
    assert sc.integration.t_end == 50.0 and sc.integration.samples == 1001
    assert sc.body.a3 == 0.1 and sc.body.I2 == 0.3
    np.testing.assert_allclose(sc.y0[12:15], (0, 0.6, 0.8))


def write(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text)
    return path


def test_defaults(tmp_path):
    sc = load_scenario(write(tmp_path, scenario_text(contact=None, integration=None)))
    assert sc.model.name == "meridian"
    assert sc.integration.t_end == DEFAULTS["t_end"] and sc.integration.rtol == 1e-10
    assert sc.integration.resolved_atol == pytest.approx(1e-12)
    assert sc.with_overrides(rtol=1e-12).integration.resolved_atol == pytest.approx(1e-14)


def test_overrides(tmp_path):
    sc = load_scenario(write(tmp_path, scenario_text()))
    sc2 = sc.with_overrides(t_end=7.0, samples=None)
    assert sc2.integration.t_end == 7.0 and sc2.model.name == "meridian"
    assert sc2.integration.samples == sc.integration.samples
    # another model must accept the same initial conditions
    with pytest.raises(InitialStateError, match="v_tau is not a free velocity component of model"):
        sc.with_overrides(model="smooth")
    rough = load_scenario(write(tmp_path, scenario_text("rough"))).with_overrides(model="smooth")
    assert rough.model.name == "smooth"
    with pytest.raises(ScenarioError, match="unknown override speed"):
        sc.with_overrides(speed=3)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        (dict(extra="x = 1"), ScenarioError, r"unknown table \[extra\]"),
        (
            dict(body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3"),
            ScenarioError,
            r"\[body\] is missing I3",
        ),
        (
            dict(body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 1.1\nI1 = 0.3\nI3 = 0.5"),
            BodyError,
            r"a3 = 1.1 violates \|a3\| < R",
        ),
        (
            dict(body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\nJ = 2"),
            ScenarioError,
            "unknown key body.J",
        ),
        (dict(contact='model = "glue"'), ContactModelError, "unknown contact model 'glue'"),
        (
            dict(initial="gamma = [0.0, 0.6, 0.9]\nomega = [0.7, -0.3, 2.0]"),
            InitialStateError,
            "gamma .* is not a unit vector",
        ),
        (
            dict(
                body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI2 = 0.35\nI3 = 0.5",
                initial="gamma = [0.0, 0.0, 1.0]\nomega = [0.7, -0.3, 2.0]",
            ),
            InitialStateError,
            "symmetry axis is vertical .* not dynamically symmetric",
        ),
        (
            dict(initial="gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nspeed = 1"),
            ScenarioError,
            "unknown key initial.speed",
        ),
        (
            dict(
                initial="gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nv_horizontal = [1, 0]"
            ),
            ScenarioError,
            "unknown key initial.v_horizontal for model 'meridian'",
        ),
        (dict(initial="gamma = [0.0, 0.6, 0.8]"), ScenarioError, r"\[initial\] is missing omega"),
        (dict(integration="t_end = -1.0"), ScenarioError, "t_end = -1 must be > 0"),
        (dict(integration="rtol = 1.0"), ScenarioError, r"rtol = 1 must lie in \[1e-15, 0.1\]"),
        (dict(integration="atol = 0.0"), ScenarioError, "atol = 0 must be > 0"),
        (dict(integration="samples = 1"), ScenarioError, "samples = 1 must be >= 2"),
        (dict(integration="samples = 2.5"), ScenarioError, "samples = 2.5 must be an integer"),
        (dict(integration='t_end = "long"'), ScenarioError, "t_end = 'long' must be a number"),
        (
            dict(integration="t_end = 5.0\nmethod = 'rk4'"),
            ScenarioError,
            "unknown key integration.method",
        ),
    ],
)
def test_bad_scenarios(tmp_path, kwargs, error, message):
    path = write(tmp_path, scenario_text(**kwargs))
    with pytest.raises(error, match=message) as err:
        load_scenario(path)
    assert str(path) in str(err.value)  # the file is named


def test_invalid_toml_and_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match="invalid TOML"):
        load_scenario(write(tmp_path, "[body\nR = 1"))
    with pytest.raises(ScenarioError, match="cannot read scenario .*No such file"):
        load_scenario(tmp_path / "absent.toml")
    assert issubclass(ScenarioError, RollingTopError)


def test_smooth_and_full_velocity(tmp_path):
    sc = load_scenario(write(tmp_path, scenario_text("smooth")))
    assert sc.y0[0:3] @ sc.y0[6:9] == pytest.approx(0.3)
    v = ", ".join(repr(float(x)) for x in sc.y0[0:3])
    text = scenario_text(
        "smooth", initial=f"gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nv = [{v}]"
    )
    np.testing.assert_allclose(load_scenario(write(tmp_path, text)).y0, sc.y0, atol=1e-15)


def test_level_table_builds_the_initial_state():
    """examples/fig5.toml has no [initial]: the state starts on its level, at the lowest turning
    point of the first orbit (w_tau = 0 there)."""
    from rollingtop.reduction import reduce_state, reduced_integrals

    sc = load_scenario(EXAMPLES / "fig5.toml")
    ints = reduced_integrals(sc.body, sc.y0)
    for name, value in (("M3", 1.0), ("C1", 0.5), ("C2", -2.0), ("h", 4.0)):
        assert float(ints[name]) == pytest.approx(value, abs=1e-12)
    red = reduce_state(sc.y0)
    assert float(red["w_tau"]) == pytest.approx(0.0, abs=1e-7)
    assert float(red["gamma3"]) == pytest.approx(-0.656411968, abs=1e-9)
    assert sc.level_h() == 4.0 and sc.level_set().C2 == -2.0


BIG = "9" * 400


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        (dict(integration="samples = 1e12"), ScenarioError,
         r"samples = 1000000000000 needs about 931.3 TiB of memory, more than the .* a run may"),
        (dict(integration=f"max_steps = {2**63}"), ScenarioError,
         r"max_steps = 9223372036854775808 must lie in \[1, 2\*\*62\]"),
        (dict(integration="t_end = 5e-324"), ScenarioError,
         "t_end = 4.94066e-324 is too small for 1001 samples"),
        (dict(integration=f"t_end = {BIG}"), ScenarioError,
         "t_end = <integer of 400 digits> is too large"),
        (dict(body=f"R = {BIG}\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5"), ScenarioError,
         "body.R = <integer of 400 digits> is too large"),
        (dict(initial=f"gamma = [0.0, 0.6, 0.8]\nomega = [{BIG}, 0, 0]"), ScenarioError,
         r"initial.omega\[0\] = <integer of 400 digits> is too large"),
        (dict(initial='gamma = ["0", 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]'), ScenarioError,
         r"initial.gamma\[0\] = '0' must be a number"),
        (dict(initial="gamma = [0.0, 0.6, 0.8]\nomega = [true, 0, 0]"), ScenarioError,
         r"initial.omega\[0\] = True must be a number"),
        (dict(initial="gamma = [0.0, 0.6, 0.8]\nomega = {x = 1}"), ScenarioError,
         r"initial.omega = \{'x': 1\} must be a list of 3 numbers"),
        (dict(initial="gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nv_tau = [1]"),
         ScenarioError, r"initial.v_tau = \[1\] must be a number"),
        (dict(contact=f'model = "{"x" * 100_000}"'), ContactModelError,
         rf"unknown contact model 'x{{77}}…' \(known: {', '.join(MODELS)}\)$"),
        (dict(contact="model = 3"), ContactModelError, "unknown contact model 3"),
        (dict(body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n" + "k" * 5000
                   + " = 1"),
         ScenarioError, r"unknown key body.k{79}… \(allowed"),
        (dict(body='R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"a\\nb" = 1'),
         ScenarioError, r"unknown key body.'a\\nb' \(allowed"),
        (dict(level="M3 = 1.0\nC1 = 1.0\nC2 = -0.3\nbranch = 2"), ScenarioError,
         "level.branch = 2 must be"),
    ],
)  # fmt: skip
def test_hostile_values_refused_in_one_short_line(tmp_path, kwargs, error, message):
    path = write(tmp_path, scenario_text(**kwargs))
    with pytest.raises(error, match=message) as err:
        load_scenario(path)
    text = str(err.value)
    assert str(path) in text and "\n" not in text and len(text) < 400


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"\xef\xbb\xbf" + scenario_text().encode(), "starts with a UTF-8 byte-order mark"),
        (b"[a]\nx = " + b"[" * 100_000 + b"]" * 100_000, "it is 195.3 KiB|nested too deeply"),
        (b"[a]\nx = " + b"[" * 5000 + b"]" * 5000, "arrays or tables nested too deeply"),
        (b"x" * (1 << 20) + b"x", r"it is 1 MiB, more than the 1 MiB an input file may have"),
        (b"\x80\x81", "not UTF-8 text"),
        (b"[integration]\nsamples = " + b"9" * 5000, "an integer with too many digits"),
    ],
    ids=["bom", "deep-big", "deep", "large", "binary", "5000-digits"],
)
def test_hostile_files_refused(tmp_path, content, message):
    path = tmp_path / "s.toml"
    path.write_bytes(content)
    with pytest.raises(ScenarioError, match=message):
        load_scenario(path)


def test_special_files_refused_without_reading(tmp_path):
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)  # no writer: opening or reading it normally would block forever
    with pytest.raises(ScenarioError, match="not a regular file .it is a FIFO."):
        load_scenario(fifo)
    with pytest.raises(ScenarioError, match="not a regular file .it is a character device."):
        load_scenario("/dev/zero")


def test_samples_bounded_by_memory(monkeypatch, tmp_path):
    from rollingtop import scenario as module

    sc = load_scenario(write(tmp_path, scenario_text()))
    limit = module.memory_limit()
    assert 0 < limit <= 8 << 30
    fits = limit // module.BYTES_PER_SAMPLE
    assert sc.with_overrides(samples=fits).integration.samples == fits
    with pytest.raises(ScenarioError, match="needs about .* of memory"):
        sc.with_overrides(samples=fits + 1)


def test_documented_model_lists_name_every_registered_model():
    """A ``model = ...  # a | b | ...`` comment in an example or the scenario guide lists every
    registered model, in the registry's order (paper.toml once listed three of six)."""
    listed = {}
    for path in [*EXAMPLES.glob("*.toml"), EXAMPLES.parent / "docs" / "guide" / "scenarios.md"]:
        for line in path.read_text().splitlines():
            if line.startswith("model =") and "|" in line:
                names = line.split("#", 1)[1].split("(")[0]
                listed[path.name] = [n.strip() for n in names.split("|")]
    assert set(listed) == {"paper.toml", "scenarios.md"}
    for names in listed.values():
        assert names == list(MODELS)
