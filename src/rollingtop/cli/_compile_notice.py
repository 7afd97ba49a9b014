"""The command line's word on a compilation: one line on stderr before numba compiles a model's
kernels (``rollingtop: compiling the meridian model's integrator kernels (first run only, about
9 s)``), then, on a terminal, a spinner with the functions compiled so far and the seconds
spent; nothing when every kernel loads from numba's cache."""

from __future__ import annotations

import contextlib
import sys
import threading
from collections.abc import Iterator
from typing import Any

import click

from rollingtop import _compiled

__all__ = ["CommandLineNotifier", "compile_notices"]


class CommandLineNotifier:
    """A :class:`rollingtop._compiled.Notifier` for the command line."""

    def __init__(self) -> None:
        self._progress: Any = None
        self._task: Any = None
        self._count = 0

    def start(self, message: str, first: bool) -> None:
        if first:
            click.echo(f"rollingtop: {message}", err=True)
        from rich.console import Console
        from rich.file_proxy import FileProxy
        from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        stderr = Console(stderr=True)
        self._count = 0
        # a spinner (the functions compiled, the time) on a terminal, from the main thread, when
        # no progress bar is live: a live bar redirects stderr through rich (the line above goes
        # above the bar) and a second live display would garble it
        quiet = isinstance(sys.stderr, FileProxy) or threading.current_thread() is not (
            threading.main_thread()
        )
        if stderr.is_terminal and not quiet:
            columns = (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn())
            self._progress = Progress(*columns, console=stderr, transient=True)
            self._task = self._progress.add_task("compiling: 0 functions")
            self._progress.start()

    def step(self, function: str, seconds: float) -> None:
        self._count += 1
        if self._progress is not None:
            self._progress.update(self._task, description=f"compiling: {self._count} functions")

    def done(self, seconds: float) -> None:
        if self._progress is not None:
            self._progress.stop()
            self._progress = None


@contextlib.contextmanager
def compile_notices() -> Iterator[None]:
    """Install :class:`CommandLineNotifier` while the block runs (a command)."""
    previous = _compiled.set_notifier(CommandLineNotifier())
    try:
        yield
    finally:
        _compiled.set_notifier(previous)
