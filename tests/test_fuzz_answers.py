"""Property-based fuzzing of what issue 36 found wrong, by class (issue 36 item 8):

* **a valid run refused** -- admissible states of every model with a reduction or a flow,
  exact poles, sleeping tops, zero spin and tiny components included: ``simulate`` exits 0,
  ``equilibria`` and ``orbits`` either answer or refuse in one line (never a traceback);
* **a number not achieved** -- ``simulate --project-integrals`` at any tolerance the command
  line accepts: exit 0 only with every claimed integral held within the summary's tolerance of
  its natural size, else exit 1 saying so;
* **a file left** -- a refusal leaves the folder as it was (``check_contract`` of
  tests/test_fuzz.py and the folder's listing);
* **a foreign input accepted** -- an atlas's saved chunks copied over, renamed, swapped or cut:
  resuming loads only chunks that are what their names say, with their own cells.

Budgets are fixed (``derandomize=True``); runs are short.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from .test_fuzz import check_contract, fuzz, listing
from .test_fuzz import invoke as invoke_cli


def invoke(args):
    """:func:`tests.test_fuzz.invoke` without the compile notices of a first run (the held
    integrator compiles on its first use, within the draw)."""
    code, out, err = invoke_cli(args)
    kept = [line for line in err.splitlines(True) if not line.startswith("rollingtop: compiling")]
    return code, out, "".join(kept)


MODELS = ("meridian", "smooth", "rough", "rubber", "parallel", "shell-rotor")
BODY = "[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
SHELL = "[shell]\nmass = 0.2\ninertia = 0.13333333333333333\n"

component = st.one_of(
    st.just(0.0),
    st.floats(-3.0, 3.0, allow_nan=False),
    st.sampled_from([1e-300, -1e-300, 1e-12, 2.0, -2.0]),
)


@st.composite
def admissible_states(draw):
    """A model and an admissible (gamma, omega): gamma exactly at a pole, near one, or anywhere;
    omega with zero, tiny and ordinary components (projected onto rubber rolling's
    (omega, gamma) = 0)."""
    model = draw(st.sampled_from(MODELS))
    kind = draw(st.sampled_from(["south", "north", "near", "any"]))
    if kind in ("south", "north"):
        gamma = np.array([0.0, 0.0, 1.0 if kind == "south" else -1.0])
    else:
        tilt = (
            draw(st.sampled_from([1e-9, 1e-4]))
            if kind == "near"
            else draw(st.floats(0.01, math.pi - 0.01))
        )
        az = draw(st.floats(0.0, 2 * math.pi))
        gamma = np.array(
            [math.sin(tilt) * math.cos(az), math.sin(tilt) * math.sin(az), math.cos(tilt)]
        )
    omega = np.array([draw(component) for _ in range(3)])
    if model == "rubber":  # projected twice: once leaves a relative residual ~ the tilt when
        for _ in range(2):  # omega is nearly vertical (7.6e-204 e3 at a tilt of 1e-9 became
            omega = omega - float(omega @ gamma) * gamma  # -7.6e-213 e1: 1e-9 off, refused)
    return model, gamma, omega


def scenario_text(model, gamma, omega, extra=""):
    vec = lambda x: "[" + ", ".join(repr(float(v)) for v in x) + "]"  # noqa: E731
    shell = SHELL if model == "shell-rotor" else ""
    return (
        f'{BODY}{shell}[contact]\nmodel = "{model}"\n[initial]\ngamma = {vec(gamma)}\n'
        f"omega = {vec(omega)}\n[integration]\nt_end = 0.05\n{extra}"
    )


@pytest.mark.slow
@fuzz(30)
@given(state=admissible_states())
def test_fuzz_a_valid_state_is_run_and_classified(tmp_path_factory, state):
    folder = tmp_path_factory.mktemp("valid")
    path = folder / "s.toml"
    path.write_text(scenario_text(*state))
    code, out, err = invoke(["simulate", str(path), "--json"])
    summary = check_contract(code, out, err, as_json=True)
    assert code == 0, err  # a valid run is never refused
    for name, row in summary["integrals"].items():
        assert row["max_rel_drift"] is None or row["max_rel_drift"] < 1e-9, name
    for command in ("equilibria", "orbits"):
        code, out, err = invoke([command, str(path), "--json"])
        check_contract(code, out, err, as_json=True)
        assert code in (0, 2), err
        assert "nan" not in err.lower().replace("finite", "")
    assert listing(folder) == ["s.toml"]  # nothing written besides


@pytest.mark.slow
@fuzz(20)
@given(
    state=admissible_states().filter(lambda state: state[0] != "shell-rotor"),  # refused at once
    tol=st.sampled_from(["1e-2", "1e-3", "1e-5", "1e-7", "1e-10"]),
    output=st.booleans(),
)
def test_fuzz_a_held_run_holds_or_says_so(tmp_path_factory, state, tol, output):
    folder = tmp_path_factory.mktemp("held")
    path = folder / "s.toml"
    path.write_text(scenario_text(*state))
    args = ["simulate", str(path), "--json", "--project-integrals", "--rtol", tol, "--atol", tol]
    if output:
        args += ["-o", str(folder / "run.nc")]
    code, out, err = invoke(args)
    assert code in (0, 1), err
    if code == 0:
        summary = check_contract(code, out, err, as_json=True)
        verdict = summary["projection"]
        assert verdict["held"] is True and verdict["max_rel_drift"] <= verdict["tolerance"]
        assert all(
            r["max_rel_drift"] is None or r["max_rel_drift"] <= verdict["tolerance"]
            for r in summary["integrals"].values()
        )
    else:
        assert err.startswith("rollingtop: error: the projection did not hold"), err
    assert (folder / "run.nc").exists() == output


# ---- a foreign chunk is never accepted ---------------------------------------------------------
CHUNKS = 4


def _chunks(folder, digest):
    from rollingtop.atlas._store import _save_chunk

    original = {}
    for k in range(CHUNKS):
        result = {
            name: np.full(5, 10 * k + j, dtype=np.int16)
            for j, name in enumerate(("status", "n_steady", "n_centres", "n_saddles", "n_folds"))
        }
        result["rotation_centre"] = np.full((5, 4), float(k))
        result["centre_gamma3"] = np.full((5, 4), -float(k))
        _save_chunk(folder, k, (5 * k, 5 * k + 5), digest, result)
        original[k] = result
    return original


damage = st.tuples(
    st.sampled_from(["copy", "swap", "rename", "cut", "keep"]),
    st.integers(0, CHUNKS - 1),
    st.integers(0, CHUNKS - 1),
)


@fuzz(60)
@given(steps=st.lists(damage, max_size=4), other_spec=st.booleans())
def test_fuzz_resume_accepts_only_its_own_chunks(tmp_path_factory, steps, other_spec):
    """Whatever is done to the saved chunk files, every chunk that loads is the one its
    index says, with its own cells and spec; the others are computed again."""
    import warnings

    from rollingtop.atlas._store import _load_partial

    folder = tmp_path_factory.mktemp("partial")
    digest = "d" * 64
    original = _chunks(folder, "e" * 64 if other_spec else digest)
    (folder / "spec.json").write_text('{"digest": "' + digest + '"}')
    name = lambda k: folder / f"chunk-{k:06d}.npz"  # noqa: E731
    for op, a, b in steps:
        if not name(a).exists() or not name(b).exists():
            continue
        if op == "copy":
            name(b).write_bytes(name(a).read_bytes())
        elif op == "swap":
            da, db = name(a).read_bytes(), name(b).read_bytes()
            name(a).write_bytes(db)
            name(b).write_bytes(da)
        elif op == "rename" and a != b:
            name(a).replace(name(b))
        elif op == "cut":
            name(a).write_bytes(name(a).read_bytes()[: len(name(a).read_bytes()) // 2])
    ranges = {k: (5 * k, 5 * k + 5) for k in range(CHUNKS)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        done = _load_partial(folder, digest, ranges)
    if other_spec:
        assert done == {}
    for k, part in done.items():
        assert set(part) == set(original[k])
        for key, values in part.items():
            np.testing.assert_array_equal(values, original[k][key])  # copied, not computed
