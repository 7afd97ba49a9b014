"""Atomic file output: a failed or interrupted write never leaves a partial file behind.

Every writer goes through a temporary file beside the target, renamed onto it only once it is
complete and flushed to disk. Data that can be built in memory (NetCDF, CSV) is written with
plain checked ``os.write`` calls (:func:`write_bytes_atomic`), so that a full disk, a file-size
limit or an I/O error is an ordinary :class:`WriteFailed` and never reaches a C library in the
middle of its own writes (HDF5 crashed the interpreter under ``ulimit -f``).

Within :func:`published_on_success` (every command of the command line runs in one), the
renames wait for the end of the block: a command that refuses its input or fails after it has
written a file leaves no file behind (a figure written before a later check refused the run, say).
Files that must survive a failure (the atlas's resumable chunks) are written ``now=True``.
"""

from __future__ import annotations

import codecs
import contextlib
import contextvars
import errno as _errno
import os
import signal
import stat
import subprocess
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TypeAlias

from rollingtop._errors import OutputError, short_path, short_repr

if TYPE_CHECKING:
    from _typeshed import ReadableBuffer
    from xarray import Dataset

__all__ = [
    "WriteFailed",
    "atomic_write",
    "check_output_path",
    "format_bytes",
    "netcdf_bytes",
    "published_on_success",
    "read_input_text",
    "write_bytes_atomic",
    "write_together",
]

#: A file name: a string or a path-like object.
PathArg: TypeAlias = str | os.PathLike[str]

#: Largest piece handed to one ``os.write`` call.
_CHUNK = 1 << 20

#: The renames :func:`published_on_success` holds back: ``(temporary, target)`` in write order.
_PENDING: contextvars.ContextVar[list[tuple[Path, Path]] | None] = contextvars.ContextVar(
    "rollingtop_pending_outputs", default=None
)


class WriteFailed(OSError):
    """An output file could not be written: disk full, file too large, I/O error, permission
    lost during the run. A runtime failure (the command line exits with status 1), not an input
    error; the target is left as it was and no temporary file remains."""

    def __init__(self, path: PathArg, errno: int | None, reason: str) -> None:
        super().__init__(errno, reason, os.fspath(path))

    def __str__(self) -> str:
        return f"cannot write {short_path(self.filename)}: {self.strerror}; no output was written"


def _reason(exc: BaseException) -> tuple[int | None, str]:
    """The errno and a short reason of a failed write."""
    code = getattr(exc, "errno", None)
    if isinstance(code, int) and code > 0:
        return code, os.strerror(code)
    if isinstance(exc, subprocess.CalledProcessError):
        if exc.returncode < 0:
            with contextlib.suppress(ValueError):
                sig = signal.Signals(-exc.returncode)
                why = signal.strsignal(sig) or ""
                return None, f"the encoder was stopped by {sig.name}" + (f" ({why})" if why else "")
        return None, f"the encoder exited with status {exc.returncode}"
    text = " ".join(str(exc).split()) or type(exc).__name__
    return None, text if len(text) <= 200 else text[:199] + "…"


