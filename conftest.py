"""Keep the test suite's numba cache in a folder named by the kernel sources.

numba invalidates a cached function when its own source file changes, not when a compiled
function it calls from another file does: in a development checkout, after an edit of a model's
kernel alone, the cached stepper would go on running the old right-hand side. numba's supported
remedy is the cache location, ``NUMBA_CACHE_DIR``: the suite sets it (unless it is set already)
to ``.numba-cache/<digest of every kernel source>`` before numba is imported, so an edit gives a
fresh cache, and it removes the folders of other digests (its own files, never the package's).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
from pathlib import Path

#: Subpackages whose modules are compiled into the kernels.
KERNEL_PACKAGES = ("_compiled", "contact")
CACHE_ROOT = Path(__file__).resolve().parent / ".numba-cache"


def _digest() -> str:
    spec = importlib.util.find_spec("rollingtop")  # finds the package without importing it
    assert spec is not None and spec.submodule_search_locations
    root = Path(next(iter(spec.submodule_search_locations)))
    digest = hashlib.sha256(str(root).encode())
    for package in KERNEL_PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
    for name in ("_jit.py", "_layout.py", "_types.py"):
        digest.update(name.encode() + b"\0" + (root / name).read_bytes())
    return digest.hexdigest()[:16]


if "NUMBA_CACHE_DIR" not in os.environ:
    _here = CACHE_ROOT / _digest()
    if CACHE_ROOT.is_dir():
        for old in CACHE_ROOT.iterdir():
            if old != _here:
                shutil.rmtree(old, ignore_errors=True)
    _here.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(_here)


def pytest_report_header(config: object) -> str:
    """Say where the compiled kernels are cached, and that a first run compiles them (the
    suite's first fixture compiles every model's, one process per package, before any dot)."""
    where = os.environ.get("NUMBA_CACHE_DIR")
    return (f"numba cache: {where} (a first run compiles every model's kernels into it before "
            "the first test, then the tests compile the rest)")  # fmt: skip
