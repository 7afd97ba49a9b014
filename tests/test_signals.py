"""SIGINT and SIGTERM stop a long run promptly when the output is not a terminal, and a
signal whose exception C code dropped still stops the command.

The command line runs in a subprocess with stdin from ``/dev/null`` and pipes for stdout and
stderr (no progress bar, so no progress callback): the compiled loops must return to Python on
their own for the signal handlers of :mod:`rollingtop._signals` to run. The signal is sent once
the integration is under way: once the process has used :data:`INTEGRATING_CPU_S` more CPU
time than a whole short run of the same command takes (start-up, kernel loading, output).
"""

import ctypes
import ctypes.util
import os
import resource
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import pytest

from rollingtop import _jit
from rollingtop._errors import Interrupted
from rollingtop._signals import handle_signals
from rollingtop.integrate.driver import compile_kernels
from rollingtop.integrate.ensemble import compile_ensemble

from .conftest import EXAMPLES

#: The tests of real processes, run until signalled (4 to 6 s each).
PROCESSES = [
    pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc"),
    pytest.mark.slow,
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


@PROCESSES[0]
@PROCESSES[1]
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


LIBC = ctypes.CDLL(ctypes.util.find_library("c"))
COMPARE = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int))


def sort_signalled(signum):
    """libc's qsort of 64 ints whose comparison (a Python callback, as LLVM calls numba back
    when it has emitted machine code) sends ``signum`` to this process once: the handler's
    exception is raised inside the callback, where ctypes prints and drops it; the sort goes
    on. The sorted values and how often the callback ran."""
    values = (ctypes.c_int * 64)(*range(64, 0, -1))
    calls = []

    def compare(a, b):
        calls.append(1)
        if len(calls) == 1:
            os.kill(os.getpid(), signum)  # its handler runs here and raises
        return a[0] - b[0]

    LIBC.qsort(values, len(values), ctypes.sizeof(ctypes.c_int), COMPARE(compare))
    return list(values), len(calls)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_dropped_by_c_code_stops_at_the_compiled_call(signum, monkeypatch):
    """The C code finishes (the signal's exception dropped, kept from ``sys.unraisablehook``:
    no traceback on stderr), and the call that ran it raises the signal: the block leaves as
    Interrupted of that signal; other unraisable exceptions still reach the hook."""
    dropped = []
    monkeypatch.setattr(sys, "unraisablehook", dropped.append)
    with pytest.raises(Interrupted) as info, handle_signals():
        sys.unraisablehook(types.SimpleNamespace(exc_value=ValueError("another")))
        _jit.call(sort_signalled, signum)
    assert info.value.signum == signum
    assert [type(d.exc_value).__name__ for d in dropped] == ["ValueError"]
    assert sys.unraisablehook == dropped.append  # restored


def test_a_signal_dropped_then_another_error_leaves_as_the_signal(monkeypatch):
    """numba's case: the dropped exception leaves the compile without its machine code, and the
    compile fails later (RuntimeError): the block reports the signal, not that failure."""
    monkeypatch.setattr(sys, "unraisablehook", lambda hook: None)

    def compile_without_its_object():
        values, calls = sort_signalled(signal.SIGINT)
        assert calls > 64
        assert values == sorted(values)  # the C code went on after the dropped exception
        raise RuntimeError("no compiled object yet")

    cleaned = []
    with pytest.raises(Interrupted) as info, handle_signals():
        try:
            _jit.call(compile_without_its_object)
        finally:  # cleanup that calls compiled code runs to its end
            cleaned.append(_jit.call(max, 2, 3))
            cleaned.append(True)
    assert info.value.signum == signal.SIGINT
    assert cleaned == [3, True]


def test_without_a_signal_errors_and_calls_pass_unchanged(monkeypatch):
    """No signal: an error leaves the block as itself; a call returns its value; a signal of an
    earlier block is forgotten."""
    monkeypatch.setattr(sys, "unraisablehook", lambda hook: None)
    with pytest.raises(Interrupted), handle_signals():
        sort_signalled(signal.SIGINT)
        raise RuntimeError
    with pytest.raises(RuntimeError, match="its own"), handle_signals():
        raise RuntimeError("its own")
    with handle_signals():
        assert _jit.call(max, 2, 3) == 3
