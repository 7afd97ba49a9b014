"""rollingtop.integrate._compile_helper: a cold compile split between this process and a forked
helper gives the kernels a compile in one process gives, bit for bit; the helper never outlives
its compile, and where it may not run (a second thread, the variable, no cache) none is forked.

Every check runs in a real process of its own: a fork copies the process, and pytest's workers
run threads (the helper is never forked there, which is what the second test checks too).
"""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from rollingtop.integrate._compile_helper import ENV

from ..conftest import COMPILE_LISTENER, EXAMPLES, ROOT

#: The simulate command under a listener of numba's compile events: what this process compiled.
COUNTED = (
    COMPILE_LISTENER
    + r"""
from rollingtop.cli import main

try:
    main(sys.argv[1:])
except SystemExit:
    pass
print(json.dumps(compiled), file=sys.stderr)
"""
)


def simulate(cache, helper, *args):
    """``rollingtop simulate examples/smooth.toml --t-end 1 --json ARGS`` in a process with
    ``cache`` as numba's cache folder, the helper on or off: (summary, compiled names)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), ENV: "1" if helper else "0"}
    proc = subprocess.run(
        [sys.executable, "-c", COUNTED, "simulate", str(EXAMPLES / "smooth.toml")]
        + ["--t-end", "1", "--json", *args],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=ROOT,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    for name in ("wall_time_s", "compile_time_s"):
        summary["stats"].pop(name)
    return summary, json.loads(proc.stderr.splitlines()[-1])


#: Where a helper may run at all (``_compile_helper.eligible``: Linux, two CPUs).
HELPED = pytest.mark.skipif(
    not sys.platform.startswith("linux") or len(os.sched_getaffinity(0)) < 2,
    reason="the helper forks on Linux with two CPUs or more only",
)


@HELPED
def test_a_helped_cold_compile_gives_the_same_run_and_compiles_half_here(tmp_path):
    """From an empty cache, with and without the helper: the same summary bit for bit (and
    again when a second process loads the helped cache); with the helper this process compiles
    the stepper's loop and not the diagnostics (the helper's half, loaded from the
    cache), without it, everything."""
    # exact: one machine, the same sources; what differs is only which process compiled a
    # kernel (the claim under test is that this cannot change a bit)
    helped, compiled_helped = simulate(tmp_path / "helped", True)
    alone, compiled_alone = simulate(tmp_path / "alone", False)
    warm, compiled_warm = simulate(tmp_path / "helped", True)
    assert helped == alone == warm
    assert compiled_warm == []
    ours = "rollingtop._compiled.smooth."
    name = "dynamics.diagnostics"  # not called by the loop: the helper's alone
    assert ours + name in compiled_alone and ours + name not in compiled_helped
    assert compiled_helped.count(ours + "stepper.run_rows") == 1  # its types: the real call's


LIFECYCLE = r"""
import json, os, sys, threading, time
from rollingtop.integrate import _compile_helper as helper

out = {}
marker = sys.argv[1]


def write():
    with open(marker, "w") as f:
        f.write(str(os.getpid()))


def fail():
    print("not shown", file=sys.stderr)
    raise RuntimeError("the child's failure")


class Dispatcher:  # what eligible() reads of a numba dispatcher
    def __init__(self, cache):
        self._cache = cache


from numba.core.caching import NullCache

out["eligible"] = helper.eligible(Dispatcher(object()))
out["no_cache"] = helper.eligible(Dispatcher(NullCache()))
os.environ[helper.ENV] = "0"
out["off"] = helper.eligible(Dispatcher(object()))
del os.environ[helper.ENV]
stop = threading.Event()
thread = threading.Thread(target=stop.wait)
thread.start()
out["threads"] = helper.eligible(Dispatcher(object()))
stop.set()
thread.join()

helper.start("a", write)
out["running"] = helper.running("a")
helper.join("a")
out["joined"] = not helper.running("a")
out["child_pid"] = int(open(marker).read())
out["own_pid"] = os.getpid()

helper.start("b", fail)
helper.join("b")  # a failed child: nothing raised here

helper.start("c", lambda: time.sleep(60))
pid = helper._children["c"]
start = time.monotonic()
helper.stop("c")
out["stop_s"] = time.monotonic() - start
try:
    os.kill(pid, 0)
    out["stopped"] = False
except ProcessLookupError:
    out["stopped"] = True

helper.WAIT = 0.3
helper.start("d", lambda: time.sleep(60))
pid = helper._children["d"]
start = time.monotonic()
helper.join("d")  # past WAIT: stopped
out["join_s"] = time.monotonic() - start
try:
    os.kill(pid, 0)
    out["timed_out_stopped"] = False
except ProcessLookupError:
    out["timed_out_stopped"] = True
print(json.dumps(out))
"""

#: Seconds within which a stopped child is gone (SIGKILL and a wait).
STOPPED = 5.0


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the helper forks on Linux only")
def test_the_helper_runs_where_it_may_and_never_outlives_its_compile(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != ENV}
    proc = subprocess.run(
        [sys.executable, "-c", LIFECYCLE, str(tmp_path / "marker")],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""  # the child's output is not the parent's
    out = json.loads(proc.stdout)
    assert out["eligible"] is (len(os.sched_getaffinity(0)) >= 2)
    assert out["no_cache"] is False and out["off"] is False and out["threads"] is False
    assert out["running"] and out["joined"]
    assert out["child_pid"] != out["own_pid"]
    assert out["stopped"] and out["stop_s"] < STOPPED
    assert out["timed_out_stopped"] and 0.3 <= out["join_s"] < STOPPED


def processes(pattern):
    """The pids of the processes whose command line contains ``pattern``."""
    found = subprocess.run(["pgrep", "-f", pattern], capture_output=True, text=True, check=False)
    return found.stdout.split()


@HELPED
def test_ctrl_c_during_a_helped_compile_leaves_no_helper(tmp_path):
    """SIGINT to the command alone (not its group) while both halves compile: the command ends
    with status 130 and its helper is stopped, not left compiling."""
    scenario = tmp_path / "unique-name-for-pgrep.toml"
    scenario.write_text((EXAMPLES / "smooth.toml").read_text())
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    env.pop(ENV, None)
    proc = subprocess.Popen(
        [sys.executable, "-m", "rollingtop", "simulate", str(scenario), "--t-end", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=ROOT,
    )
    try:
        # the compile notice: both halves are compiling, in two processes of that command line
        assert "compiling" in proc.stderr.readline()
        time.sleep(1.0)
        assert len(processes(str(scenario))) == 2
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=60) == 130
        # one line, whenever the signal came (numba's compiler may drop its exception in a
        # callback from LLVM: rollingtop._signals raises it again, without a traceback)
        assert proc.stderr.read().splitlines() == [
            "rollingtop: error: interrupted by SIGINT; no output was written"
        ]
    finally:
        proc.kill()
        proc.wait()
    time.sleep(0.5)
    assert processes(str(scenario)) == []
