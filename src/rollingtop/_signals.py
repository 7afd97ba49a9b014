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

A handler's exception can be lost: where the signal arrives while Python runs a callback of C
code (numba's compiler is called back by LLVM when it has emitted a module's machine code),
``ctypes`` prints the exception and drops it, and the C code goes on. numba then fails later
(``RuntimeError: no compiled object yet``) or, with its cache off, finishes the compile and
the run goes on as though no signal had come. So the handler also records the signal, and the
block turns any exception that leaves it after a signal into :class:`Interrupted`. The block's
``sys.unraisablehook`` (where a dropped exception goes) records a dropped :class:`Signalled`
and keeps it quiet (its traceback is not the one-line report; others pass to the hook it
replaced), and :func:`raise_lost` (called after each compiled call,
:func:`rollingtop._jit.call`) raises it once.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from types import FrameType
from typing import Any, NoReturn

from rollingtop._errors import Interrupted

__all__ = ["Signalled", "forget_lost", "handle_signals", "raise_lost"]

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Signalled(BaseException):
    """SIGINT or SIGTERM arrived inside :func:`handle_signals` (``signum`` says which); leaves
    the block as :class:`Interrupted`. Caught like any ``BaseException``, not as a
    ``KeyboardInterrupt``."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = int(signum)


#: The signals received inside the current block, in order (main thread only).
_received: list[int] = []
#: Those whose :class:`Signalled` was dropped in a callback and not raised again since.
_lost: list[int] = []


def _raise(signum: int, frame: FrameType | None) -> NoReturn:
    _received.append(int(signum))
    raise Signalled(signum)


def _quiet_dropped(previous: Any) -> Callable[[Any], None]:
    """An unraisable hook that records a dropped :class:`Signalled` for :func:`raise_lost`
    and hands any other exception to ``previous``."""

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, Signalled):
            _lost.append(unraisable.exc_value.signum)
        else:
            previous(unraisable)

    return hook


def raise_lost() -> None:
    """Raise :class:`Signalled` again for the first signal of the current block whose exception
    was dropped in a callback (see the module docstring), once; nothing where none was (outside
    a block, no signal, or one forgotten by :func:`forget_lost` because an exception followed:
    cleanup that calls compiled code in ``finally`` then runs on)."""
    if _lost:
        signum = _lost[0]
        _lost.clear()
        raise Signalled(signum)


def forget_lost() -> None:
    """Forget the dropped signals of the block: an exception that followed is on its way out,
    and the block reports the signal in its place."""
    _lost.clear()


@contextlib.contextmanager
def handle_signals() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM stop the code that runs (by :class:`Signalled`),
    and the block raises :class:`Interrupted` (main thread only; elsewhere the block runs
    unchanged). The previous handlers are restored on exit."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _raise) for sig in SIGNALS}
    unraisable = sys.unraisablehook
    sys.unraisablehook = _quiet_dropped(unraisable)
    _received.clear()
    _lost.clear()
    try:
        yield
    except Signalled as exc:
        raise Interrupted(exc.signum) from None
    except BaseException:
        if _received:  # the signal's exception was lost and another followed (a RuntimeError)
            raise Interrupted(_received[0]) from None
        raise
    finally:
        _received.clear()
        _lost.clear()
        sys.unraisablehook = unraisable
        for sig, handler in previous.items():
            signal.signal(sig, handler)
