"""The compiler options of rollingtop's numba kernels, defined once.

Every compiled function is cached on disk (``cache=True``, numba's supported mechanism; the
directory follows ``NUMBA_CACHE_DIR``), uses numpy's floating-point error model (a division by
zero gives ``inf``/``nan``, which the integrator reports, instead of raising) and allows only
fused multiply-add among the fast-math rewrites (``contract``: results stay within an ulp of
the written expression and do not depend on reassociation).

- :func:`kernel`: called at every stage of the integrator; compiled with ``_nrt=False``
  (numba's flag, used the same way in numba's own string kernels): with numba's reference
  counting on, every call increments and decrements each array argument's count atomically,
  which cost more than the arithmetic -- the whole stepper ran about twice as slow
  (``benchmarks/``). Such a function must not allocate or return arrays.
- :func:`inline`: a small helper inlined into its caller at numba's IR level.
- :func:`compiled`: a driver that may allocate (reference counting on), with extra options.

The decorators are typed (they return the function's own type), so that type checkers see the
Python signature of each kernel.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

from numba import njit as _numba_njit

F = TypeVar("F", bound=Callable[..., Any])

# numba's stubs do not know the private ``_nrt`` flag; the options are checked by numba itself
njit: Any = _numba_njit

#: Options shared by every compiled function of the package.
BASE_OPTIONS: dict[str, Any] = {"cache": True, "error_model": "numpy", "fastmath": {"contract"}}


def kernel(func: F) -> F:
    """Compile ``func`` as a stage kernel: no reference counting, no allocation."""
    return cast(F, njit(**BASE_OPTIONS, _nrt=False)(func))


def inline(func: F) -> F:
    """Compile ``func`` as a helper inlined into every compiled caller."""
    return cast(F, njit(**BASE_OPTIONS, inline="always")(func))


def compiled(**options: Any) -> Callable[[F], F]:
    """Compile a function that may allocate, with :data:`BASE_OPTIONS` and ``options``."""

    def decorate(func: F) -> F:
        return cast(F, njit(**{**BASE_OPTIONS, **options})(func))

    return decorate


class CacheNotSaved(UserWarning):
    """numba could not save a compiled kernel to its on-disk cache (full disk, file-size limit,
    permissions): the run goes on with the kernel compiled in memory."""


#: Most failed cache saves tolerated in one :func:`call` (each repetition compiles at least one
#: more function, which numba keeps in memory; the package has fewer compiled functions).
MAX_SAVE_FAILURES = 200
_warned = False

R = TypeVar("R")


def _from_numba_cache(exc: OSError) -> bool:
    """Whether ``exc`` was raised while numba saved its cache (``numba/core/caching.py``)."""
    tb = exc.__traceback__
    while tb is not None:
        path = Path(tb.tb_frame.f_code.co_filename)
        if path.name == "caching.py" and "numba" in path.parts:
            return True
        tb = tb.tb_next
    return False


def call(func: Callable[..., R], *args: Any) -> R:
    """Call the compiled ``func`` from Python, tolerating a failed save of numba's cache.

    numba compiles a function on first use, registers the machine code in memory, and only then
    saves it to its cache. An ``OSError`` from that save (``ENOSPC``, ``EFBIG`` under
    ``ulimit -f``, ``EACCES``) escapes from the call that triggered the compilation, although the
    code is ready: every command would fail on a full disk. numba has no option for this, so the
    call is repeated here (numba then finds the code in memory, or compiles the next function of
    the chain), and the failure is reported once, as a :class:`CacheNotSaved` warning. Only
    supported behaviour is relied on: the exception, and the function kept in memory.
    """
    global _warned
    for _ in range(MAX_SAVE_FAILURES):
        try:
            return func(*args)
        except OSError as exc:
            if not _from_numba_cache(exc):
                raise
            if not _warned:
                _warned = True
                where = exc.filename or "numba's cache folder"
                warnings.warn(
                    CacheNotSaved(
                        f"compiled kernels not saved to {where} ({exc.strerror or exc}): they "
                        "are compiled again in every run until it can be written"
                    ),
                    stacklevel=2,
                )
    return func(*args)
