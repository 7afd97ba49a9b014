"""The compiler options of rollingtop's numba kernels, defined once.

Every compiled function is cached on disk, keyed on every source compiled into it
(:mod:`rollingtop._kernel_cache`: numba's own ``cache=True`` keys it on the function's file
alone; the folder follows ``NUMBA_CACHE_DIR``), uses numpy's floating-point error model (a
division by zero gives ``inf``/``nan``, which the integrator reports, instead of raising) and
allows only fused multiply-add among the fast-math rewrites (``contract``: results stay within
an ulp of the written expression and do not depend on reassociation).

- :func:`kernel`: called at every stage of the integrator; compiled with ``_nrt=False``
  (numba's flag, used the same way in numba's own string kernels): with numba's reference
  counting on, every call increments and decrements each array argument's count atomically,
  which cost more than the arithmetic -- the whole stepper ran about twice as slow
  (``benchmarks/``). Such a function must not allocate or return arrays.
- :func:`inline`: a small helper that LLVM inlines into its compiled callers.
- :func:`spliced`: a function typed as part of its one compiled caller.
- :func:`compiled`: a driver that may allocate (reference counting on), with extra options.

The decorators are typed (they return the function's own type), so that type checkers see the
Python signature of each kernel. They defer numba itself: a decorated function is recorded,
and the first call of any (or :func:`load_numba`, which :func:`rollingtop._compiled.for_code`
calls) imports numba and makes them all dispatchers, in place (:class:`_Deferred`).
"""

from __future__ import annotations

import sys
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar, cast

from rollingtop import _kernel_cache, _signals

F = TypeVar("F", bound=Callable[..., Any])

#: Options shared by every compiled function of the package (``cache``: the cache of
#: :mod:`rollingtop._kernel_cache`, not numba's own).
BASE_OPTIONS: dict[str, Any] = {"cache": True, "error_model": "numpy", "fastmath": {"contract"}}


@dataclass
class _State:
    """What this module learns while the process runs. Kept out of plain module globals: the
    cache key hashes the constants of every module compiled in, and these are no constants."""

    numba_loaded: bool = False
    #: every cache of the package switched off (:func:`disable_caching`)
    caching_off: bool = False
    #: the one warning about saving the cache given
    warned: bool = False
    #: the one notice that NUMBA_CACHE_DIR cannot be written given
    told_moved: bool = False


_state = _State()


#: Every dispatcher made by the decorators below (their caches are switched off together when
#: numba cannot save them, :func:`call`).
_DISPATCHERS: list[Any] = []


def _registered(dispatcher: Any) -> Any:
    _DISPATCHERS.append(dispatcher)
    if _state.caching_off:
        _disable_cache(dispatcher)
    return dispatcher


def _njit(func: Callable[..., Any], options: dict[str, Any]) -> Any:
    """numba's dispatcher of ``func``; with ``cache``, the cache of
    :mod:`rollingtop._kernel_cache` (keyed on every source compiled in) instead of numba's."""
    from numba import njit

    dispatcher = njit(**{**options, "cache": False})(func)
    if options.get("cache") and not _state.caching_off:
        root, failures = _kernel_cache.cache_root()
        if root is None:
            _no_cache_folder(failures)
        else:
            chosen = _kernel_cache.explicit_folder()
            failed = dict(failures)
            # numba's order falls back silently from a read-only installation's folder; a
            # folder the user chose (NUMBA_CACHE_DIR) that cannot be written is said, once
            if chosen in failed and not _state.told_moved:
                _state.told_moved = True
                exc = failed[chosen]
                warnings.warn(
                    CacheNotSaved(
                        f"cannot write {chosen} ({exc.strerror or exc}): compiled kernels are "
                        f"cached in {root} instead"
                    ),
                    stacklevel=4,
                )
            dispatcher._cache = _kernel_cache.KernelCache(func, dispatcher.targetoptions)
    return _registered(dispatcher)


