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

**The key** (:func:`module_digest`): what numba reads when it compiles a function, for the
function's module and every rollingtop module reached from it through globals (modules,
functions, numba dispatchers and intrinsics, classes, the elements of tuples), recursively: the
bytecode of each function defined there (nested functions, default values and captured values
included; not its file or line numbers), and the value of every plain constant among the
globals (numba freezes a global's value into the machine code: ``HELD = True`` of a stepper
copy, a layout size imported by name, a compiler option), with the versions of rollingtop,
numba, llvmlite, NumPy and Python. Both are read from memory, not from files: a file edited
after the import cannot stamp the old code. So an edit of one model's module changes the key of
that model's kernels only (and of the models that call its functions); an edit of a shared
compiled module or of the template changes every model's. Each entry's index key also holds the
options the function is compiled with (:func:`options_key`: ``nogil``, ``fastmath``, ...): they
change its machine code, not its bytecode, and numba's own key leaves them out.

**The place** (:func:`cache_root`): ``NUMBA_CACHE_DIR/rollingtop`` when numba's variable is set,
else ``__pycache__/kernels`` beside the package, else the user's cache folder -- numba's own
order -- with a folder per module and, in it, per digest (the locator of
:func:`kernel_cache_class`): the template's functions instantiated for two models
(:mod:`rollingtop._compiled`) have the same file, name and line and never share an index, and
two versions of one module (an edit, two checkouts on one cache folder) never share a folder;
the newest :data:`KEEP_VERSIONS` of a module are kept. Data files are named by their key. When
no candidate can be written, :func:`cache_root` returns ``None`` and the caller compiles
without a cache (:mod:`rollingtop._jit`, one notice).
"""

from __future__ import annotations

import functools
import hashlib
import shutil
import sys
import tempfile
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from types import CodeType, FunctionType, ModuleType
from typing import Any

__all__ = [
    "KernelCache",
    "cache_root",
    "candidates",
    "closure",
    "explicit_folder",
    "first_writable",
    "module_digest",
    "options_key",
]

#: The package whose modules are followed and hashed (others are covered by their versions).
PACKAGE = "rollingtop"


def _ours(name: str) -> bool:
    return name == PACKAGE or name.startswith(PACKAGE + ".")


def _function(value: Any) -> FunctionType | None:
    """The Python function whose bytecode numba compiles for ``value`` (a global), if any: the
    function itself, a numba dispatcher's ``py_func``, a function not yet handed to numba
    (``rollingtop._jit._Deferred``, read without triggering its attribute hook), a numba
    intrinsic's code generator (``_defn``)."""
    if type(value).__name__ == "_Deferred" and type(value).__module__ == "rollingtop._jit":
        value = object.__getattribute__(value, "func")
    if isinstance(value, FunctionType):
        return value
    for attribute in ("py_func", "_defn"):
        inner = getattr(value, attribute, None) if callable(value) else None
        if isinstance(inner, FunctionType):
            return inner
    return None


def _modules_of(value: Any) -> set[str]:
    """The rollingtop modules a global that is no constant and no function brings in: a module,
    a class, a callable object, the elements of a tuple."""
    if isinstance(value, ModuleType):
        names = {value.__name__}
    elif isinstance(value, tuple):  # not a list or dict: numba compiles no mutable global
        return set().union(*(_modules_of(v) for v in value)) if value else set()
    elif isinstance(value, type) or callable(value):
        names = {getattr(value, "__module__", None) or ""}
    else:
        return set()
    return {n for n in names if _ours(n)}


def _constant(value: Any) -> bytes | None:
    """The bytes of a plain constant numba could freeze into machine code, or a compiler option
    (``None`` for anything else); independent of the process (sets sorted, no addresses)."""
    import numpy as np

    if value is None or isinstance(value, int | float | complex | str | bytes):
        return f"{type(value).__name__}:{value!r}".encode()
    if isinstance(value, np.generic):
        return f"{value.dtype.str}:{value!r}".encode()
    if isinstance(value, np.ndarray):
        if value.dtype.hasobject:
            return None
        return f"{value.dtype.str}{value.shape}:".encode() + np.ascontiguousarray(value).tobytes()
    if isinstance(value, tuple | list | set | frozenset):
        parts = [_constant(v) for v in value]
        if any(p is None for p in parts):
            return None
        items = [p for p in parts if p is not None]
        if isinstance(value, set | frozenset):
            items.sort()
        return f"{type(value).__name__}(".encode() + b",".join(items) + b")"
    if isinstance(value, dict):
        pairs = [(_constant(k), _constant(v)) for k, v in value.items()]
        if any(k is None or v is None for k, v in pairs):
            return None
        return b"dict(" + b",".join(sorted(k + b":" + v for k, v in pairs if k and v)) + b")"
    return None


