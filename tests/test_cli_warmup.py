"""``rollingtop warmup``: compiles the chosen models' kernels, one process per model
(:func:`rollingtop._warmup.warmup`), then prints one line per model and the total, or one JSON
object."""

import json

import pytest

from rollingtop import _warmup
from rollingtop.contact import MODELS

from .test_cli import run_cli


def test_warmup_json_names_each_model_and_its_groups(capsys):
    """One model, in this process (already compiled by the suite: fast)."""
    code, out, err = run_cli(capsys, "warmup", "--model", "meridian", "--processes", "1", "--json")
    assert code == 0
    assert err.startswith("rollingtop: compiling the kernels of 1 model (meridian)")
    data = json.loads(out)
    assert set(data) == {"models", "total_s"}
    groups = data["models"]["meridian"]
    assert set(groups) == {*_warmup.GROUPS, "total_s"}
    assert all(s >= 0 for s in groups.values())
    assert groups["total_s"] == pytest.approx(sum(groups[g] for g in _warmup.GROUPS))


def test_warmup_prints_a_line_per_model_and_the_total(capsys, monkeypatch):
    told = []

    def warmup(models, processes=None, progress=None):
        out = {}
        for i, name in enumerate(models):
            out[name] = {"integrator": 10.0 + i, "ensemble": 2.5}
            progress(name, out[name])
            told.append((name, processes))
        return out

    monkeypatch.setattr(_warmup, "warmup", warmup)
    code, out, err = run_cli(capsys, "warmup", "--model", "smooth", "--model", "rough",
                             "--processes", "2")  # fmt: skip
    assert code == 0
    lines = out.splitlines()
    assert lines[:2] == ["smooth          12.50 s", "rough           13.50 s"]
    assert lines[2].startswith("total") and lines[2].endswith("s (wall)")
    assert told == [("smooth", 2), ("rough", 2)]


def test_warmup_defaults_to_every_model(capsys, monkeypatch):
    seen = []

    def warmup(models, processes=None, progress=None):
        seen.extend(models)
        return {}

    monkeypatch.setattr(_warmup, "warmup", warmup)
    code, _, err = run_cli(capsys, "warmup")
    assert code == 0 and seen == list(MODELS)
    assert f"the kernels of {len(MODELS)} models" in err


def test_warmup_refuses_an_unknown_model(capsys):
    code, out, err = run_cli(capsys, "warmup", "--model", "glue")
    assert code == 2 and out == ""
    assert "glue" in err and err.count("\n") == 1


def test_warmup_runs_packages_in_separate_processes():
    """Two models, three packages (the meridian model's variants have their own), two processes
    (spawned: each compiles or loads from the suite's cache); each model's seconds are its
    packages' sums, reported once per model."""
    told = []
    seconds = _warmup.warmup(["meridian", "rough"], processes=2,
                             progress=lambda name, s: told.append(name))  # fmt: skip
    assert list(seconds) == ["meridian", "rough"] and sorted(told) == ["meridian", "rough"]
    assert all(set(g) == set(_warmup.GROUPS) for g in seconds.values())
    packages = [g.package for g in _warmup._packages(["meridian", "rough"])]
    assert sorted(packages) == ["meridian", "meridian_variants", "rough"]
    # the longest first, by the seconds measured for each
    measured = [_warmup.PACKAGE_SECONDS[p] for p in packages]
    assert measured == sorted(measured, reverse=True)


def test_a_package_not_measured_is_handed_out_first(monkeypatch):
    """A package without measured seconds (a new model's) comes before every measured one: the
    longest first is the safe guess."""
    measured = {k: v for k, v in _warmup.PACKAGE_SECONDS.items() if k != "rough"}
    monkeypatch.setattr(_warmup, "PACKAGE_SECONDS", measured)
    packages = [g.package for g in _warmup._packages(["meridian", "rough"])]
    assert packages[0] == "rough" and sorted(packages[1:]) == ["meridian", "meridian_variants"]