def _write_error(exc: BaseException | None) -> BaseException | None:
    """The ``OSError`` (or failed encoder process) behind ``exc``, if any: a writer that fails
    while cleaning up after a failed write (matplotlib's PDF backend raises ``zlib.error``) still
    counts as a write failure."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, OSError | subprocess.CalledProcessError):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _ignore_sigxfsz() -> None:
    """Make a file-size limit an ``EFBIG`` error instead of a fatal signal (the Python
    interpreter already does this at start-up; an embedding application may not)."""
    sig = getattr(signal, "SIGXFSZ", None)
    if sig is None or threading.current_thread() is not threading.main_thread():
        return
    with contextlib.suppress(ValueError, OSError):
        if signal.getsignal(sig) == signal.SIG_DFL:
            signal.signal(sig, signal.SIG_IGN)


def check_output_path(path: PathArg, suffixes: Iterable[str]) -> Path:
    """Check, before any work, that ``path`` can be written; return it as a :class:`Path`.

    Raises
    ------
    OutputError
        Unknown suffix, missing or unwritable parent folder, or ``path`` is a folder.
    """
    path = Path(path)
    suffixes = tuple(suffixes)
    if path.suffix.lower() not in suffixes:
        given = short_repr(path.suffix) if path.suffix else repr("(none)")
        raise OutputError(
            f"cannot write {short_path(path)}: unknown output format {given} "
            f"(use {' or '.join(suffixes)})"
        )
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise OutputError(f"cannot write {short_path(path)}: it is a folder")
    if not parent.is_dir():
        raise OutputError(
            f"cannot write {short_path(path)}: folder {short_path(parent)} does not exist"
        )
    if not os.access(parent, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise OutputError(f"cannot write {short_path(path)}: permission denied")
    return path


def _new_temporary(path: Path, suffix: str) -> tuple[int, Path]:
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    except OSError as exc:
        raise WriteFailed(path, *_reason(exc)) from None
    return fd, Path(tmp)


@contextlib.contextmanager
def _temporary_beside(path: Path, suffix: str) -> Iterator[tuple[int, Path]]:
    """A new temporary file ``(fd, name)`` beside ``path``, removed if the block raises
    anything (``KeyboardInterrupt`` included). SIGXFSZ is ignored first, so that a file-size
    limit is an ``EFBIG`` error rather than the death of the process."""
    _ignore_sigxfsz()
    fd, tmp = _new_temporary(path, suffix)
    try:
        yield fd, tmp
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


def _flush(fd: int, data: memoryview | None = None) -> None:
    """Write ``data`` (if any) to ``fd`` with checked writes, give the file the permissions
    ``open()`` would, flush it to disk and close it (always)."""
    try:
        view = data if data is not None else memoryview(b"")
        while view:
            n = os.write(fd, view[:_CHUNK])
            if n <= 0:
                raise OSError(_errno.EIO, os.strerror(_errno.EIO))
            view = view[n:]
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)  # mkstemp creates 0600
        os.fsync(fd)
    finally:
        os.close(fd)


def _rename(tmp: Path, path: Path, *, now: bool = False) -> None:
    """Rename ``tmp`` onto ``path``, and make the rename durable where possible; within
    :func:`published_on_success` (unless ``now``), at the end of its block."""
    pending = None if now else _PENDING.get()
    if pending is not None:
        pending.append((tmp, path))
        return
    os.replace(tmp, path)
    with contextlib.suppress(OSError):
        dir_fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)


def _publish(
    fd: int, tmp: Path, path: Path, data: memoryview | None = None, *, now: bool = False
) -> None:
    """:func:`_flush` ``data`` into ``tmp`` (open as ``fd``), then :func:`_rename` it onto
    ``path``."""
    _flush(fd, data)
    _rename(tmp, path, now=now)


@contextlib.contextmanager
def published_on_success() -> Iterator[None]:
    """Hold back the renames of the files written in the block until it ends without an
    exception (``SystemExit(0)``, click's ``Exit(0)`` and an exception whose ``keeps_outputs``
    is true count as success: a run that finished but missed a claim); otherwise remove
    their temporary files, so that nothing the block wrote appears. Files written ``now=True``
    are not held. The writes are complete and flushed when made, so the renames at the end
    cannot fail for lack of space; a file written twice ends with the later content."""
    pending: list[tuple[Path, Path]] = []
    token = _PENDING.set(pending)
    ok = False
    try:
        yield
        ok = True
    except SystemExit as exc:
        ok = exc.code in (0, None)
        raise
    except BaseException as exc:
        # click's Exit(0), or a failure whose outputs are its evidence (``keeps_outputs``)
        ok = getattr(exc, "exit_code", None) == 0 or getattr(exc, "keeps_outputs", False)
        raise
    finally:
        _PENDING.reset(token)
        try:
            while ok and pending:
                tmp, path = pending[0]
                with _failures_named(path):
                    _rename(tmp, path)
                del pending[0]
        finally:  # not published (a failure, or a rename refused): no temporary file stays
            for tmp, _ in pending:
                with contextlib.suppress(OSError):
                    tmp.unlink()


@contextlib.contextmanager
def _failures_named(path: Path) -> Iterator[None]:
    """An ``OSError`` of a writer (or a failed encoder process) inside the block leaves as
    :class:`WriteFailed` naming ``path``; anything else passes unchanged."""
    try:
        yield
    except WriteFailed:
        raise
    except Exception as exc:
        cause = _write_error(exc)
        if cause is None:
            raise
        raise WriteFailed(path, *_reason(cause)) from None


def write_bytes_atomic(path: PathArg, data: ReadableBuffer, *, now: bool = False) -> Path:
    """Write the bytes ``data`` (any buffer) to ``path`` atomically; with ``now``, at once even
    within :func:`published_on_success`.

    Raises
    ------
    WriteFailed
        Any operating-system error on the way (``ENOSPC``, ``EFBIG``, ``EIO``, ``EACCES``...),
        naming ``path``; the temporary file is removed and ``path`` is unchanged.
    """
    path = Path(path)
    view = memoryview(data).cast("B")
    with _temporary_beside(path, ".tmp") as (fd, tmp):
        try:
            _publish(fd, tmp, path, view, now=now)
        except OSError as exc:
            raise WriteFailed(path, *_reason(exc)) from None
    return path


def atomic_write(
    path: PathArg, write: Callable[[Path], None], *, keep_suffix: bool = False
) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it onto ``path``.

    For writers that need a file name (matplotlib, ffmpeg); prefer :func:`write_bytes_atomic`
    for data built in memory. The rename is atomic on POSIX file systems, so readers see either
    the old file or the complete new one. On any exception (``KeyboardInterrupt`` included) the
    temporary file is removed; an ``OSError`` of the writer (or a failed encoder process) is
    raised as :class:`WriteFailed` naming ``path``, anything else propagates unchanged. With
    ``keep_suffix`` the temporary name ends with ``path``'s suffix (for writers that infer the
    format from it, such as ffmpeg).
    """
    path = Path(path)
    suffix = f".tmp{path.suffix}" if keep_suffix else ".tmp"
    with _temporary_beside(path, suffix) as (fd, tmp):
        os.close(fd)
        with _failures_named(path):
            write(tmp)
            _publish(os.open(tmp, os.O_RDONLY), tmp, path)
    return path


