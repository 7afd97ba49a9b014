"""Shared fixtures. Reference values cite their source; tolerances are named where used."""

import contextlib
from pathlib import Path

import mpmath
import numpy as np
import pytest

from rollingtop import SphericalTop

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: Kilin & Ivanova (2023), Fig. 5: R = 1, m = 1, g = 1, a3 = 0.1, I1 = 0.3, I3 = 0.5.
PAPER_BODY = dict(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)

#: Initial conditions of examples/paper.toml, with each model's free velocity.
GAMMA0 = (0.0, 0.6, 0.8)
OMEGA0 = (0.7, -0.3, 2.0)
FREE = {
    "meridian": {"v_tau": 0.25},
    "smooth": {"v_horizontal": (0.3, -0.2)},
    "rough": {},
    "parallel": {"v_nu": 0.25},
    "rubber": {},
}


def local_cluster(n_workers: int, *, processes: bool = False, **options):
    """A Dask ``LocalCluster`` for a test: one thread per worker, in this process unless
    ``processes``, no dashboard, and the scheduler's HTTP server on a free port (on 8787, taken
    by another test's cluster, Dask warns "Port 8787 is already in use"), as the atlas's own."""
    from distributed import LocalCluster

    return LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=processes,
                        dashboard_address=None,
                        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                        **options)  # fmt: skip


#: The start of a script run with ``python -c``: numba's compile events are listened to, and
#: the functions this process compiles are listed in ``compiled`` (module.qualname), for the
#: script to print.
COMPILE_LISTENER = r"""
import json, sys
from numba.core import event

compiled = []


class Count(event.Listener):
    def on_start(self, ev):
        func = getattr(ev.data.get("dispatcher"), "py_func", None)
        compiled.append(f"{func.__module__}.{func.__qualname__}")

    def on_end(self, ev):
        pass


event.register("numba:compile", Count())
"""


#: Default of ``--fuzz-budget``: keeps test_fuzz.py's click-driven section near a minute on 2 cores.
FUZZ_BUDGET = 6


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--slow", action="store_true", default=False, help="run the slow tests too")
    parser.addoption(
        "--fuzz-budget",
        type=int,
        default=FUZZ_BUDGET,
        metavar="N",
        help=f"random examples per command of test_fuzz.py's click-driven fuzz (default "
        f"{FUZZ_BUDGET})",
    )


@pytest.fixture
def fuzz_budget(request: pytest.FixtureRequest) -> int:
    """``--fuzz-budget N``: hypothesis examples per command (tests/test_fuzz.py)."""
    budget = request.config.getoption("--fuzz-budget")
    if budget < 1:
        raise pytest.UsageError(f"--fuzz-budget {budget}: must be >= 1")
    return budget


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests marked ``slow`` run only with ``--slow``; the default run stays short."""
    if config.getoption("--slow"):
        return
    skip = pytest.mark.skip(reason="slow test: pass --slow to run it")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(autouse=True)
def _mpmath_precision_untouched():
    """A test that needs more digits takes a local context (``mpmath.workdps``): the global
    precision is shared by every later test, so a test that changes it fails here."""
    prec = mpmath.mp.prec
    yield
    changed = mpmath.mp.prec
    mpmath.mp.prec = prec
    assert changed == prec, f"the test left mpmath.mp.prec = {changed} (was {prec})"


@pytest.fixture
def paper_body() -> SphericalTop:
    return SphericalTop(**PAPER_BODY)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20231205)


def quoted_path(path) -> str:
    """``path`` as an error message quotes it, written plainly: its ``repr`` when that is at most
    80 characters, else an ellipsis and its last 77 characters in quotes, the file's name kept
    (ASCII paths; ``rollingtop._errors.short_path``)."""
    text = str(path)
    return repr(text) if len(repr(text)) <= 80 else "'…" + text[-77:] + "'"


def scenario_text(model: str = "meridian", **sections) -> str:
    """TOML text of a scenario on the paper's body; ``sections`` replace whole tables."""
    free = {"meridian": "v_tau = 0.25", "smooth": "v_horizontal = [0.3, -0.2]", "rough": "",
            "rubber": ""}[model]  # fmt: skip
    tables = {
        "body": "R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5",
        "contact": f'model = "{model}"',
        "initial": f"gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 2.0]\n{free}",
        "integration": "t_end = 2.0\nrtol = 1e-10\nsamples = 21",
    }
    tables.update(sections)
    return "\n".join(f"[{k}]\n{v}\n" for k, v in tables.items() if v is not None)


def admissible_omega(model, gamma, omega):
    """``omega`` without its components along the model's spin-constraint directions
    (:attr:`rollingtop.contact.ContactModel.spin_directions`, mutually orthogonal; rubber
    rolling: the part along ``gamma``), so that ``initial_state`` accepts it; unchanged for a
    model whose angular velocity is free."""
    omega = np.array(omega, dtype=float)
    if model.spin_directions is not None:
        for d in model.spin_directions(np.asarray(gamma, dtype=float)).values():
            d = np.asarray(d, dtype=float)
            omega -= (omega @ d) / (d @ d) * d
    return omega


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile (or load) every model's integrator and ensemble kernels before the first test,
    one process per model on every core (:func:`rollingtop.warmup`): on a cold numba cache the
    tests would otherwise compile them one after the other, on one core. A warm cache loads in
    seconds. Says so on the terminal, and each model as it is done: a cold start is a minute
    or more of otherwise silent work on 2 cores (the start-up table's ``rollingtop warmup``,
    measured by ``benchmarks/run_benchmarks.py``).

    With pytest-xdist (``-n``) the controller does it once, before it starts its workers (this
    hook runs before xdist's own, which is ``trylast``); the workers load the cache."""
    import json
    import time

    config = session.config
    if hasattr(config, "workerinput"):  # an xdist worker: the controller has compiled them
        return
    if config.getoption("collectonly", False):
        return
    from rollingtop import warmup

    reporter = config.pluginmanager.get_plugin("terminalreporter")
    capture = config.pluginmanager.get_plugin("capturemanager")

    def say(text):
        if reporter is None:
            return
        with capture.global_and_fixture_disabled() if capture else contextlib.nullcontext():
            reporter.write_line(text)

    try:
        measured = json.loads((ROOT / "benchmarks" / "results.json").read_text())
        cold = f"{measured['cold_start']['warmup_empty_cache_s']:.0f} s in the start-up table"
    except (OSError, KeyError, ValueError):
        cold = "a minute or more on 2 cores"
    start = time.perf_counter()
    say(
        "rollingtop: compiling or loading every model's kernels before the first test (a cold "
        f"numba cache: {cold}, one process per compiled package; a warm one: seconds)"
    )
    warmup(progress=lambda model, seconds: say(
        f"  {model}: {sum(seconds.values()):.1f} s"))  # fmt: skip
    say(f"rollingtop: kernels ready in {time.perf_counter() - start:.1f} s")
