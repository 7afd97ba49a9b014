"""Compile the kernels of some or all contact models once, ahead of the first command that needs
them.

Each model's kernels are compiled by numba on first use and kept in numba's on-disk cache
(``cache=True``: ``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR`` when set), so only the
first run after an installation pays for a model's compilation, and only for the models it runs
(:mod:`rollingtop._compiled`). :func:`warmup` pays it up front, for a container image, a
cluster's workers, or before timing: one process per model, in parallel, since each model's
kernels are independent (their own source files, their own cache entries).

numba invalidates a cached function when its own source file changes, not when a function it
calls from another file does; installing rollingtop rewrites every file, so an installation never
runs stale code. An editable (development) checkout should keep its cache in a folder named by the
sources (the test suite does: the repository's root ``conftest.py``) or clear ``__pycache__``
after editing a kernel. Nothing here deletes files.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence

from rollingtop.contact import MODELS, get_model

#: The groups compiled for each model by :func:`warmup`, in order, with what each serves.
GROUPS = {
    "integrator": "the right-hand side, projection, diagnostics and DOP853 stepper",
    "ensemble": "the parallel ensemble kernel",
}


def warm_model(model: str) -> dict[str, float]:
    """Compile (or load) ``model``'s groups of kernels (:data:`GROUPS`), its variants' too, in
    this process; the seconds each took."""
    from rollingtop.integrate.driver import compile_kernels
    from rollingtop.integrate.ensemble import compile_ensemble

    steps: dict[str, Callable[..., float]] = {
        "integrator": compile_kernels,
        "ensemble": compile_ensemble,
    }
    seconds = {}
    for name, step in steps.items():
        start = time.perf_counter()
        step(model, variants=True)
        seconds[name] = time.perf_counter() - start
    return seconds


def warmup(
    models: Sequence[str] | None = None,
    *,
    processes: int | None = None,
    progress: Callable[[str, dict[str, float]], None] | None = None,
) -> dict[str, dict[str, float]]:
    """Compile (or load from numba's cache) the kernels of ``models`` (default: every registered
    model), one process per model, ``processes`` at a time (default: the CPUs).

    Parameters
    ----------
    models : sequence of str, optional
        Names of registered models (:data:`rollingtop.contact.MODELS`).
    processes : int, optional
        Models compiled at once; 1 compiles them one after the other in this process.
    progress : callable, optional
        ``progress(model, seconds)`` as each model finishes.

    Returns
    -------
    dict of str to dict of str to float
        For each model, the seconds each group took (:data:`GROUPS`); 0 for a group already
        compiled in the process that ran it.
    """
    names = [get_model(m).name for m in (MODELS if models is None else models)]
    names = list(dict.fromkeys(names))
    workers = max(1, min(len(names), processes or os.cpu_count() or 1))
    out: dict[str, dict[str, float]] = {}
    if workers == 1:
        for name in names:
            out[name] = warm_model(name)
            if progress is not None:
                progress(name, out[name])
        return out
    import concurrent.futures  # here: every command imports this module, few run warmup
    import multiprocessing

    # spawn: a fresh interpreter per worker (no fork of a process holding numba's threads)
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=context) as pool:
        futures = {pool.submit(warm_model, name): name for name in names}
        for future in concurrent.futures.as_completed(futures):
            name = futures[future]
            out[name] = future.result()
            if progress is not None:
                progress(name, out[name])
    return {name: out[name] for name in names}