def _no_cache_folder(failures: list[tuple[Path, OSError]]) -> None:
    """No cache folder can be written: caching off, said once."""
    _state.caching_off = True
    if not _state.warned:
        _state.warned = True
        tried = "; ".join(f"{p}: {e.strerror or e}" for p, e in failures)
        warnings.warn(
            CacheNotSaved(
                f"no folder for compiled kernels can be written ({tried}): they are compiled "
                "again in every run"
            ),
            stacklevel=5,
        )


class _Deferred:
    """A function of the package not yet handed to numba.

    Importing numba takes a sixth of a second, and numba's first use of its NumPy support more:
    the commands that need no compiled code (a portrait, the reduction, ``--help``) should not
    pay for it. So the decorators below only record their function while numba is not loaded;
    the first call of any of them (or a look at a dispatcher's attributes) loads numba, makes
    every recorded function a dispatcher, and puts the dispatchers where the deferred functions
    were in the package's modules -- where numba, compiling a caller, looks its callees up.
    """

    __slots__ = ("dispatcher", "func", "options")

    def __init__(self, func: Callable[..., Any], options: dict[str, Any]) -> None:
        self.func = func
        self.options = options
        self.dispatcher: Any = None

    def _real(self) -> Any:
        if self.dispatcher is None:
            load_numba()
        return self.dispatcher

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._real()(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._real(), name)


_pending: list[_Deferred] = []
_load_lock = threading.RLock()


def load_numba() -> None:
    """Load numba and make every function of the package that the decorators recorded a numba
    dispatcher, in place in the package's modules (see :class:`_Deferred`); done once."""
    with _load_lock:
        if _state.numba_loaded:
            return
        _answer_blas_probe()
        for deferred in _pending:
            deferred.dispatcher = _njit(deferred.func, deferred.options)
        _state.numba_loaded = True
        for name, module in list(sys.modules.items()):
            if module is None or not (name == "rollingtop" or name.startswith("rollingtop.")):
                continue
            for attr, value in list(vars(module).items()):
                if type(value) is _Deferred:
                    setattr(module, attr, value.dispatcher)
        _pending.clear()


def _answer_blas_probe() -> None:
    """Import numba's array support with its probe for BLAS answered from scipy's presence.

    ``numba.np.arraymath``, which numba imports before it compiles or loads anything, probes
    for BLAS by importing ``scipy.linalg`` (a quarter of a second of every process that runs a
    kernel); no kernel of ours calls BLAS, and scipy, a dependency, provides it. So for that one
    import the probe (``numba.np.linalg.ensure_blas``) only checks that scipy is installed;
    the real one is put back for everything after it (numba's calls of BLAS check again when
    they are compiled)."""
    import importlib.util

    if "numba.np.arraymath" in sys.modules or importlib.util.find_spec("scipy") is None:
        return
    from numba.np import linalg

    probe = linalg.ensure_blas
    linalg.ensure_blas = lambda: None
    try:
        from numba.np import arraymath
    finally:
        linalg.ensure_blas = probe
    setattr(arraymath, "ensure_blas", probe)  # noqa: B010 (not an exported name)


def _make(func: F, options: dict[str, Any]) -> F:
    if _state.numba_loaded:  # a module imported after numba: its dispatcher at once
        return cast(F, _njit(func, options))
    deferred = _Deferred(func, options)
    _pending.append(deferred)
    return cast(F, deferred)


def kernel(func: F) -> F:
    """Compile ``func`` as a stage kernel: no reference counting, no allocation."""
    return _make(func, {**BASE_OPTIONS, "_nrt": False})


def loop(func: F) -> F:
    """Compile ``func`` as a stage kernel (:func:`kernel`) that Python calls to run a long loop
    (a chunk of steps): it releases the GIL while it runs (``nogil``), so that the caller's
    other threads go on meanwhile (the explorer's event loop while a worker integrates)."""
    return _make(func, {**BASE_OPTIONS, "_nrt": False, "nogil": True})


#: Options of :func:`inline`: a stage kernel's (no reference counting), LLVM's ``alwaysinline``
#: (numba's ``forceinline``), and no C-callable wrapper (none is used). The wrapper for calls
#: from Python stays: numba does not refuse a Python call of a function compiled without one,
#: it crashes.
INLINE_OPTIONS: dict[str, Any] = {
    **BASE_OPTIONS,
    "_nrt": False,
    "forceinline": True,
    "no_cfunc_wrapper": True,
}


