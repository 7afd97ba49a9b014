"""Keep the test suite's compiled kernels in the repository's ``.numba-cache`` folder.

rollingtop's cache key covers every source compiled into a kernel
(:mod:`rollingtop._kernel_cache`), so an edit of a model or of the compiled core recompiles what
it changes, whatever the folder. The suite keeps its entries in a folder of the checkout (unless
``NUMBA_CACHE_DIR`` is set already) so that it neither reads nor fills the caches of an
installation; the tests that exercise the cache itself use folders of their own.
"""

from __future__ import annotations

import os
from pathlib import Path

CACHE = Path(__file__).resolve().parent / ".numba-cache"

if "NUMBA_CACHE_DIR" not in os.environ:
    CACHE.mkdir(exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(CACHE)


def pytest_report_header(config: object) -> str:
    """Say where the compiled kernels are cached, and that a first run compiles them (the
    suite's first fixture compiles every model's, one process per package, before any dot)."""
    where = os.environ.get("NUMBA_CACHE_DIR")
    return (
        f"numba cache: {where} (a first run compiles every model's kernels into it before "
        "the first test, then the tests compile the rest)"
    )
