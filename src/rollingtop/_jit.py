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

from collections.abc import Callable
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