def write_together(files: Sequence[tuple[PathArg, Callable[[Path], None]]]) -> list[Path]:
    """Write several files all or none (a command's figure and its data, say): each
    ``write(tmp)`` fills a temporary file beside its path, flushed to disk; only when every one
    has succeeded are they renamed onto their paths. A failure removes every temporary file and
    leaves every path as it was (raised as :class:`WriteFailed` naming the file, as
    :func:`atomic_write` does)."""
    paths = [Path(p) for p, _ in files]
    with contextlib.ExitStack() as stack:
        temps = []
        for path, (_, write) in zip(paths, files, strict=True):
            fd, tmp = stack.enter_context(_temporary_beside(path, ".tmp"))
            os.close(fd)
            with _failures_named(path):
                write(tmp)
                _flush(os.open(tmp, os.O_RDONLY))
            temps.append(tmp)
        for tmp, path in zip(temps, paths, strict=True):
            with _failures_named(path):
                _rename(tmp, path)
    return paths


def netcdf_bytes(ds: Dataset) -> memoryview:
    """The NetCDF-4 file of the :class:`xarray.Dataset` ``ds`` (engine ``h5netcdf``), in memory.

    HDF5 then never writes to disk itself: the bytes go out through :func:`write_bytes_atomic`.
    """
    return memoryview(ds.to_netcdf(engine="h5netcdf"))


def format_bytes(n: float) -> str:
    """``n`` bytes in B, KiB, MiB, GiB, TiB or PiB, to one decimal (``"4.8 MiB"``)."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024:
            return f"{n:.1f}".removesuffix(".0") + f" {unit}"
        n /= 1024
    return f"{n:.1f}".removesuffix(".0") + " PiB"


_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def read_input_text(
    path: PathArg, what: str, limit: int, error: type[Exception] = ValueError
) -> str:
    """The UTF-8 text of the input file ``path`` (a scenario, a table), read safely.

    Only a regular file of at most ``limit`` bytes is read: a FIFO, a device such as
    ``/dev/zero`` or a folder is refused at once (the file is opened without blocking), and so
    is text that is not UTF-8 or starts with a byte-order mark (TOML and our CSV tables are
    plain UTF-8). Every refusal raises ``error`` with one line naming the file as ``what``.
    """
    path = Path(path)
    where = f"cannot read {what} {short_path(path)}"
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise error(f"{where}: {_reason(exc)[1]}") from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise error(f"{where}: it is a folder")
        if not stat.S_ISREG(info.st_mode):
            kind = next((name for test, name in _KINDS if test(info.st_mode)), "special")
            raise error(f"{where}: not a regular file (it is {kind})")
        if info.st_size > limit:
            raise error(
                f"{where}: it is {format_bytes(info.st_size)}, more than the "
                f"{format_bytes(limit)} an input file may have"
            )
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, limit + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:  # the file grew while read
            raise error(f"{where}: more than the {format_bytes(limit)} an input file may have")
    except OSError as exc:
        raise error(f"{where}: {_reason(exc)[1]}") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if data.startswith(codecs.BOM_UTF8):
        raise error(
            f"{where}: it starts with a UTF-8 byte-order mark (BOM); save it as UTF-8 without BOM"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{where}: not UTF-8 text (invalid byte at offset {exc.start})") from None