def _code(code: CodeType) -> bytes:
    """A function's bytecode and what it names, nested functions included: not its file or line
    numbers (a comment added above it, or another checkout, keeps the key)."""
    parts = [
        code.co_code,
        repr((code.co_names, code.co_varnames, code.co_freevars, code.co_cellvars)).encode(),
        repr((code.co_argcount, code.co_posonlyargcount, code.co_kwonlyargcount)).encode(),
        repr(code.co_flags).encode(),
    ]
    for const in code.co_consts:
        if isinstance(const, CodeType):
            parts.append(_code(const))
        else:
            parts.append(_constant(const) or repr(type(const)).encode())
    return b"\0".join(parts)


#: :func:`_own_part` of each module, with the identities of the globals it was read from.
_parts: dict[str, tuple[tuple[tuple[str, int], ...], tuple[bytes, set[str]]]] = {}


def _own_part(module: ModuleType) -> tuple[bytes, set[str]]:
    """:func:`_read_part`, read again only when a global of the module changed (a reload, a
    monkeypatch): within a process too, the key follows the code numba would compile."""
    identity = tuple((k, id(v)) for k, v in vars(module).items() if not k.startswith("__"))
    known = _parts.get(module.__name__)
    if known is None or known[0] != identity:
        known = (identity, _read_part(module))
        _parts[module.__name__] = known
    return known[1]


def _read_part(module: ModuleType) -> tuple[bytes, set[str]]:
    """One module's part of the key and the other rollingtop modules its globals bring in.

    The part is what numba reads when it compiles a function of the module: the bytecode of
    the functions defined here (with their default values and the values they captured), and
    the value of every plain constant among the module's globals. Both are read from memory,
    not from the file, so a file edited after the import cannot stamp the old code."""
    digest = hashlib.sha256()
    reached: set[str] = set()
    for name, value in sorted(vars(module).items()):
        if name.startswith("__"):
            continue
        if isinstance(value, list | dict | set) and not name.isupper():
            continue  # a module's state (numba compiles no mutable global): not a constant
        constant = _constant(value)
        if constant is not None:
            digest.update(b"\0" + name.encode() + b"=" + constant)
            continue
        func = _function(value)
        if func is None:
            reached |= _modules_of(value)
            continue
        if func.__module__ != module.__name__:  # imported: its own module's part covers it
            if _ours(func.__module__):
                reached.add(func.__module__)
            continue
        digest.update(b"\0" + name.encode() + b":" + _code(func.__code__))
        digest.update(_constant(func.__defaults__) or b"")
        for cell in func.__closure__ or ():
            try:
                captured = cell.cell_contents
            except ValueError:  # an empty cell
                continue
            inner = _function(captured)
            if inner is not None:
                reached |= {inner.__module__} if _ours(inner.__module__) else set()
            else:
                digest.update(_constant(captured) or b"")
                reached |= _modules_of(captured)
    reached.discard(module.__name__)
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


def module_digest(name: str) -> str:
    """The stamp of the cache entries of module ``name``'s compiled functions: a SHA-256 of
    the bytecode and constants compiled into them (module docstring), hex. Computed when a
    function of the module is first compiled or loaded (its globals complete then)."""
    digest = hashlib.sha256(_versions())
    for other in closure(name):
        own, _ = _own_part(sys.modules[other])
        digest.update(b"\0" + other.encode() + b"\0" + own)
    return digest.hexdigest()


