"""Compile every kernel once, ahead of the first command that needs it.

The kernels are compiled by numba on first use and kept in numba's on-disk cache
(``cache=True``: ``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR`` when set), so only the
first run after an installation pays for the compilation (about half a minute on two cores).
:func:`warmup` pays it up front: for a container image, a cluster's workers, or before timing.

numba invalidates a cached function when its own source file changes, not when a function it
calls from another file does; installing rollingtop rewrites every file, so an installation never
runs stale code. An editable (development) checkout should keep its cache in a folder named by the
sources (the test suite does: the repository's root ``conftest.py``) or clear ``__pycache__``
after editing a kernel. Nothing here deletes files.
"""

from __future__ import annotations

import time
from collections.abc import Callable

#: The groups compiled by :func:`warmup`, in order, with what each serves.
GROUPS = {
    "integrator": "the DOP853 stepper, right-hand sides and projections of every model kernel",
    "ensemble": "the parallel ensemble kernel",
}


def warmup(progress: Callable[[str], None] | None = None) -> dict[str, float]:
    """Compile (or load from numba's cache) every compiled kernel of the package.

    Parameters
    ----------
    progress : callable, optional
        Called with the name of each group (:data:`GROUPS`) before it is compiled.

    Returns
    -------
    dict of str to float
        Seconds taken by each group; 0 for a group already compiled in this process.
    """
    from rollingtop.integrate.driver import compile_kernels
    from rollingtop.integrate.ensemble import compile_ensemble

    steps: dict[str, Callable[[], float]] = {
        "integrator": compile_kernels,
        "ensemble": compile_ensemble,
    }
    seconds = {}
    for name, step in steps.items():
        if progress is not None:
            progress(name)
        start = time.perf_counter()
        step()
        seconds[name] = time.perf_counter() - start
    return seconds
