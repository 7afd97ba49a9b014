"""rollingtop._jit: a failed save of numba's cache is one warning, and the run goes on."""

import errno
import json
import os
import subprocess
import sys
import warnings

import pytest

from rollingtop import _jit
from rollingtop._compiled import GROUPS

from .conftest import ROOT


def _raiser_in(filename):
    """A function raising ``OSError(EFBIG)`` from a frame whose source file is ``filename``."""
    namespace = {"OSError": OSError, "errno": errno}
    code = compile("def fail():\n    raise OSError(errno.EFBIG, 'File too large', '/c/k.nbc')\n",
                   filename, "exec")  # fmt: skip
    exec(code, namespace)
    return namespace["fail"]


NUMBA_CACHING = os.path.join("site-packages", "numba", "core", "caching.py")


@pytest.fixture
def disabled(monkeypatch):
    """Record :func:`rollingtop._jit.disable_caching` instead of switching this test process's
    caches off (the rest of the suite needs them)."""
    told = []
    monkeypatch.setattr(_jit, "disable_caching", lambda: told.append(1))
    return told


def test_a_failed_cache_save_is_retried_and_reported_once(monkeypatch, disabled):
    monkeypatch.setattr(_jit._state, "warned", False)
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
    assert len(disabled) == 2  # each failure switches the caches off (the first one does it)
    assert [type(w.message) for w in caught] == [_jit.CacheNotSaved]
    assert "/c/k.nbc" in str(caught[0].message) and "File too large" in str(caught[0].message)


def test_other_os_errors_propagate(monkeypatch, disabled):
    monkeypatch.setattr(_jit._state, "warned", False)
    fail = _raiser_in(os.path.join("somewhere", "else.py"))

    def compiled():
        fail()

    with pytest.raises(OSError, match="File too large"):
        _jit.call(compiled)
    assert not disabled


def test_a_bounded_number_of_retries(monkeypatch, disabled):
    monkeypatch.setattr(_jit._state, "warned", True)
    fail = _raiser_in(NUMBA_CACHING)
    calls = []

    def compiled():
        calls.append(1)
        fail()

    with pytest.raises(OSError):
        _jit.call(compiled)
    assert len(calls) == _jit.MAX_SAVE_FAILURES + 1


def test_disable_caching_switches_every_dispatcher_to_no_cache():
    """In a fresh process: every dispatcher made by the decorators, before and after the call,
    holds numba's NullCache, and the announcement says that every run compiles."""
    script = (
        "from numba.core.caching import NullCache\n"
        "from rollingtop import _compiled, _jit\n"
        "before = _compiled.for_model('smooth').dynamics.rhs\n"
        "_jit.disable_caching()\n"
        "after = _compiled.for_model('rough').dynamics.rhs\n"
        "assert _jit.caching_disabled()\n"
        "assert all(isinstance(d._cache, NullCache) for d in _jit._DISPATCHERS)\n"
        "assert isinstance(before._cache, NullCache) and isinstance(after._cache, NullCache)\n"
        "print(_compiled.message('rough', 'integrator'))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "numba cannot save its cache: every run compiles them" in proc.stdout


def test_simulate_runs_when_numba_cannot_save_its_cache(tmp_path):
    """A real process under a file-size limit with an empty numba cache: every save fails
    (``EFBIG``); the command still succeeds, with the compile notice and one warning line, and
    costs at most one more compilation than a cold run (the caches are switched off at the first
    failure: before, each cached function of the chain cost one more compilation of its caller,
    two minutes in all). The smooth model alone is compiled (the quickest to compile: the
    failure path is the same for every model)."""
    script = (
        "import resource, signal, sys, runpy\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))\n"
        "sys.argv = ['rollingtop', 'simulate', 'examples/smooth.toml', '--t-end', '0.1',"
        " '--json']\n"
        "runpy.run_module('rollingtop.cli', run_name='__main__')\n"
    )
    env = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=1200)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["t_end"] == 0.1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 2, proc.stderr
    assert lines[0].startswith("rollingtop: compiling the smooth model's integrator kernels")
    assert "compiled kernels not saved" in lines[1]


def test_compiling_one_model_compiles_no_other(tmp_path):
    """A fresh process with an empty numba cache compiles one model's right-hand side: numba's
    cache then holds entries of that model's package and of the shared modules only, and no
    other model's package was even imported."""
    script = (
        "import sys, numpy as np\n"
        "from rollingtop import _compiled\n"
        "from rollingtop._jit import call\n"
        "from rollingtop._compiled._kernel import new_workspace\n"
        "from rollingtop._layout import WARMUP_PARAMS\n"
        "y = np.zeros(18); y[6:15] = (1, 0, 0, 0, 0.8, -0.6, 0, 0.6, 0.8)\n"
        "k = _compiled.for_model('rough')\n"
        "call(k.dynamics.rhs, k._dispatch.CODES[0], np.array(WARMUP_PARAMS), y, np.empty(18),"
        " call(new_workspace))\n"
        "print(sorted(m for m in sys.modules if m.startswith('rollingtop._compiled.')))\n"
    )
    cache = tmp_path / "cache"
    env = os.environ | {"NUMBA_CACHE_DIR": str(cache)}
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    packages = {g.package for g in GROUPS}
    imported = {m.split(".")[2] for m in eval(proc.stdout)} & packages
    assert imported == {"rough"}
    # the kernel cache: one folder per module (rollingtop._kernel_cache)
    modules = {p.parent.parent.name for p in cache.rglob("*.nbi")}  # <module>/<digest>/
    folders = {m.split(".")[2] for m in modules if m.startswith("rollingtop._compiled.")}
    assert "rough" in folders
    others = packages - {"rough"}
    assert not folders & others, folders
    assert not {m for m in modules if m.startswith("rollingtop.contact.")} - {
        "rollingtop.contact.rough",
        "rollingtop.contact._rows",
        "rollingtop.contact._closed",
    }


def test_importing_the_package_does_not_import_numba():
    """``import rollingtop`` (every public name, the ensemble's and the command line's modules
    among them) leaves numba unloaded: a command that runs no compiled code never pays for it
    (the ensemble's driver once imported the stop flag's module, which imports numba)."""
    code = (
        "import sys, rollingtop, rollingtop.cli, rollingtop.integrate.ensemble\n"
        "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] == 'numba')))\n"
    )
    proc = subprocess.run([sys.executable, "-c", "import json\n" + code], cwd=ROOT,
                          capture_output=True, text=True, timeout=120, check=True)  # fmt: skip
    assert json.loads(proc.stdout) == []