def explicit_folder() -> Path | None:
    """The cache folder the user chose (``NUMBA_CACHE_DIR/rollingtop``), if any."""
    from numba.core import config

    chosen = getattr(config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR, as numba read it
    return Path(chosen) / PACKAGE if chosen else None


def candidates() -> list[Path]:
    """Where the cache may live, in order of preference (numba's own order): the folder of
    ``NUMBA_CACHE_DIR`` if set, ``__pycache__/kernels`` beside the package, the user's cache
    folder."""
    from numba.misc.appdirs import AppDirs

    chosen = explicit_folder()
    out = [] if chosen is None else [chosen]
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


#: Versions of a module's entries kept side by side (its newest folders of digests): an edit
#: and its undo, or two checkouts sharing a folder, load instead of compiling again.
KEEP_VERSIONS = 4


def prune(module_folder: Path, keep: int = KEEP_VERSIONS) -> None:
    """Remove all but the ``keep`` most recently changed digest folders of a module's entries
    (a process still loading from one removed meanwhile misses, and compiles)."""
    try:
        folders = sorted(
            (p for p in module_folder.iterdir() if p.is_dir()),
            key=lambda p: p.stat().st_mtime,
            reverse=True,
        )
    except OSError:
        return
    for old in folders[keep:]:
        shutil.rmtree(old, ignore_errors=True)


@functools.lru_cache(maxsize=1)
def kernel_cache_class() -> type:
    """:class:`KernelCache`, built on numba's classes when first needed (importing this module
    does not import numba)."""
    from numba.core import caching

    class Locator(caching._CacheLocator):
        """Entries of module ``M``'s functions in ``<root>/M/<digest>``, stamped by the digest
        (:func:`module_digest`): two versions of a module never share a folder, so they never
        race on one index or its numbered data files."""

        def __init__(self, py_func: Any, root: Path) -> None:
            self._module = py_func.__module__
            self._lineno = py_func.__code__.co_firstlineno
            self._root = root

        def ensure_cache_path(self) -> None:
            path = Path(self.get_cache_path())
            if not path.is_dir():
                path.mkdir(parents=True, exist_ok=True)
                prune(path.parent)

        def get_cache_path(self) -> str:
            return str(self._root / self._module / module_digest(self._module)[:16])

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

    class File(caching.IndexDataCacheFile):
        """numba's index and data files, a data file named by its key (numba numbers them from
        the index it read, so two processes saving two signatures at once could leave the index
        pointing one at the other's machine code), written before the index names it."""

        def save(self, key: Any, data: Any) -> None:
            name = f"{self._index_name[:-4]}.{hashlib.sha256(repr(key).encode()).hexdigest()[:16]}"
            self._save_data(f"{name}.nbc", data)  # type: ignore[no-untyped-call]
            overloads = self._load_index()  # type: ignore[no-untyped-call]
            overloads[key] = f"{name}.nbc"
            self._save_index(overloads)  # type: ignore[no-untyped-call]

    class Cache(caching.FunctionCache):
        """numba's function cache with :class:`Locator` and :class:`File`; the folder and the
        stamp are computed at the first load or save, when the module's globals are complete
        (numba computes them when the dispatcher is made, in the middle of the module's
        execution). A dispatcher rebuilt from a pickle gets numba's own cache options, not this
        cache: rollingtop ships plain functions to its workers, which import the kernels."""

        _impl_class = Impl

        def __init__(self, py_func: Any, options: Mapping[str, Any] | None = None) -> None:
            self._name = repr(py_func)
            self._py_func = py_func
            self._options = options_key(options or {})
            self._impl = Impl(py_func)
            self._file: Any = None
            self.enable()  # type: ignore[no-untyped-call]

        def _index_key(self, sig: Any, codegen: Any) -> Any:
            """numba's key (the signature, the target, the function's bytecode) and the options
            it is compiled with (``nogil``, ``fastmath``, ...): they change the machine code but
            neither the bytecode nor the module's digest."""
            return (*super()._index_key(sig, codegen), self._options)  # type: ignore[no-untyped-call]

        @property
        def cache_path(self) -> str:
            return str(self._impl.locator.get_cache_path())

        @property  # numba's attribute, made when first read
        def _cache_file(self) -> Any:  # type: ignore[override]
            if self._file is None:
                self._file = File(  # type: ignore[no-untyped-call]
                    cache_path=self.cache_path,
                    filename_base=self._impl.filename_base,
                    source_stamp=self._impl.locator.get_source_stamp(),
                )
            return self._file

    return Cache


def options_key(options: Mapping[str, Any]) -> str:
    """The compile options as text that is the same in every process (a set's items sorted:
    a set of strings iterates in a per-process order)."""

    def plain(value: Any) -> Any:
        return sorted(map(repr, value)) if isinstance(value, set | frozenset) else value

    return repr(sorted((str(k), plain(v)) for k, v in options.items()))


def KernelCache(py_func: Any, options: Mapping[str, Any] | None = None) -> Any:  # noqa: N802
    """A numba cache for ``py_func`` compiled with ``options`` (the dispatcher's target
    options), keyed on every source compiled into it (module docstring) and on those options;
    :func:`cache_root` must have found a folder. (The name stands for the class.)"""
    return kernel_cache_class()(py_func, options)
