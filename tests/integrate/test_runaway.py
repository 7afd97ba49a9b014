"""Runaway states end a run with a status and one line, after finitely many attempted steps.

Before these guards, ``omega3 = 1e170`` gave a NaN derivative, a NaN initial step and an endless
loop of rejected steps (``NaN < min_step`` is false), deaf to ``max_steps`` and Ctrl-C. Each
test asserts the error and that the run returns at all, well within :data:`RETURNS_WITHIN_S`;
a watchdog (:func:`faulthandler.dump_traceback_later`) ends the test process if one hangs.
"""

import faulthandler
import subprocess
import sys
import time

import numpy as np
import pytest

from rollingtop import IntegrationError, SphericalTop, initial_state, simulate
from rollingtop._compiled import _dop853 as dop
from rollingtop._errors import InitialStateError
from rollingtop.contact import get_model
from rollingtop.integrate import integrate
from rollingtop.integrate.driver import _stepper_calls, compile_kernels
from rollingtop.integrate.ensemble import compile_ensemble, integrate_batch

from ..conftest import GAMMA0, OMEGA0, PAPER_BODY, scenario_text

#: Kernel code of the paper's model (no pole variant).
MERIDIAN = get_model("meridian").code

#: Generous bound on the wall time of a run that must fail (they take milliseconds once the
#: kernels are loaded; the bound only has to separate "returns" from "hangs").
RETURNS_WITHIN_S = 30.0
#: The watchdog's limit: past it the test process is ended with a traceback of every thread.
WATCHDOG_S = 120.0
#: Tolerances (rtol, atol) that no step can meet: ``atol = 1e-150`` with ``rtol = 0`` rejects
#: every attempt down to h ~ 1e-89; ``atol = 1e-300`` makes the scaled norm of the state overflow.
REJECTING_TOLERANCE = (0.0, 1e-150)
OVERFLOWING_TOLERANCE = (0.0, 1e-300)

HUGE_OMEGA3 = [1e170, 1e200, 1e300]


