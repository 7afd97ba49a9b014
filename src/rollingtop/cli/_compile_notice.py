"""The command line's word on a compilation: one line on stderr before numba compiles a model's
kernels (``rollingtop: compiling the meridian model's integrator kernels (first run only, about
9 s)``), then, on a terminal, a spinner with the functions compiled so far and the seconds
spent; nothing when every kernel loads from numba's cache."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import click

from rollingtop import _compiled

__all__ = ["CommandLineNotifier", "compile_notices"]


class CommandLineNotifier:
    """A :class:`rollingtop._compiled.Notifier` for the command line."""

    def __init__(self) -> None:
        self._spinner: Any = None
        self._count = 0
        self._message = ""

    def start(self, message: str, first: bool) -> None:
        if first:
            click.echo(f"rollingtop: {message}", err=True)
        from rich.console import Console

        stderr = Console(stderr=True)
        self._count = 0
        self._message = message.split(" (", 1)[0]
        if stderr.is_terminal:
            self._spinner = stderr.status(f"{self._message}...")
            self._spinner.start()

    def step(self, function: str, seconds: float) -> None:
        self._count += 1
        if self._spinner is not None:
            self._spinner.update(
                f"{self._message}: {self._count} functions, {seconds:.0f} s ({function})"
            )

    def done(self, seconds: float) -> None:
        if self._spinner is not None:
            self._spinner.stop()
            self._spinner = None


@contextlib.contextmanager
def compile_notices() -> Iterator[None]:
    """Install :class:`CommandLineNotifier` while the block runs (a command)."""
    previous = _compiled.set_notifier(CommandLineNotifier())
    try:
        yield
    finally:
        _compiled.set_notifier(previous)