def inline(func: F) -> F:
    """Compile ``func`` as a helper that LLVM inlines into every compiled caller.

    It is compiled once, as a function of its own, and inlined by LLVM (``alwaysinline``) where
    it is called: the caller's machine code is that of the function written out in place.
    numba's own inlining (``inline="always"``) gave the same code but ran the helper's front
    end, typing and lowering again at every call site, nested helpers once per path: 1.2 to
    2.9 s of each model's 8 to 11 s first compile (``docs/guide/development.md``, "Compiled
    code and its cache").
    Like a :func:`kernel` it must not allocate."""
    return _make(func, INLINE_OPTIONS)


def spliced(func: F) -> F:
    """Compile ``func`` into its compiled caller at numba's IR level (``inline="always"``):
    typed, lowered and optimised as part of it, with no machine code of its own. For a function
    called at one site (the stepper's loop in the rows it advances): a function of its own is
    optimised and emitted once more inside each caller, which cost a second of every model's
    first compile; where called at several sites, each types it again (:func:`inline` serves
    those). Called from Python, it compiles as a :func:`kernel`."""
    return _make(func, {**BASE_OPTIONS, "_nrt": False, "inline": "always"})


def compiled(**options: Any) -> Callable[[F], F]:
    """Compile a function that may allocate, with :data:`BASE_OPTIONS` and ``options``."""

    def decorate(func: F) -> F:
        return _make(func, {**BASE_OPTIONS, **options})

    return decorate


class CacheNotSaved(UserWarning):
    """numba could not save a compiled kernel to its on-disk cache (full disk, file-size limit,
    permissions): the run goes on with the kernel compiled in memory."""


#: Most failed cache saves tolerated in one :func:`call`: after the first, every cache of the
#: package is switched off, so a second failure would come from somewhere else.
MAX_SAVE_FAILURES = 3


def _disable_cache(dispatcher: Any) -> None:
    # numba's own "no cache" object, the one a dispatcher without ``cache=True`` holds
    from numba.core.caching import NullCache

    dispatcher._cache = NullCache()


def disable_caching() -> None:
    """Stop saving (and loading) compiled kernels to numba's on-disk cache in this process: every
    dispatcher of the package, those made from now on included."""
    _state.caching_off = True
    load_numba()
    for dispatcher in _DISPATCHERS:
        _disable_cache(dispatcher)


def caching_disabled() -> bool:
    """Whether :func:`disable_caching` was called (numba could not save its cache)."""
    return _state.caching_off


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
    code is ready: every command would fail on a full disk. numba has no option for this. So on
    the first such failure every cache of the package is switched off (:func:`disable_caching`:
    each dispatcher gets numba's ``NullCache``, what a function compiled without ``cache=True``
    has) and the call is repeated: the functions already compiled are kept in memory, the rest
    compile without trying to save. Repeating the call without that cost one more compilation of
    the caller per cached function of the chain (minutes). The failure is reported once, as a
    :class:`CacheNotSaved` warning.

    A SIGINT or SIGTERM whose exception was lost inside the call (numba's compiler runs Python
    callbacks from C, which drop exceptions) is raised once it returns
    (:func:`rollingtop._signals.raise_lost`).
    """
    try:
        result = _call_saving(func, *args)
    except BaseException:
        _signals.forget_lost()  # an exception is on its way: the block reports the signal
        raise
    _signals.raise_lost()
    return result


def _call_saving(func: Callable[..., R], *args: Any) -> R:
    """:func:`call` without its check for a lost signal."""
    for _ in range(MAX_SAVE_FAILURES):
        try:
            return func(*args)
        except OSError as exc:
            if not _from_numba_cache(exc):
                raise
            disable_caching()
            if not _state.warned:
                _state.warned = True
                where = exc.filename or "numba's cache folder"
                warnings.warn(
                    CacheNotSaved(
                        f"compiled kernels not saved to {where} ({exc.strerror or exc}): they "
                        "are compiled again in every run until it can be written"
                    ),
                    stacklevel=3,
                )
    return func(*args)
