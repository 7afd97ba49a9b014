"""The worker plugin of the atlas's embedded Dask cluster (a module of its own: it imports
``distributed``, which ``import rollingtop.atlas`` does not)."""

from __future__ import annotations

import signal
import threading

from distributed import Worker, WorkerPlugin

__all__ = ["QuietWorker"]


class QuietWorker(WorkerPlugin):
    """Worker processes of the embedded cluster ignore SIGINT.

    A Ctrl-C reaches the whole process group. The main process ends the run (one line, exit
    130) and closes the cluster, which stops its workers; without this each worker printed its
    own ``KeyboardInterrupt`` traceback (measured: 63 lines of stderr). SIGTERM and the
    cluster's own shutdown still end the workers.
    """

    def setup(self, worker: Worker) -> None:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
