"""The C limit of ``benchmarks/`` stays the same integration as rollingtop's compiled stepper.

``benchmarks/c_limit/dop853.c`` writes rollingtop's DOP853 for the meridian model in plain C with
a fixed state size (``N = 18`` at compile time, the loops of known length the C compiler
specialises), against which ``benchmarks/c_limit.py`` measures rollingtop's speed. The
comparison means something only while both compute the same numbers: these tests hold every
piece -- right-hand side, normal force, projection, the fixed-size stage and error-estimate code,
dense output, initial step -- to rollingtop's generic (run-time length) code to the last bit on
random inputs, and a short integration to the same steps and final state. Skipped, with the
reason, where there is no C compiler.
"""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest

from ..conftest import ROOT

PATH = ROOT / "benchmarks" / "c_limit.py"


@pytest.fixture(scope="module")
def c_limit():
    spec = importlib.util.spec_from_file_location("c_limit", PATH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["c_limit"] = module
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("c_limit", None)


@pytest.fixture(scope="module")
def lib(c_limit):
    if c_limit.find_compiler() is None:
        pytest.skip("no C compiler: the C limit cannot be built here")
    built = c_limit.build(quiet=True)
    if built is None:
        pytest.skip("the C compiler failed on benchmarks/c_limit/dop853.c")
    return built


def test_pieces_equal_rollingtop_to_the_last_bit(c_limit, lib):
    """60 states along W1 (perturbed by 1e-3) with random stages, step sizes and
    interpolation points: no component of any piece differs."""
    sc, code = c_limit.w1_problem()
    differ = c_limit.check_pieces(lib, sc, code, n_states=60)
    assert set(differ) >= {"rhs", "project", "stage", "scaled_errors", "prepare_dense"}
    assert differ == dict.fromkeys(differ, 0)


def test_short_w1_takes_the_same_steps_to_the_same_state(c_limit, lib):
    sc, code = c_limit.w1_problem()
    sc = sc.with_overrides(t_end=200.0)
    c = c_limit.run_c(sc, lib)
    rt = c_limit.integrate_rollingtop(sc, code)
    assert (c["steps"], c["rejected"], c["rhs_evals"]) == (
        rt["steps"],
        rt["rejected"],
        rt["rhs_evals"],
    )
    assert c["steps"] > 1000  # a real run, with rejections to compare too
    assert c["rejected"] > 0
    np.testing.assert_array_equal(c["y"], rt["y"])
    # the same work: the reactions monitored at the same step ends (no dip search)
    assert c["reactions"]["min_normal_force"] == rt["reactions"]["min_normal_force"]
