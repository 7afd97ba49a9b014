"""Atomic output and safe input reading (rollingtop.io): a failed write leaves nothing behind and
is one WriteFailed naming the file; an input that is not a small regular UTF-8 file is refused."""

import errno
import os
import stat
import subprocess
import zlib

import pytest

from rollingtop import io as rio
from rollingtop.io import WriteFailed, atomic_write, read_input_text, write_bytes_atomic

from .conftest import quoted_path


def listing(folder):
    return sorted(p.name for p in folder.iterdir())


def test_bytes_written_whole_with_open_permissions(tmp_path):
    target = tmp_path / "out.bin"
    data = bytes(range(256)) * 10_000  # several os.write chunks
    write_bytes_atomic(target, memoryview(data))
    assert target.read_bytes() == data
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert listing(tmp_path) == ["out.bin"]


def test_short_writes_are_continued(tmp_path, monkeypatch):
    real = os.write
    monkeypatch.setattr(os, "write", lambda fd, data: real(fd, bytes(data[:3])))
    write_bytes_atomic(tmp_path / "out.bin", b"0123456789")
    assert (tmp_path / "out.bin").read_bytes() == b"0123456789"


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EIO, errno.EFBIG, errno.EDQUOT])
def test_failed_write_is_one_error_and_leaves_nothing(tmp_path, monkeypatch, code):
    target = tmp_path / "out.nc"
    target.write_bytes(b"previous")
    real = os.write

    def failing(fd, data):
        real(fd, bytes(data[:5]))  # a part goes out first
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(os, "write", failing)
    with pytest.raises(WriteFailed) as exc:
        write_bytes_atomic(target, b"new content")
    assert str(exc.value) == (
        f"cannot write {quoted_path(target)}: {os.strerror(code)}; no output was written"
    )
    assert exc.value.errno == code and exc.value.filename == str(target)
    assert target.read_bytes() == b"previous"
    assert listing(tmp_path) == ["out.nc"]


@pytest.mark.parametrize("step", ["fsync", "replace", "mkstemp"])
def test_failures_around_the_write_are_mapped(tmp_path, monkeypatch, step):
    def fail(*args, **kwargs):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))

    if step == "mkstemp":
        monkeypatch.setattr(rio.tempfile, "mkstemp", fail)
    else:
        monkeypatch.setattr(os, step, fail)
    with pytest.raises(WriteFailed, match="Permission denied; no output was written"):
        write_bytes_atomic(tmp_path / "out.csv", b"a,b\n")
    assert listing(tmp_path) == []


def test_interrupt_during_write_removes_the_temporary(tmp_path, monkeypatch):
    def interrupted(fd, data):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "write", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_bytes_atomic(tmp_path / "out.nc", b"x" * 100)
    assert listing(tmp_path) == []


@pytest.mark.parametrize(
    ("raised", "reason"),
    [
        (OSError(errno.ENOSPC, "No space left on device"), os.strerror(errno.ENOSPC)),
        (subprocess.CalledProcessError(255, ["ffmpeg"]), "the encoder exited with status 255"),
    ],
)
def test_writer_callback_failure(tmp_path, raised, reason):
    def write(tmp):
        tmp.write_bytes(b"partial")
        raise raised

    with pytest.raises(WriteFailed, match=reason):
        atomic_write(tmp_path / "fig.png", write)
    assert listing(tmp_path) == []


def test_writer_failing_in_its_cleanup_is_still_a_write_failure(tmp_path):
    """matplotlib's PDF backend raises zlib.error while closing after a failed write."""

    def write(tmp):
        try:
            raise OSError(errno.EFBIG, os.strerror(errno.EFBIG))
        except OSError:
            raise zlib.error("Error -2 while flushing: inconsistent stream state") from None

    with pytest.raises(WriteFailed, match="File too large"):
        atomic_write(tmp_path / "fig.pdf", write)
    assert listing(tmp_path) == []


def test_writer_bug_propagates_unchanged(tmp_path):
    def write(tmp):
        raise ZeroDivisionError("a bug, not a write failure")

    with pytest.raises(ZeroDivisionError):
        atomic_write(tmp_path / "fig.png", write)
    assert listing(tmp_path) == []


# ---- reading inputs ---------------------------------------------------------------------------


def read(path, limit=1 << 20):
    return read_input_text(path, "scenario", limit, ValueError)


def test_reads_utf8_text(tmp_path):
    (tmp_path / "s.toml").write_text("a = 'é'\n", encoding="utf-8")
    assert read(tmp_path / "s.toml") == "a = 'é'\n"


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"\xef\xbb\xbfa = 1\n", "byte-order mark"),
        (b"a = '\xff'\n", "not UTF-8 text"),
        (b"x" * 2000, "it is 2 KiB, more than the 1000 B an input file may have"),
    ],
    ids=["bom", "latin1", "large"],
)
def test_refused_content(tmp_path, content, message):
    (tmp_path / "s.toml").write_bytes(content)
    with pytest.raises(ValueError, match=message) as exc:
        read(tmp_path / "s.toml", limit=1000)
    assert str(exc.value).startswith(f"cannot read scenario {quoted_path(tmp_path / 's.toml')}: ")


def test_fifo_device_and_folder_refused_without_blocking(tmp_path):
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)  # nobody writes to it: a blocking open or read would hang
    with pytest.raises(ValueError, match="not a regular file .it is a FIFO."):
        read(fifo)
    with pytest.raises(ValueError, match="not a regular file .it is a character device."):
        read("/dev/zero")
    with pytest.raises(ValueError, match="it is a folder"):
        read(tmp_path)
    with pytest.raises(ValueError, match="No such file or directory"):
        read(tmp_path / "absent.toml")
