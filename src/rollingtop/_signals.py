"""SIGINT and SIGTERM as exceptions, so that a run stops cleanly wherever it is.

Python runs signal handlers only between bytecodes of the main thread; compiled loops therefore
return to Python now and then (see :mod:`rollingtop.integrate.driver`) for a handler installed
here to take effect. :func:`handle_signals` turns both signals into
:class:`~rollingtop._errors.Interrupted`, a ``KeyboardInterrupt``: ``finally`` blocks and
:func:`rollingtop.io.atomic_write` then remove temporary files, and the command line reports one
line and exits with ``128 + signum``.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

from rollingtop._errors import Interrupted

__all__ = ["handle_signals"]

SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _raise(signum, frame):
    raise Interrupted(signum)


@contextlib.contextmanager
def handle_signals() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM raise :class:`Interrupted` (main thread only;
    elsewhere the block runs unchanged). The previous handlers are restored on exit."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _raise) for sig in SIGNALS}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
