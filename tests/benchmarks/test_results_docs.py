"""Every performance number in the README and on the performance page comes from
``benchmarks/results.json`` through ``benchmarks/run_benchmarks.py`` (never typed by hand): the
committed blocks equal what the script writes from the committed results."""

from __future__ import annotations

import json
import sys

import pytest

from ..conftest import ROOT

BENCHMARKS = ROOT / "benchmarks"


@pytest.fixture(scope="module")
def run_benchmarks():
    sys.path.insert(0, str(BENCHMARKS))
    try:
        import run_benchmarks

        yield run_benchmarks
    finally:
        sys.path.remove(str(BENCHMARKS))


@pytest.fixture(scope="module")
def results(run_benchmarks):
    res = json.loads((BENCHMARKS / "results.json").read_text())
    res["table_markdown"] = run_benchmarks.table(res)
    return res


def block(text: str, start: str, end: str) -> str:
    _, sep, rest = text.partition(start)
    inner, sep2, _ = rest.partition(end)
    assert sep and sep2, f"markers {start!r} ... {end!r} not found"
    return inner.strip("\n")


def test_readme_table_is_generated_from_results(run_benchmarks, results):
    text = (ROOT / "README.md").read_text()
    got = block(text, run_benchmarks.README_START, run_benchmarks.README_END)
    assert got == run_benchmarks.readme_block(results)


def test_performance_page_is_generated_from_results(run_benchmarks, results):
    text = run_benchmarks.DOCS_PAGE.read_text()
    got = block(text, run_benchmarks.DOCS_START, run_benchmarks.DOCS_END)
    assert got == run_benchmarks.docs_block(results)


def test_results_hold_the_numbers_issue_13_asks_for(results):
    """The C ratio with identical steps, the cold and warm starts, the peers, the scaling."""
    c = results["C"]
    # the C limit computes rollingtop's numbers to the last bit (test_c_limit): a difference of 0
    assert c["identical_steps"] and c["final_state_difference"] == 0.0
    assert len(c["ratios"]) >= 5 and c["ratio_median"] > 0
    assert {"portrait_empty_cache_s", "simulate_empty_cache_s", "rough_after_paper_s",
            "warmup_empty_cache_s", "simulate_warm_cache_s", "portrait_warm_cache_s",
            "import_heavy_modules"} <= set(results["cold_start"])  # fmt: skip
    assert {"cyrk_nbsolve2_ivp", "numbalsoda_dop853"} <= set(results["peers"])
    assert {"t_end", "rtol", "ensemble"} <= set(results["scaling"])
