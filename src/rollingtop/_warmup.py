"""Compile the kernels of some or all contact models once, ahead of the first command that needs
them.

Each model's kernels are compiled by numba on first use and kept on disk
(:mod:`rollingtop._kernel_cache`: ``NUMBA_CACHE_DIR/rollingtop`` when set, else
``__pycache__/kernels`` beside the package), so only the first run pays for a model's
compilation, and only for the models it runs (:mod:`rollingtop._compiled`). :func:`warmup` pays
it up front, for a container image, a cluster's workers, or before timing: one process per
package, in parallel, since each model's kernels are independent (their own cache entries).

An entry is keyed on every source compiled into it, so an edit of a model, an upgrade
installed over an old cache, or a cache folder shared between checkouts never runs stale
machine code: what changed is compiled again. Nothing here deletes files.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence

from rollingtop._compiled import GROUPS as PACKAGES
from rollingtop._compiled import PACKAGE_SECONDS, Group
from rollingtop.contact import MODELS, get_model

#: The groups compiled for each model by :func:`warmup`, in order, with what each serves.
GROUPS = {
    "integrator": "the right-hand side, projection, diagnostics and DOP853 stepper",
    # the single run's loop since issue 35: nothing more to compile (the key stays for scripts)
    "ensemble": "the parallel ensembles' loop (the integrator's)",
}


def warm_package(package: str) -> dict[str, float]:
    """Compile (or load) the groups of kernels (:data:`GROUPS`) of one compiled package
    (:data:`rollingtop._compiled.GROUPS`: a model's own kernel, or its variants) in this
    process; the seconds each took."""
    from rollingtop.integrate.driver import compile_code
    from rollingtop.integrate.ensemble import compile_ensemble_code

    code = next(g.codes[0] for g in PACKAGES if g.package == package)
    steps: dict[str, Callable[[int], float]] = {
        "integrator": compile_code,
        "ensemble": compile_ensemble_code,
    }
    seconds = {}
    for name, step in steps.items():
        start = time.perf_counter()
        step(code)
        seconds[name] = time.perf_counter() - start
    return seconds


def warm_shared() -> float:
    """Compile (or load) the pieces of the stepper's loop that every package shares
    (:func:`rollingtop.integrate.driver.compile_shared`) in this process; seconds spent."""
    from rollingtop.integrate.driver import compile_shared

    start = time.perf_counter()
    compile_shared()
    return time.perf_counter() - start


def _no_compile_helper() -> None:
    """In a worker of :func:`warmup`: no helper process for a cold compile (the workers already
    fill the CPUs; :mod:`rollingtop.integrate._compile_helper`)."""
    from rollingtop.integrate._compile_helper import ENV

    os.environ[ENV] = "0"


def _sum(parts: list[dict[str, float]]) -> dict[str, float]:
    return {group: sum(p[group] for p in parts) for group in GROUPS}


def _packages(models: Sequence[str]) -> list[Group]:
    """The compiled packages of ``models``, the longest to compile first, by the seconds
    measured for each (:data:`PACKAGE_SECONDS`; a package not measured, a new model's, first of
    all). Handed out in this order, the last process to finish is not left with a long one
    alone."""
    chosen = [g for g in PACKAGES if g.model in models]
    return sorted(chosen, key=lambda g: -PACKAGE_SECONDS.get(g.package, float("inf")))


def warmup(
    models: Sequence[str] | None = None,
    *,
    processes: int | None = None,
    progress: Callable[[str, dict[str, float]], None] | None = None,
) -> dict[str, dict[str, float]]:
    """Compile (or load from numba's cache) the kernels of ``models`` (default: every registered
    model), one process per compiled package (a model's own kernel, its variants'), ``processes``
    at a time (default: the CPUs), the longest first.

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
    packages = _packages(names)
    workers = max(1, min(len(packages), processes or os.cpu_count() or 1))
    parts: dict[str, list[dict[str, float]]] = {name: [] for name in names}
    out: dict[str, dict[str, float]] = {}

    def finished(group: Group, seconds: dict[str, float]) -> None:
        parts[group.model].append(seconds)
        if len(parts[group.model]) == sum(g.model == group.model for g in packages):
            out[group.model] = _sum(parts[group.model])
            if progress is not None:
                progress(group.model, out[group.model])

    if workers == 1:
        for group in packages:
            finished(group, warm_package(group.package))
        return {name: out[name] for name in names}
    import concurrent.futures  # here: every command imports this module, few run warmup
    import multiprocessing

    # spawn: a fresh interpreter per worker (no fork of a process holding numba's threads)
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(
        workers, mp_context=context, initializer=_no_compile_helper
    ) as pool:
        # first, in one worker, the pieces every package's loop shares: the others' first
        # packages reach their loops after their right-hand sides, and find them saved
        shared = pool.submit(warm_shared)
        futures = {pool.submit(warm_package, g.package): g for g in packages}
        for future in concurrent.futures.as_completed(futures):
            finished(futures[future], future.result())
        shared.result()
    return {name: out[name] for name in names}
