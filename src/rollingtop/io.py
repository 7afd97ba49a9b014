"""Atomic file output: a failed or interrupted write never leaves a partial file behind."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from rollingtop._errors import OutputError

__all__ = ["atomic_write", "check_output_path"]


def check_output_path(path: str | os.PathLike, suffixes: Iterable[str]) -> Path:
    """Check, before any work, that ``path`` can be written; return it as a :class:`Path`.

    Raises
    ------
    OutputError
        Unknown suffix, missing or unwritable parent folder, or ``path`` is a folder.
    """
    path = Path(path)
    suffixes = tuple(suffixes)
    if path.suffix.lower() not in suffixes:
        raise OutputError(
            f"cannot write {str(path)!r}: unknown output format {path.suffix or '(none)'!r} "
            f"(use {' or '.join(suffixes)})"
        )
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise OutputError(f"cannot write {str(path)!r}: it is a folder")
    if not parent.is_dir():
        raise OutputError(f"cannot write {str(path)!r}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise OutputError(f"cannot write {str(path)!r}: permission denied")
    return path


def atomic_write(
    path: str | os.PathLike, write: Callable[[Path], None], *, keep_suffix: bool = False
) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it onto ``path``.

    The rename is atomic on POSIX file systems, so readers see either the old file or the
    complete new one. On any exception (``KeyboardInterrupt`` included) the temporary file is
    removed and the exception propagates. With ``keep_suffix`` the temporary name ends with
    ``path``'s suffix (for writers that infer the format from it, such as ffmpeg).
    """
    path = Path(path)
    suffix = f".tmp{path.suffix}" if keep_suffix else ".tmp"
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent or ".")
    os.close(fd)
    tmp = Path(tmp)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give what open() would
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    return path
