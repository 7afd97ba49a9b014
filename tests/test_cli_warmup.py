"""``rollingtop warmup``: compiles every kernel group once (:func:`rollingtop._warmup.warmup`),
then prints one line per group and the total, or one JSON object."""

import json

import pytest

from .test_cli import run_cli


def test_warmup_json_names_every_group(capsys):
    code, out, err = run_cli(capsys, "warmup", "--json")
    assert code == 0 and err == ""
    assert out.count("\n") == 1
    data = json.loads(out)
    assert set(data) == {"groups", "total_s"}
    assert data["groups"] and all(s >= 0 for s in data["groups"].values())
    assert data["total_s"] == pytest.approx(sum(data["groups"].values()))


def test_warmup_prints_a_line_per_group_and_the_total(capsys, monkeypatch):
    import rollingtop._warmup as module

    told = []

    def warmup(progress=None):
        for name in ("integrator", "ensemble"):
            if progress is not None:
                progress(name)
            told.append(name)
        return {"integrator": 12.5, "ensemble": 3.25}

    monkeypatch.setattr(module, "warmup", warmup)
    code, out, err = run_cli(capsys, "warmup")
    assert code == 0 and err == ""
    assert out.splitlines() == [
        "integrator     12.50 s",
        "ensemble        3.25 s",
        "total          15.75 s",
    ]
    assert told == ["integrator", "ensemble"]
