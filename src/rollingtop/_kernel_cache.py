"""Keep numba's on-disk cache of the compiled kernels in step with their sources.

numba invalidates a cached function when *its own* source file changes, not when a compiled
function it calls from another module does: after an edit of ``dynamics/_kernel.py`` alone, the
cached stepper of ``integrate/_dop853.py`` would go on running the old right-hand side, silently.
An installed copy is safe (installing rewrites every file, so every cache entry goes stale), but
an editable install is not. So on import a digest of every kernel source is compared with the
one stored beside the cache, and on a mismatch all cached kernels are dropped (they are
recompiled on first use, about 20 s).

numba offers no hook for this (its cache locators stamp one file each), hence this module.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

ROOT = Path(os.path.abspath(__file__)).parent  # as numba names the sources (not resolved)
#: Subpackages whose modules are compiled into (or frozen as constants into) the kernels.
KERNEL_PACKAGES = ("contact", "dynamics", "integrate")
STAMP_NAME = "rollingtop-kernels.sha256"


def sources_digest(root: Path = ROOT) -> str:
    """SHA-256 over the relative paths and contents of every kernel source file."""
    digest = hashlib.sha256()
    for package in KERNEL_PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            digest.update(path.relative_to(root).as_posix().encode())
            digest.update(b"\0")
            digest.update(path.read_bytes())
    return digest.hexdigest()


def numba_subpath(directory: Path) -> str:
    """The folder name numba gives a source folder's cache outside the source tree
    (``<folder name>_<sha1 of its absolute path>``), from numba itself."""
    from numba.core.caching import _CacheLocator

    return _CacheLocator.get_suitable_cache_subpath(os.path.join(directory, "module.py"))


def _cache_dirs(root: Path) -> list[Path]:
    """Where numba may keep the kernels' cache files: ``__pycache__`` beside each source,
    ``NUMBA_CACHE_DIR`` when that is set, or the user-wide cache when the tree is read-only."""
    sources = [root / package for package in KERNEL_PACKAGES]
    sources += [d for s in list(sources) for d in s.rglob("*") if d.is_dir()]
    sources = [d for d in sources if d.name != "__pycache__"]
    dirs = [d / "__pycache__" for d in sources]
    elsewhere = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        elsewhere.append(Path(os.environ["NUMBA_CACHE_DIR"]))
    from numba.misc.appdirs import AppDirs  # numba's own user-wide cache folder

    elsewhere.append(Path(AppDirs(appname="numba", appauthor=False).user_cache_dir))
    dirs += [base / numba_subpath(d) for base in elsewhere for d in sources]
    return dirs


def refresh(root: Path = ROOT) -> bool:
    """Drop the cached kernels if any kernel source changed since they were cached.

    Returns True when cache files were dropped. Never raises for file-system reasons (a
    read-only install leaves everything as it is: numba then keeps its cache elsewhere and an
    installed copy does not change).
    """
    try:
        digest = sources_digest(root)
        stamp = root / "__pycache__" / STAMP_NAME
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        dropped = False
        for directory in _cache_dirs(root):
            if directory.is_dir():
                for entry in directory.iterdir():
                    if entry.suffix in (".nbi", ".nbc"):
                        entry.unlink(missing_ok=True)
                        dropped = True
        stamp.parent.mkdir(exist_ok=True)
        tmp = stamp.with_name(f"{STAMP_NAME}.{os.getpid()}.tmp")
        tmp.write_text(digest + "\n")
        os.replace(tmp, stamp)
        return dropped
    except OSError:
        return False


class CacheNotSaved(UserWarning):
    """numba could not save a compiled kernel to its on-disk cache (full disk, file-size limit,
    permissions): the run goes on with the kernel compiled in memory."""


_warned = False


def _tolerate_unsavable_cache() -> None:
    """Make a failed write of numba's cache a warning instead of an error.

    numba compiles a kernel, registers it in memory, and only then saves it to disk; an
    ``OSError`` from that save (``ENOSPC``, ``EFBIG`` under ``ulimit -f``, ``EACCES``) escapes from
    the call that triggered the compilation, and every command would fail on a full disk although
    the kernel is ready. numba has no option for this (its guard forgives only spurious Windows
    errors), so its ``Cache.save_overload`` is wrapped here: the error is reported once as a
    :class:`CacheNotSaved` warning, the partial cache file numba may leave is its own to
    overwrite next time, and the kernel runs from memory.
    """
    from numba.core.caching import Cache

    original = Cache.save_overload
    if getattr(original, "_rollingtop_tolerant", False):
        return

    def save_overload(self, sig, data):
        global _warned
        try:
            original(self, sig, data)
        except OSError as exc:
            if not _warned:
                import warnings

                _warned = True
                where = exc.filename or getattr(self, "_cache_path", "numba's cache folder")
                warnings.warn(
                    CacheNotSaved(
                        f"compiled kernels not saved to {where} ({exc.strerror or exc}): they "
                        "are compiled again in every run until it can be written"
                    ),
                    stacklevel=2,
                )

    save_overload._rollingtop_tolerant = True
    Cache.save_overload = save_overload


refresh()  # on import of the package, before any kernel is loaded from the cache
_tolerate_unsavable_cache()
