"""numba's on-disk cache for rollingtop's kernels, keyed on every source compiled in.

numba's own ``cache=True`` stamps a cache entry with a hash of the function's *own* source file.
Everything numba compiles into the function besides -- the functions it calls from other modules,
their constants, a model's closed forms called through a dispatch module -- is not part of the
key: after an edit of a model, the cached stepper would go on running the old right-hand side,
bit for bit. numba has no option for this, but its cache is built from replaceable parts (a
*locator* says where entries live and what stamps them fresh); :class:`KernelCache` is numba's
:class:`~numba.core.caching.FunctionCache` with a locator of our own (numba's documented
extension point, ``numba.core.caching._CacheLocator``; the bound on numba in ``pyproject.toml``
keeps that internal interface fixed under the users).

**The key** (:func:`module_digest`): the source text of the function's module and of every
rollingtop module it reaches through its globals -- modules, functions, numba dispatchers,
classes, recursively -- with the value of every plain constant in their globals (numba freezes
a global's value into the machine code: ``HELD = True`` of a stepper copy, a layout size
imported by name), and the versions of rollingtop, numba, llvmlite, NumPy and Python. So an edit
of one model's module changes the key of that model's kernels only (and of the models that
call its functions); an edit of a shared compiled module or of the template changes every
model's.

**The place** (:func:`cache_root`): ``NUMBA_CACHE_DIR/rollingtop`` when numba's variable is set,
else ``__pycache__/kernels`` beside the package, else the user's cache folder -- numba's own
order -- with one folder per module under it (the locator of :func:`kernel_cache_class`): the
template's functions instantiated for two models (:mod:`rollingtop._compiled`) have the same
file, name and line, and never share an index. An entry whose stamp differs is not loaded,
and is overwritten by the next save (numba's behaviour). When no candidate can be written,
:func:`cache_root` returns ``None`` and the caller compiles without a cache
(:mod:`rollingtop._jit`, one notice).
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import os
import sys
import tempfile
from importlib import metadata
from pathlib import Path
from types import ModuleType
from typing import Any

__all__ = ["KernelCache", "cache_root", "candidates", "first_writable", "module_digest"]

#: The package whose modules are followed and hashed (others are covered by their versions).
PACKAGE = "rollingtop"
#: Attribute of an instantiated module (:mod:`rollingtop._compiled`) holding the text it was
#: executed from, hashed instead of its ``__file__`` (the template's).
SOURCE_ATTRIBUTE = "__rollingtop_source__"


def _ours(name: str) -> bool:
    return name == PACKAGE or name.startswith(PACKAGE + ".")


def _code_module(value: Any) -> str | None:
    """The rollingtop module whose code ``value`` (a global) brings in, if any: a module, a
    function, a numba dispatcher (its ``py_func``), a function not yet handed to numba
    (``rollingtop._jit._Deferred``: read without triggering its attribute hook), a class."""
    if isinstance(value, ModuleType):
        name = value.__name__
    elif type(value).__name__ == "_Deferred" and type(value).__module__ == "rollingtop._jit":
        name = object.__getattribute__(value, "func").__module__
    elif inspect.isfunction(value) or isinstance(value, type):
        name = getattr(value, "__module__", None) or ""
    elif callable(value):  # a numba dispatcher: its Python function
        name = getattr(getattr(value, "py_func", None), "__module__", None) or ""
    else:
        return None
    return name if _ours(name) else None


def _constant(value: Any) -> bytes | None:
    """The bytes of a plain constant numba could freeze into machine code (``None`` for
    anything else)."""
    import numpy as np

    if value is None or isinstance(value, int | float | complex | str | bytes):
        return f"{type(value).__name__}:{value!r}".encode()
    if isinstance(value, np.generic):
        return f"{value.dtype.str}:{value!r}".encode()
    if isinstance(value, np.ndarray):
        return f"{value.dtype.str}{value.shape}:".encode() + np.ascontiguousarray(value).tobytes()
    if isinstance(value, tuple):
        parts = [_constant(v) for v in value]
        if any(p is None for p in parts):
            return None
        return b"(" + b",".join(p for p in parts if p is not None) + b")"
    return None


def _source(module: ModuleType) -> bytes:
    text = getattr(module, SOURCE_ATTRIBUTE, None)
    if text is not None:
        return str(text).encode()
    path = getattr(module, "__file__", None)
    return Path(path).read_bytes() if path else b""


def _own_part(module: ModuleType) -> tuple[bytes, set[str]]:
    """One module's part of the key (its source, its constants) and the rollingtop modules its
    globals bring in."""
    digest = hashlib.sha256(_source(module))
    reached: set[str] = set()
    for name, value in sorted(vars(module).items()):
        if name.startswith("__"):
            continue
        constant = _constant(value)
        if constant is not None:
            digest.update(b"\0" + name.encode() + b"=" + constant)
            continue
        found = _code_module(value)
        if found is not None:
            reached.add(found)
        for cell in getattr(value, "__closure__", None) or ():  # a factory's captured values
            try:
                inner = _code_module(cell.cell_contents)
            except ValueError:  # an empty cell
                continue
            if inner is not None:
                reached.add(inner)
    return digest.digest(), reached


def closure(name: str) -> list[str]:
    """The rollingtop modules reached from module ``name`` through globals (itself included),
    sorted; each must be imported already."""
    seen = {name}
    todo = [name]
    while todo:
        _, reached = _own_part(sys.modules[todo.pop()])
        for other in sorted(reached - seen):
            if other in sys.modules:
                seen.add(other)
                todo.append(other)
    return sorted(seen)


def _versions() -> bytes:
    import llvmlite  # type: ignore[import-untyped]
    import numba
    import numpy

    try:
        ours = metadata.version(PACKAGE)
    except metadata.PackageNotFoundError:  # a source tree on PYTHONPATH
        ours = "source"
    parts = (ours, numba.__version__, llvmlite.__version__, numpy.__version__, sys.version)
    return "\0".join(parts).encode()


@functools.cache
def module_digest(name: str) -> str:
    """The stamp of the cache entries of module ``name``'s compiled functions: a SHA-256 of
    every source and constant compiled into them (module docstring), hex. Computed once per
    process, when a function of the module is first compiled or loaded (its globals complete)."""
    digest = hashlib.sha256(_versions())
    for other in closure(name):
        own, _ = _own_part(sys.modules[other])
        digest.update(b"\0" + other.encode() + b"\0" + own)
    return digest.hexdigest()


def candidates() -> list[Path]:
    """Where the cache may live, in order of preference (numba's own order): the folder of
    ``NUMBA_CACHE_DIR`` if set, ``__pycache__/kernels`` beside the package, the user's cache
    folder."""
    from numba.core import config
    from numba.misc.appdirs import AppDirs

    out = []
    chosen = getattr(config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR, as numba read it
    if chosen:
        out.append(Path(chosen) / PACKAGE)
    out.append(Path(__file__).resolve().parent / "__pycache__" / "kernels")
    user = AppDirs(appname="numba", appauthor=False)  # type: ignore[no-untyped-call]
    out.append(Path(user.user_cache_dir) / PACKAGE)
    return out


def first_writable(paths: list[Path]) -> tuple[Path | None, list[tuple[Path, OSError]]]:
    """The first of ``paths`` that exists or can be made, and can be written (a file made and
    removed there, as numba checks); with the failures met before it."""
    failures = []
    for path in paths:
        try:
            path.mkdir(parents=True, exist_ok=True)
            tempfile.TemporaryFile(dir=path).close()
        except OSError as exc:
            failures.append((path, exc))
            continue
        return path, failures
    return None, failures


_root: list[tuple[Path | None, list[tuple[Path, OSError]]]] = []


def cache_root() -> tuple[Path | None, list[tuple[Path, OSError]]]:
    """The cache's folder for this process (:func:`candidates`, :func:`first_writable`; chosen
    once) and the candidates that could not be written before it; ``None`` if none can."""
    if not _root:
        _root.append(first_writable(candidates()))
    return _root[0]


@functools.lru_cache(maxsize=1)
def kernel_cache_class() -> type:
    """:class:`KernelCache`, built on numba's classes when first needed (importing this module
    does not import numba)."""
    from numba.core import caching

    class Locator(caching._CacheLocator):
        """Entries of module ``M``'s functions in ``<root>/M``, stamped by
        :func:`module_digest`."""

        def __init__(self, py_func: Any, root: Path) -> None:
            self._module = py_func.__module__
            self._lineno = py_func.__code__.co_firstlineno
            self._path = root / self._module

        def ensure_cache_path(self) -> None:
            os.makedirs(self._path, exist_ok=True)

        def get_cache_path(self) -> str:
            return str(self._path)

        def get_source_stamp(self) -> str:
            return module_digest(self._module)

        def get_disambiguator(self) -> str:
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func: Any, py_file: str) -> Any:
            root, _ = cache_root()
            return None if root is None else cls(py_func, root)

    class Impl(caching.CompileResultCacheImpl):
        """numba's implementation with :class:`Locator` alone (numba's ``__init__`` would let
        ``NUMBA_CACHE_LOCATOR_CLASSES`` replace it)."""

        def __init__(self, py_func: Any) -> None:
            self._lineno = py_func.__code__.co_firstlineno
            locator = Locator.from_function(py_func, "")
            if locator is None:
                raise RuntimeError("no writable folder for rollingtop's compiled kernels")
            self._locator = locator
            fullname = f"{py_func.__module__.rsplit('.', 1)[-1]}.{py_func.__qualname__}"
            abiflags = getattr(sys, "abiflags", "")
            self._filename_base = self.get_filename_base(fullname, abiflags)  # type: ignore[no-untyped-call]

    class Cache(caching.FunctionCache):
        """numba's function cache with :class:`Locator`; the stamp is computed at the first
        load or save, when the module's globals are complete (numba's computes it when the
        dispatcher is made, in the middle of the module's execution)."""

        _impl_class = Impl

        def __init__(self, py_func: Any) -> None:
            self._name = repr(py_func)
            self._py_func = py_func
            self._impl = Impl(py_func)
            self._cache_path = self._impl.locator.get_cache_path()
            self._file: Any = None
            self.enable()  # type: ignore[no-untyped-call]

        @property  # numba's attribute, made when first read
        def _cache_file(self) -> Any:  # type: ignore[override]
            if self._file is None:
                self._file = caching.IndexDataCacheFile(  # type: ignore[no-untyped-call]
                    cache_path=self._cache_path,
                    filename_base=self._impl.filename_base,
                    source_stamp=self._impl.locator.get_source_stamp(),
                )
            return self._file

    return Cache


def KernelCache(py_func: Any) -> Any:  # noqa: N802 (stands for the class)
    """A numba cache for ``py_func`` keyed on every source compiled into it (module docstring);
    :func:`cache_root` must have found a folder."""
    return kernel_cache_class()(py_func)
