"""Property-based fuzzing of the command line with valid and hostile inputs.

Scenario files (mutations of the examples' TOML: wrong types, huge, tiny and non-finite numbers,
missing keys, strings in vectors, nested tables, a BOM, big values), ``[level]`` tables, CSV
tables for ``ensemble --initial`` and hostile option values run through the real CLI
(``rollingtop.cli.main``, in-process; a few cases in a real process). For every run:

* the exit status is 0, 1 or 2, and no exception escapes (it would print a traceback);
* an error is exactly one ``rollingtop: error:`` line on stderr (only ``note:``/``warning:``
  lines besides it) and leaves the folder as it was;
* ``--json`` prints exactly one strict JSON object;
* a file written reopens with the data the run reported.

Budgets are fixed (``derandomize=True``) and runs are short (``t_end`` of a few hundredths).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from rollingtop import IntegrationOptions
from rollingtop.cli import main

from .conftest import EXAMPLES


def fuzz(examples: int) -> settings:
    """A fixed budget of ``examples``, the same examples on every run, no time limit each."""
    return settings(
        max_examples=examples,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )


# ---- running the CLI and checking the contract ------------------------------------------------


def invoke(args: list[str]) -> tuple[int, str, str]:
    """Run the CLI in-process; every Python warning is shown (a user's process shows the first
    of each place: the same lines or fewer)."""
    out, err = io.StringIO(), io.StringIO()
    with (
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
        warnings.catch_warnings(),
    ):
        warnings.resetwarnings()  # every warning shows, wherever it ran before (deterministic)
        warnings.simplefilter("always")
        warnings.simplefilter("ignore", DeprecationWarning)
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        try:
            main(args)
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return code, out.getvalue(), err.getvalue()


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def check_contract(code: int, out: str, err: str, *, as_json: bool = False) -> dict | None:
    event(f"exit {code}")  # pytest --hypothesis-show-statistics shows how the runs ended
    assert code in (0, 1, 2), (code, err)
    assert "Traceback" not in err and "Traceback" not in out
    lines = err.splitlines()
    for line in lines:
        assert re.match(r"rollingtop: (error|warning|note): ", line), err
        assert len(line) < 2000, line[:300]
    errors = [line for line in lines if line.startswith("rollingtop: error: ")]
    if code == 0:
        assert not errors, err
    elif code == 2:  # refused input: that one line, nothing else
        assert len(lines) == 1 and errors, err
    else:  # a run that failed may have warned before
        assert len(errors) == 1 and lines[-1] == errors[0], err
        assert out == "" or not as_json, out
    if as_json and code == 0:
        assert out.count("\n") == 1, out[:300]

        def strict(name):
            raise AssertionError(f"{name} in the JSON output")

        summary = json.loads(out, parse_constant=strict)
        assert isinstance(summary, dict)
        return summary
    return None


def check_trajectory_file(path: Path, summary: dict, samples: int | None) -> None:
    """The file reopens with the samples whose last one the JSON summary reported."""
    final = summary["final"]
    if path.suffix == ".nc":
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            assert float(ds["t"][-1]) == final["t"] == summary["t_end"]
            assert ds["gamma"].values[-1].tolist() == final["gamma"]
            assert ds["omega"].values[-1].tolist() == final["omega"]
            assert ds["position"].values[-1].tolist() == final["position"]
            assert json.loads(ds.attrs["summary_json"])["final"] == final
            assert samples is None or ds.sizes["t"] == samples
    else:
        with open(path, encoding="utf-8") as fh:
            header = next(line for line in fh if not line.startswith("#")).strip().split(",")
            table = np.loadtxt(fh, delimiter=",", ndmin=2)
        last = dict(zip(header, table[-1], strict=True))
        assert last["t"] == final["t"]
        assert [last[f"gamma{i}"] for i in (1, 2, 3)] == final["gamma"]
        assert [last["X"], last["Y"]] == final["position"]
        assert samples is None or table.shape[0] == samples


@contextlib.contextmanager
def workdir():
    folder = Path(tempfile.mkdtemp(prefix="rollingtop-fuzz-"))
    try:
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# ---- TOML text from Python values (including what TOML allows but we must refuse) -------------


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _string(k)


def _string(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(doc: dict) -> str:
    parts = []
    for table, values in doc.items():
        if not isinstance(values, dict):
            parts.append(f"{_key(table)} = {toml_value(values)}\n")
    for table, values in doc.items():
        if isinstance(values, dict):
            body = "".join(f"{_key(k)} = {toml_value(v)}\n" for k, v in values.items())
            parts.append(f"[{_key(table)}]\n{body}")
    return "\n".join(parts)


def base_document(name: str) -> dict:
    doc = tomllib.loads((EXAMPLES / f"{name}.toml").read_text())
    doc.setdefault("integration", {}).update(t_end=0.02, samples=5, max_steps=20_000)
    return doc


def test_toml_writer_round_trips():
    for name in ("paper", "smooth", "rough", "rubber", "pole", "fig5"):
        doc = base_document(name)
        assert tomllib.loads(toml_text(doc)) == doc


# ---- strategies ---------------------------------------------------------------------------------

EXAMPLE_NAMES = ("paper", "smooth", "rough", "rubber", "pole", "fig5")

hostile_numbers = st.one_of(
    st.sampled_from(
        [
            0,
            -1,
            1,
            2,
            -0.0,
            5e-324,
            1e-300,
            1e-16,
            1e16,
            1e300,
            1.7976931348623157e308,
            math.inf,
            -math.inf,
            math.nan,
            2**63,
            2**64,
            -(2**63),
            10**400,
            -(10**400),
            0.5,
            1e-12,
            1e5,
        ]
    ),  # fmt: skip
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(),
)
leaves = st.one_of(
    hostile_numbers,
    st.booleans(),
    st.text(max_size=20),
    st.sampled_from(["0", "1.0", "meridian", "smooth", "nan", "", "\n", "é"]),
    st.just("x" * 200_000),
)
hostile_values = st.recursive(
    leaves,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.dictionaries(st.text(max_size=5), inner, max_size=3),
    ),
    max_leaves=8,
)


def vector_like(n: int):
    """Lists of about ``n`` items, some hostile: strings, booleans, tables, huge numbers."""
    return st.lists(st.one_of(hostile_numbers, leaves, hostile_values), min_size=n - 1,
                    max_size=n + 1)  # fmt: skip


def nudge(draw, doc: dict) -> None:
    """A plausible change (mostly still a valid scenario): other initial conditions, body
    parameters scaled, other integration options, another contact model."""
    what = draw(st.sampled_from(["gamma", "omega", "body", "integration", "model", "free"]))
    if what == "gamma" and "initial" in doc:
        g = draw(st.lists(st.floats(-1, 1), min_size=3, max_size=3))
        norm = math.sqrt(sum(x * x for x in g))
        doc["initial"]["gamma"] = [x / norm for x in g] if norm > 0.1 else [0.0, 0.6, 0.8]
        doc["initial"].pop("alpha", None)
    elif what == "omega" and "initial" in doc:
        doc["initial"]["omega"] = draw(st.lists(st.floats(-4, 4), min_size=3, max_size=3))
    elif what == "body" and "body" in doc:
        key = draw(st.sampled_from(["R", "m", "g", "a3", "I1", "I3", "I2"]))
        old = doc["body"].get(key, 0.3)
        # an earlier hostile mutation may have left a non-number (a list, a huge integer) here
        # (found by a fresh run): scale a plausible value instead
        if isinstance(old, bool) or not isinstance(old, int | float) or abs(old) > 1e300:
            old = 0.3
        doc["body"][key] = float(old) * draw(st.floats(0.2, 3.0))
    elif what == "integration":
        key, values = draw(st.sampled_from([
            ("t_end", st.floats(1e-4, 0.05)), ("samples", st.integers(2, 60)),
            ("rtol", st.sampled_from([1e-15, 1e-12, 1e-6, 0.1])),
            ("atol", st.sampled_from([1e-300, 1e-14, 1e-3])), ("max_steps", st.integers(1, 50)),
        ]))  # fmt: skip
        doc.setdefault("integration", {})[key] = draw(values)
    elif what == "model":
        models = ["meridian", "smooth", "rough", "rubber"]
        doc.setdefault("contact", {})["model"] = draw(st.sampled_from(models))
    elif what == "free" and "initial" in doc:
        for key in ("v_tau", "v_horizontal"):
            doc["initial"].pop(key, None)
        model = doc.get("contact", {}).get("model", "meridian")
        if model == "meridian":
            doc["initial"]["v_tau"] = draw(st.floats(-2, 2))
        elif model == "smooth":
            doc["initial"]["v_horizontal"] = draw(st.lists(st.floats(-2, 2), min_size=2,
                                                           max_size=2))  # fmt: skip


@st.composite
def mutated_document(draw) -> tuple[str, dict]:
    name = draw(st.sampled_from(EXAMPLE_NAMES))
    doc = base_document(name)
    for _ in range(draw(st.sampled_from([0, 1, 1, 2, 3]))):
        tables = [t for t in doc if isinstance(doc[t], dict)]
        hostile = ["set", "set", "vector", "delete", "add_key", "add_table", "del_table",
                   "model", "nest"]  # fmt: skip
        action = draw(st.sampled_from(["nudge"] * 5 + hostile))
        table = draw(st.sampled_from(tables)) if tables else "body"
        doc.setdefault(table, {})
        keys = list(doc[table]) or ["R"]
        key = draw(st.sampled_from(keys))
        if action == "nudge":
            nudge(draw, doc)
        elif action == "set":
            doc[table][key] = draw(hostile_values)
        elif action == "vector":
            key = draw(st.sampled_from(["gamma", "omega", "alpha", "position", "v",
                                        "v_horizontal"]))  # fmt: skip
            doc.setdefault("initial", {})[key] = draw(vector_like(3))
        elif action == "delete":
            doc[table].pop(key, None)
        elif action == "add_key":
            doc[table][draw(st.text(min_size=1, max_size=8))] = draw(hostile_values)
        elif action == "add_table":
            doc[draw(st.text(min_size=1, max_size=8))] = {"a": draw(hostile_values)}
        elif action == "del_table":
            doc.pop(table, None)
        elif action == "model":
            doc.setdefault("contact", {})["model"] = draw(
                st.one_of(
                    st.sampled_from(["meridian", "smooth", "rough", "rubber"]), hostile_values
                )
            )
        else:
            doc[table][key] = {"nested": {"deeper": draw(hostile_values)}}
    return name, doc


@st.composite
def scenario_bytes(draw) -> bytes:
    """The TOML of a mutated example, sometimes made hostile as text."""
    _, doc = draw(mutated_document())
    text = toml_text(doc)
    kind = draw(st.sampled_from(["plain"] * 15 + ["bom", "deep", "garbage", "truncate", "crlf",
                                                  "digits"]))  # fmt: skip
    data = text.encode("utf-8")
    if kind == "bom":
        data = b"\xef\xbb\xbf" + data
    elif kind == "deep":
        depth = draw(st.sampled_from([50, 999, 5000, 100_000]))
        data += b"\n[deep]\nx = " + b"[" * depth + b"]" * depth + b"\n"
    elif kind == "garbage":
        data = draw(st.binary(max_size=64)) + data
    elif kind == "truncate":
        data = data[: draw(st.integers(0, len(data)))]
    elif kind == "crlf":
        data = data.replace(b"\n", b"\r\n")
    elif kind == "digits":  # beyond Python's 4300-digit limit on int(str)
        data = b"x = " + b"9" * draw(st.sampled_from([4300, 4301, 100_000])) + b"\n" + data
    return data


# ---- scenarios through simulate, equilibria, orbits -------------------------------------------


# A scenario without [integration] (found by CI): the default samples hold
NO_INTEGRATION_TABLE = (
    b"[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
    b'\n[contact]\nmodel = "meridian"\n'
    b"\n[initial]\ngamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\nv_tau = 0.25\n"
)


@pytest.mark.slow
@fuzz(120)
@given(data=scenario_bytes(), output=st.sampled_from([None, "out.nc", "out.csv"]))
@example(data=NO_INTEGRATION_TABLE, output="out.nc")
def test_fuzz_simulate_scenarios(data, output):
    with workdir() as folder:
        scenario = folder / "s.toml"
        scenario.write_bytes(data)
        args = ["simulate", str(scenario), "--json"]
        if output is not None:
            args += ["-o", str(folder / output)]
        before = listing(folder)
        code, out, err = invoke(args)
        summary = check_contract(code, out, err, as_json=True)
        if code != 0:
            assert listing(folder) == before, err
        elif output is not None:
            # A scenario may leave out [integration] (or its samples): the default then holds
            table = tomllib.loads(data.decode("utf-8-sig")).get("integration", {})
            samples = table.get("samples", IntegrationOptions().samples)
            check_trajectory_file(folder / output, summary, samples)


@fuzz(40)
@given(data=scenario_bytes(), command=st.sampled_from(["equilibria", "orbits"]))
def test_fuzz_reduction_commands(data, command):
    run_scenario_command(data, command)


def run_scenario_command(data: bytes, command: str) -> None:
    """``rollingtop COMMAND s.toml --json`` on ``data``: the contract, and no file written."""
    with workdir() as folder:
        scenario = folder / "s.toml"
        scenario.write_bytes(data)
        code, out, err = invoke([command, str(scenario), "--json"])
        check_contract(code, out, err, as_json=True)
        assert listing(folder) == ["s.toml"]


@pytest.mark.slow
@fuzz(30)
@given(data=scenario_bytes(), command=st.sampled_from(["bifurcation", "stability"]))
def test_fuzz_classification_commands(data, command):
    """The classification commands (issue 14) on hostile scenarios: one line or a result."""
    run_scenario_command(data, command)


# Huge and tiny finite values included: a level too large for double precision is refused in
# one line (LevelSet), one whose walls are too thin near theta = pi too (orbits)
hostile_level_numbers = st.sampled_from([0.0, 1.0, -1.0, 1e-12, -1e-300, 1e-150, 1e150, 1e300,
                                         math.inf, math.nan, 10**400, "1", True])  # fmt: skip


@st.composite
def level_tables(draw) -> dict:
    """The level of an example (a pole case or Fig. 5's), moved a little, or made hostile."""
    base = draw(st.sampled_from([
        {"M3": 1.0, "C1": 1.0, "C2": -0.3, "h": 1.1},  # examples/pole.toml
        {"M3": 1.0, "C1": 0.5, "C2": -2.0, "h": 4.0},  # examples/fig5.toml
    ]))  # fmt: skip
    level = {}
    for key, value in base.items():
        choice = draw(st.integers(0, 9))
        if choice == 0:
            level[key] = draw(hostile_level_numbers)
        elif choice == 1 and key == "h":
            continue  # no h: no state, the reduction commands only
        else:
            level[key] = value * draw(st.sampled_from([1.0, 1.0, 0.9, 1.1, 1 + 1e-12, -1.0, 0.0]))
    optional = {"gamma3": st.one_of(st.floats(-1, 1), hostile_level_numbers),
                "branch": st.sampled_from([1, -1, 0, 2, 1.0, "1", True]),
                "phi": st.floats(-7, 7), "psi": st.floats(-7, 7)}  # fmt: skip
    for key, values in optional.items():
        if draw(st.integers(0, 3)) == 0:
            level[key] = draw(values)
    return level


@fuzz(40)
@given(level=level_tables(), command=st.sampled_from(["simulate", "equilibria", "orbits"]))
def test_fuzz_level_tables(level, command):
    doc = base_document("pole")
    doc["level"] = level
    with workdir() as folder:
        scenario = folder / "s.toml"
        scenario.write_text(toml_text(doc), encoding="utf-8")
        code, out, err = invoke([command, str(scenario), "--json"])
        check_contract(code, out, err, as_json=True)
        assert listing(folder) == ["s.toml"]


# ---- hostile option values ----------------------------------------------------------------------

option_numbers = st.one_of(
    st.sampled_from(
        [
            "0",
            "-1",
            "1e-320",
            "5e-324",
            "1e308",
            "inf",
            "-inf",
            "nan",
            "1e400",
            "9" * 400,
            "2",
            "x",
            "",
            "0x10",
            "1_000",
            " 1",
            "1e12",
            "10000000000",
        ]
    ),  # fmt: skip
    st.floats(allow_nan=True).map(repr),
    st.integers().map(str),
)


@fuzz(80)
@given(
    example=st.sampled_from(["paper", "smooth", "rough", "rubber", "pole"]),
    options=st.dictionaries(
        st.sampled_from(["--t-end", "--rtol", "--atol", "--samples", "--model"]),
        st.one_of(
            option_numbers,
            st.sampled_from(["meridian", "smooth", "rough", "rubber", "ice", "z" * 5000]),
        ),
        max_size=3,
    ),
    output=st.sampled_from([None, "out.nc", "out.csv", "out.xlsx", "missing/out.nc", "."]),
)
def test_fuzz_simulate_options(example, options, output):
    options = {"--t-end": "0.02", "--samples": "5"} | options
    with workdir() as folder:
        scenario = folder / "s.toml"  # the example, with few steps allowed (--t-end 1e308)
        scenario.write_text(toml_text(base_document(example)), encoding="utf-8")
        args = ["simulate", str(scenario), "--json"]
        for k, v in options.items():
            args += [k, v]
        if output is not None:
            args += ["-o", str(folder / output)]
        code, out, err = invoke(args)
        summary = check_contract(code, out, err, as_json=True)
        if code != 0:
            assert listing(folder) == ["s.toml"], err
        elif output is not None:
            check_trajectory_file(folder / output, summary, int(float(options["--samples"])))


valid_grid = st.lists(
    st.tuples(
        st.sampled_from(["omega3", "omega1", "theta", "v_tau", "gamma1", "position1", "v1"]),
        st.floats(-2, 2),
        st.floats(-2, 2),
        st.integers(1, 3),
    ),
    min_size=1,
    max_size=2,
    unique_by=lambda axis: axis[0],
).map(lambda axes: ",".join(f"{n}={a!r}:{b!r}:{c}" for n, a, b, c in axes))

grid_specs = st.one_of(
    valid_grid,
    valid_grid,
    st.sampled_from(
        [
            "omega3=1:3:3",
            "omega3=1:3:3,v_tau=0:0.5:2",
            "theta=0.5:1.0:2",
            "omega3=1:3:0",
            "omega3=1:3:100000,v_tau=0:1:100000",
            "omega3=nan:1:2",
            "omega3=inf:1:2",
            "omega3=1e400:1:2",
            "omega3=1:2:" + "9" * 400,
            "omega3=1:2",
            "=1:2:3",
            "",
            ",",
            "omega3=1:3:2,omega3=1:3:2",
            "gamma1=0:1:2",
            "x" * 300_000,
            "omega3=a:b:2",
            "v_horizontal1=0:1:2",
            "position1=0:1e308:2",
        ]
    ),  # fmt: skip
    st.text(max_size=30),
)


@fuzz(50)
@given(
    example=st.sampled_from(["paper", "smooth", "rough", "rubber"]),
    grid=grid_specs,
    samples=st.sampled_from([None, "2", "5", "1", "10000000000", "x", "1e10"]),
    threads=st.sampled_from([None, "1", "2", "64", "0", "-3", "9" * 30]),
    output=st.booleans(),
)
def test_fuzz_ensemble_grid(example, grid, samples, threads, output):
    with workdir() as folder:
        args = ["ensemble", str(EXAMPLES / f"{example}.toml"), "--grid", grid, "--t-end", "0.02",
                "--json"]  # fmt: skip
        for flag, value in (("--samples", samples), ("--threads", threads)):
            if value is not None:
                args += [flag, value]
        if output:
            args += ["-o", str(folder / "ens.nc")]
        code, out, err = invoke(args)
        summary = check_contract(code, out, err, as_json=True)
        if code != 0:
            assert listing(folder) == [], err
        else:
            if threads is not None and int(threads) > os.cpu_count():
                assert "rollingtop: note: --threads" in err
            assert summary["threads"] <= max(os.cpu_count(), 1)
            if output:
                check_ensemble_file(folder / "ens.nc", summary)


def check_ensemble_file(path: Path, summary: dict) -> None:
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds.sizes["trajectory"] == summary["n"]
        assert ds["final_state"].shape == (summary["n"], 18)
        assert json.loads(ds.attrs["summary_json"])["n"] == summary["n"]
        assert int((ds["status"] != 0).sum()) == summary["failed"]


plain_cells = st.floats(-3, 3, allow_nan=False).map(repr)
hostile_cells = st.sampled_from(["", "nan", "inf", "-inf", "1e400", "9" * 400, "x", "0x1", " 1 ",
                                 '"1"', "1e-320", "True", "1,2"])  # fmt: skip
good_names = st.sampled_from(["omega1", "omega2", "omega3", "theta", "v_tau", "position1",
                              "position2"])  # fmt: skip
bad_names = st.sampled_from(["gamma1", "v1", "v_horizontal1", "foo", "", "omega3 ", "é",
                             "x" * 500])  # fmt: skip
csv_names = st.integers(0, 5).flatmap(lambda k: good_names if k else bad_names)


@st.composite
def csv_tables(draw) -> bytes:
    names = draw(st.lists(csv_names, min_size=1, max_size=3, unique=draw(st.integers(0, 4)) > 0))
    rows = draw(st.lists(st.lists(plain_cells, min_size=len(names), max_size=len(names)),
                         min_size=draw(st.sampled_from([0, 1, 1, 1])), max_size=4))  # fmt: skip
    if rows and draw(st.integers(0, 2)) == 0:  # one hostile cell
        row = draw(st.integers(0, len(rows) - 1))
        rows[row][draw(st.integers(0, len(names) - 1))] = draw(hostile_cells)
    if rows and draw(st.integers(0, 9)) == 0:  # a ragged row
        rows[-1] = rows[-1][:-1] or ["1", "2"]
    text = "# fuzz\n" + ",".join(names) + "\n" + "".join(",".join(r) + "\n" for r in rows)
    data = text.encode("utf-8")
    kind = draw(st.sampled_from(["plain"] * 10 + ["bom", "binary", "crlf"]))
    if kind == "bom":
        data = b"\xef\xbb\xbf" + data
    elif kind == "binary":
        data = draw(st.binary(min_size=1, max_size=64)) + data
    elif kind == "crlf":
        data = data.replace(b"\n", b"\r\n")
    return data


@pytest.mark.slow
@fuzz(60)
@given(example=st.sampled_from(["paper", "smooth", "rough", "rubber", "pole"]), table=csv_tables())
def test_fuzz_ensemble_tables(example, table):
    with workdir() as folder:
        csv = folder / "ic.csv"
        csv.write_bytes(table)
        out_file = folder / "ens.nc"
        args = ["ensemble", str(EXAMPLES / f"{example}.toml"), "--initial", str(csv), "--t-end",
                "0.02", "--samples", "3", "-o", str(out_file), "--json"]  # fmt: skip
        code, out, err = invoke(args)
        summary = check_contract(code, out, err, as_json=True)
        if code != 0:
            assert listing(folder) == ["ic.csv"], err
        else:
            check_ensemble_file(out_file, summary)


@pytest.mark.slow
@fuzz(12)
@given(
    command=st.sampled_from(["plot", "path", "compare", "portrait", "animate"]),
    value=option_numbers,
    data=scenario_bytes(),
)
def test_fuzz_figure_commands(command, value, data):
    """Figures are slow: a small budget, mostly the cheap refusals of their own options."""
    suffix = {"animate": "roll.gif"}.get(command, "fig.png")
    option = {"plot": "--t-end", "path": "--periods", "compare": "--t-end",
              "portrait": "--h-levels", "animate": "--duration"}[command]  # fmt: skip
    with workdir() as folder:
        scenario = folder / "s.toml"
        scenario.write_bytes(data)
        args = [command, str(scenario), "-o", str(folder / suffix), option, value]
        if command in ("plot", "compare"):
            args[-1] = value if not re.fullmatch(r"[0-9.]+", value) else "0.05"
        if command == "path":
            args += ["--t-end", "0.05"]
        if command == "animate":
            args += ["--fps", "2", "--speed", "0.01"]
        code, out, err = invoke(args)
        check_contract(code, out, err)
        if code != 0:
            assert listing(folder) == ["s.toml"], err
        else:
            assert (folder / suffix).stat().st_size > 0


# ---- a few cases in a real process (what a user's terminal sees) ------------------------------


@pytest.mark.parametrize(
    ("content", "args", "message"),
    [
        (b"\xef\xbb\xbf[body]\n", [], "byte-order mark"),
        pytest.param(None, [], "not a regular file (it is a FIFO)", marks=pytest.mark.slow),
        pytest.param(
            (EXAMPLES / "paper.toml").read_bytes(),
            ["--samples", "1000000000000"],
            "needs about 931.3 TiB of memory",
            marks=pytest.mark.slow,
        ),  # fmt: skip
    ],
    ids=["bom", "fifo", "samples"],
)
def test_real_process_refusals(tmp_path, content, args, message):
    scenario = tmp_path / "s.toml"
    if content is None:
        os.mkfifo(scenario)
    else:
        scenario.write_bytes(content)
    proc = subprocess.run(
        [sys.executable, "-m", "rollingtop", "simulate", str(scenario), *args, "--json"],
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    assert proc.returncode == 2 and proc.stdout == ""
    (line,) = proc.stderr.splitlines()
    assert line.startswith("rollingtop: error: ") and message in line
    assert listing(tmp_path) == ["s.toml"]