@pytest.fixture(autouse=True)
def watchdog():
    compile_kernels()
    compile_ensemble()
    faulthandler.dump_traceback_later(WATCHDOG_S, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def paper_state(omega=OMEGA0, model="meridian"):
    body = SphericalTop(**PAPER_BODY)
    free = {"v_tau": 0.25} if model == "meridian" else {}
    return body, initial_state(body, model, gamma=GAMMA0, omega=omega, free=free)


def timed(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``'s exception (or None) and the seconds it took."""
    start = time.perf_counter()
    try:
        fn(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001 - returned for the test to check
        return exc, time.perf_counter() - start
    return None, time.perf_counter() - start


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")  # |omega|**2 in the checks
@pytest.mark.parametrize("omega3", HUGE_OMEGA3)
def test_huge_spin_ends_a_single_run(tmp_path, omega3):
    initial = f"gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, {omega3!r}]\nv_tau = 0.25"
    path = tmp_path / "huge.toml"
    path.write_text(scenario_text(initial=initial), encoding="utf-8")
    exc, seconds = timed(simulate, path, t_end=50.0)
    # a bad input, named (issue 36 row 12): was an IntegrationError "initial values too large?"
    assert isinstance(exc, InitialStateError)
    assert "derivative of the initial state is not finite at t = 0" in str(exc)
    assert f"|omega| = {omega3:g} overflows double precision" in str(exc)
    assert seconds < RETURNS_WITHIN_S


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("component", [0, 5, 12, 16])
def test_non_finite_initial_state_ends_a_low_level_run(bad, component):
    body, y0 = paper_state()
    y0[component] = bad
    exc, seconds = timed(integrate, 0, body.params, y0, np.array([0.0, 50.0]), rtol=1e-10,
                         atol=1e-12)  # fmt: skip
    assert isinstance(exc, IntegrationError) and "not finite" in str(exc)
    assert seconds < RETURNS_WITHIN_S


def test_too_tight_tolerance_ends_a_run_after_a_hundred_rejections():
    body, y0 = paper_state()
    rtol, atol = REJECTING_TOLERANCE
    exc, seconds = timed(integrate, 0, body.params, y0, np.array([0.0, 50.0]), rtol=rtol,
                         atol=atol)  # fmt: skip
    assert isinstance(exc, IntegrationError)
    assert f"{dop.MAX_REJECTED_IN_A_ROW} rejected steps in a row at t = 0" in str(exc)
    assert seconds < RETURNS_WITHIN_S


def test_overflowing_tolerance_has_no_initial_step():
    body, y0 = paper_state()
    rtol, atol = OVERFLOWING_TOLERANCE
    exc, seconds = timed(integrate, 0, body.params, y0, np.array([0.0, 50.0]), rtol=rtol,
                         atol=atol)  # fmt: skip
    assert isinstance(exc, IntegrationError) and "no initial step size at t = 0" in str(exc)
    assert seconds < RETURNS_WITHIN_S


def test_non_finite_t_eval_is_refused():
    body, y0 = paper_state()
    with pytest.raises(ValueError, match="t_eval must be finite"):
        integrate(MERIDIAN, body.params, y0, np.array([0.0, np.inf]), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("h", [np.nan, 0.0, 1e-15])
def test_stepper_stops_on_a_nan_or_underflowing_step(h):
    """The loop of ``run`` itself: a NaN step (the old endless loop) or one below ten units in
    the last place of ``t`` (at t = 1: 2.2e-15) returns ``STEP_TOO_SMALL`` without a step."""
    body, y0 = paper_state()
    t_eval = np.array([1.0, 50.0])
    stepper, run_args, (row, _, _, _) = _stepper_calls(
        0, body.params, y0, t_eval, 1e-10, 1e-12, (0, 0, 1)
    )
    stepper.run_rows(*run_args(0))  # starts the row, takes no step
    assert row.STATUS[0] == dop.BUDGET_EXHAUSTED and row.COUNTS[0, dop.STEPS] == 0
    row.CTRL[0, dop.H_ABS] = h
    stepper.run_rows(*run_args(10**6))
    assert row.STATUS[0] == dop.STEP_TOO_SMALL and row.COUNTS[0, dop.STEPS] == 0


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")
def test_ensemble_reports_runaway_trajectories_and_finishes_the_others():
    """Per-trajectory status in ``stats[:, 0]``: the sound states finish, each runaway one gets
    its code, and the batch returns."""
    body, good = paper_state()
    rows = [good]
    for omega3 in HUGE_OMEGA3:
        rows.append(paper_state(omega=(0.7, -0.3, omega3))[1])
    nan_state = good.copy()
    nan_state[3] = np.nan
    rows += [nan_state, good]
    states = np.array(rows)
    n = len(rows)
    start = time.perf_counter()
    codes, params = np.zeros(n, dtype=np.int64), np.tile(body.params, (n, 1))
    _, final, stats, _ = integrate_batch(codes, params, states, np.array([0.0, 5.0]), rtol=1e-10,
                                         atol=1e-12)  # fmt: skip
    assert time.perf_counter() - start < RETURNS_WITHIN_S
    expected = [dop.FINISHED] + [dop.NOT_FINITE] * 4 + [dop.FINISHED]
    assert stats[:, 0].tolist() == expected
    np.testing.assert_array_equal(final[0], final[-1])  # one state, one computation: same bits


@pytest.mark.parametrize(
    ("tolerance", "status"),
    [(REJECTING_TOLERANCE, dop.TOO_MANY_REJECTED), (OVERFLOWING_TOLERANCE, dop.STEP_TOO_SMALL)],
)
def test_ensemble_reports_too_tight_tolerances(tolerance, status):
    body, good = paper_state()
    rtol, atol = tolerance
    start = time.perf_counter()
    _, _, stats, _ = integrate_batch(np.zeros(2, dtype=np.int64), np.tile(body.params, (2, 1)),
                                     np.array([good, good]), np.array([0.0, 5.0]), rtol=rtol,
                                     atol=atol)  # fmt: skip
    assert time.perf_counter() - start < RETURNS_WITHIN_S
    assert stats[:, 0].tolist() == [status, status]


def test_ensemble_max_steps_status():
    body, good = paper_state()
    _, _, stats, _ = integrate_batch(np.zeros(1, dtype=np.int64), body.params[None, :],
                                     good[None, :], np.array([0.0, 50.0]), rtol=1e-10,
                                     atol=1e-12, max_steps=10)  # fmt: skip
    assert stats[0, 0] == dop.BUDGET_EXHAUSTED and stats[0, 1] == 10


def test_every_status_has_a_name():
    codes = [dop.FINISHED, dop.BUDGET_EXHAUSTED, dop.INTERRUPTED, dop.STEP_TOO_SMALL,
             dop.NOT_FINITE, dop.TOO_MANY_REJECTED, dop.PROJECTION_FAILED]  # fmt: skip
    assert sorted(dop.STATUS_NAMES) == sorted(codes) and len(set(codes)) == len(codes)


def test_cli_reports_a_huge_spin_in_one_line(tmp_path):
    """``rollingtop simulate`` on ``omega3 = 1e170`` (the reported hang): exit 2 (a bad input,
    named), one line."""
    initial = "gamma = [0.0, 0.6, 0.8]\nomega = [0.7, -0.3, 1e170]\nv_tau = 0.25"
    (tmp_path / "huge.toml").write_text(scenario_text(initial=initial), encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "rollingtop.cli", "simulate", "huge.toml", "-o", "out.nc"],
        cwd=tmp_path,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=WATCHDOG_S,
    )
    lines = proc.stderr.splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("rollingtop: error: ")
    assert "not finite" in lines[0] and "|omega| = 1e+170" in lines[0]
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["huge.toml"]


def test_the_pace_guard_refuses_a_run_far_beyond_max_steps():
    """Issue 27: after PACE_AFTER steps, a pace that needs more than PACE_FACTOR x max_steps to
    reach t_end is one IntegrationError; a pace within it, or too few steps to judge, is not."""
    from rollingtop.integrate._pace import PACE_AFTER, PACE_FACTOR, check_pace

    n = PACE_AFTER
    with pytest.raises(IntegrationError, match=r"needs about 4e\+17 steps, more than 100 times"):
        check_pace(0.0, 1e-13, 1.0, n, 10**8)
    with pytest.raises(IntegrationError, match="needs about inf steps"):
        check_pace(5.0, 5.0, 6.0, n, 10**8)  # no progress at all
    check_pace(0.0, 1e-13, 1.0, n - 1, 10**8)  # too early to judge
    limit = n * 10 / PACE_FACTOR  # needs 10 n steps: exactly the factor
    check_pace(0.0, 0.1, 1.0, n, int(limit))
    with pytest.raises(IntegrationError):
        check_pace(0.0, 0.1, 1.0, n, int(limit) - 1)
