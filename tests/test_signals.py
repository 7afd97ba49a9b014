"""SIGINT and SIGTERM stop a long run promptly when the output is not a terminal.

The command line runs in a subprocess with stdin from ``/dev/null`` and pipes for stdout and
stderr (no progress bar, so no progress callback): the compiled loops must return to Python on
their own for the signal handlers of :mod:`rollingtop._signals` to run. The signal is sent once
the integration is under way: once the process has used :data:`INTEGRATING_CPU_S` more CPU
time than a whole short run of the same command takes (start-up, kernel loading, output).
"""

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rollingtop.integrate.driver import compile_kernels
from rollingtop.integrate.ensemble import compile_ensemble

from .conftest import EXAMPLES

pytestmark = [
    pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc"),
    pytest.mark.slow,  # real processes run until signalled: 4 to 6 s each
]

#: Seconds from the signal to the exit of the process (the compiled loops return to Python
#: every few tens of milliseconds; the rest is the interpreter's shutdown).
STOP_WITHIN_S = 3.0
#: CPU seconds past a short run's whole cost after which the long run is surely integrating.
INTEGRATING_CPU_S = 0.5
#: Give up waiting for the long run to start after this many seconds.
START_TIMEOUT_S = 60.0

PAPER = str(EXAMPLES / "paper.toml")
COMMANDS = {
    "simulate": ["simulate", PAPER],
    "ensemble": ["ensemble", PAPER, "--grid", "omega3=1.5:2.5:2,v_tau=-0.2:0.2:2"],
}


def cli(args, cwd):
    return subprocess.Popen(
        [sys.executable, "-m", "rollingtop.cli", *args],
        cwd=cwd,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a running process (all its threads), from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.fixture(scope="module")
def startup_cpu(tmp_path_factory):
    """CPU seconds of a whole short run of each command (the kernels' cache warmed first)."""
    compile_kernels("meridian")
    compile_ensemble("meridian")
    cost = {}
    for name, args in COMMANDS.items():
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        proc = cli([*args, "--t-end", "1"], tmp_path_factory.mktemp(name))
        _, err = proc.communicate(timeout=START_TIMEOUT_S)
        assert proc.returncode == 0, err
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cost[name] = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return cost


@pytest.mark.parametrize(("signum", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_signal_stops_a_long_run(tmp_path, startup_cpu, command, signum, status):
    proc = cli([*COMMANDS[command], "--t-end", "1e7", "-o", "out.nc"], tmp_path)
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while cpu_seconds(proc.pid) < startup_cpu[command] + INTEGRATING_CPU_S:
            assert proc.poll() is None, proc.communicate()[1]
            assert time.monotonic() < deadline, "the run did not start"
            time.sleep(0.05)
        sent = time.monotonic()
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=STOP_WITHIN_S + 30)
        stopped_after = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    name = signal.Signals(signum).name
    assert proc.returncode == status, err
    assert err.splitlines() == [f"rollingtop: error: interrupted by {name}; no output was written"]
    assert stopped_after < STOP_WITHIN_S
    assert list(tmp_path.iterdir()) == []  # neither out.nc nor a temporary file
