"""SIGINT and SIGTERM as exceptions, so that a run stops cleanly wherever it is.

Python runs signal handlers only between bytecodes of the main thread; compiled loops therefore
return to Python now and then (see :mod:`rollingtop.integrate.driver` and
:mod:`rollingtop.integrate.ensemble`) for a handler installed here to take effect.
:func:`handle_signals` turns both signals into :class:`~rollingtop._errors.Interrupted`, a
``KeyboardInterrupt``: ``finally`` blocks and :func:`rollingtop.io.atomic_write` then remove
temporary files, and the command line reports one line and exits with ``128 + signum``.

Inside the block the handler raises :class:`Signalled`, a ``BaseException`` that is *not* a
``KeyboardInterrupt``, and the block turns it into :class:`Interrupted` on the way out. The
reason is click: its ``main`` catches every ``KeyboardInterrupt`` raised by a command, writes an
empty line to stderr and raises ``Abort`` instead, which would lose the signal's number (exit
130 for SIGTERM too) and add a line to the one-line error report.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType
from typing import NoReturn

from rollingtop._errors import Interrupted

__all__ = ["Signalled", "handle_signals"]

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Signalled(BaseException):
    """SIGINT or SIGTERM arrived inside :func:`handle_signals` (``signum`` says which); leaves
    the block as :class:`Interrupted`. Caught like any ``BaseException``, not as a
    ``KeyboardInterrupt``."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = int(signum)


def _raise(signum: int, frame: FrameType | None) -> NoReturn:
    raise Signalled(signum)


@contextlib.contextmanager
def handle_signals() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM stop the code that runs (by :class:`Signalled`),
    and the block raises :class:`Interrupted` (main thread only; elsewhere the block runs
    unchanged). The previous handlers are restored on exit."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _raise) for sig in SIGNALS}
    try:
        yield
    except Signalled as exc:
        raise Interrupted(exc.signum) from None
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
