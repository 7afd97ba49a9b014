"""The explore page's work off the server's event loop: the newest-request-wins queue of each
kind of work (:class:`Latest`), run in the server's thread pool (:func:`new_executor`, one per
:func:`rollingtop.explore.server.serve`, shared by its sessions).

The compiled loops the work runs release the GIL (the stepper's chunks are compiled ``nogil``,
:func:`rollingtop._jit.loop`), so the event loop answers the page while a worker integrates."""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable
from concurrent.futures import Executor, ThreadPoolExecutor
from typing import Any

from rollingtop._errors import RollingTopError

__all__ = ["WORKER_THREADS", "Latest", "new_executor"]

#: Threads of a server's pool for the page's computations.
WORKER_THREADS = 2


def new_executor() -> ThreadPoolExecutor:
    """A pool of :data:`WORKER_THREADS` threads for the pages of one server (or one page)."""
    return ThreadPoolExecutor(max_workers=WORKER_THREADS, thread_name_prefix="rollingtop-explore")


class Latest:
    """The newest request of one kind of work: runs ``compute`` in ``executor``, at most one at
    a time, and hands the result of the newest request to ``apply`` on the page's document.
    Requests made while one runs replace each other; only the last one runs next."""

    def __init__(
        self,
        executor: Executor,
        on_document: Callable[[Callable[[], None]], None],
        compute: Callable[[Any], Any],
        apply: Callable[[Any, Any], None],
    ) -> None:
        self.executor = executor
        self.on_document, self.compute, self.apply = on_document, compute, apply
        self.lock = threading.Lock()
        self.pending: Any = None
        self.has_pending = False
        self.running = False
        self.generation = 0

    def request(self, arg: Any) -> None:
        with self.lock:
            self.generation += 1
            self.pending, self.has_pending = arg, True
            if self.running:
                return
            self.running = True
        self.executor.submit(self._run)

    def _run(self) -> None:
        while True:
            with self.lock:
                if not self.has_pending:
                    self.running = False
                    return
                arg, gen = self.pending, self.generation
                self.has_pending = False
            try:
                result: Any = self.compute(arg)
            except RollingTopError as err:  # a level or body the analysis refuses: a message
                result = err
            except Exception as err:  # noqa: BLE001 -- never a server traceback on the page
                result = RuntimeError(f"{type(err).__name__}: {err}")
            with self.lock:
                stale = gen != self.generation
            if not stale:
                self.on_document(functools.partial(self.apply, arg, result))
