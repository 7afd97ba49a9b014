"""rollingtop._jit: a failed save of numba's cache is one warning, and the run goes on."""

import errno
import json
import os
import subprocess
import sys
import warnings

import pytest

from rollingtop import _jit

from .conftest import ROOT


def _raiser_in(filename):
    """A function raising ``OSError(EFBIG)`` from a frame whose source file is ``filename``."""
    namespace = {"OSError": OSError, "errno": errno}
    code = compile("def fail():\n    raise OSError(errno.EFBIG, 'File too large', '/c/k.nbc')\n",
                   filename, "exec")  # fmt: skip
    exec(code, namespace)
    return namespace["fail"]


NUMBA_CACHING = os.path.join("site-packages", "numba", "core", "caching.py")


def test_a_failed_cache_save_is_retried_and_reported_once(monkeypatch):
    monkeypatch.setattr(_jit, "_warned", False)
    fail = _raiser_in(NUMBA_CACHING)
    calls = []

    def compiled(x):  # stands for a dispatcher whose first two calls fail to save
        calls.append(x)
        if len(calls) <= 2:
            fail()
        return 2 * x

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert _jit.call(compiled, 21) == 42
        assert _jit.call(compiled, 1) == 2
    assert len(calls) == 4
    assert [type(w.message) for w in caught] == [_jit.CacheNotSaved]
    assert "/c/k.nbc" in str(caught[0].message) and "File too large" in str(caught[0].message)


def test_other_os_errors_propagate(monkeypatch):
    monkeypatch.setattr(_jit, "_warned", False)
    fail = _raiser_in(os.path.join("somewhere", "else.py"))

    def compiled():
        fail()

    with pytest.raises(OSError, match="File too large"):
        _jit.call(compiled)


def test_a_bounded_number_of_retries(monkeypatch):
    monkeypatch.setattr(_jit, "_warned", True)
    fail = _raiser_in(NUMBA_CACHING)
    calls = []

    def compiled():
        calls.append(1)
        fail()

    with pytest.raises(OSError):
        _jit.call(compiled)
    assert len(calls) == _jit.MAX_SAVE_FAILURES + 1


@pytest.mark.slow
def test_simulate_runs_when_numba_cannot_save_its_cache(tmp_path):
    """A real process under a file-size limit with an empty numba cache: every save fails
    (``EFBIG``); the command still succeeds, with one warning line."""
    script = (
        "import resource, signal, sys, runpy\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))\n"
        "sys.argv = ['rollingtop', 'simulate', 'examples/paper.toml', '--t-end', '0.1', '--json']\n"
        "runpy.run_module('rollingtop.cli', run_name='__main__')\n"
    )
    env = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=1200)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["t_end"] == 0.1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "compiled kernels not saved" in lines[0]
