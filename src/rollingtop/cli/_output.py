"""What the command line shows besides its results: notes, warnings, progress bars, consoles.

Notes and warnings are one line each on stderr (``rollingtop: note: ...``,
``rollingtop: warning: ...``); progress bars appear only when stderr is a terminal, and
vanish when done.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections.abc import Callable, Iterator
from typing import IO, TYPE_CHECKING, TypeVar

import click

from rollingtop._errors import ContactLostWarning
from rollingtop.cli._errors import one_line

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure
    from rich.console import Console
    from rich.progress import Progress

__all__ = [
    "console",
    "counting",
    "note",
    "progress_bar",
    "status",
    "timing",
    "warnings_as_lines",
    "with_warnings_reported",
]

T = TypeVar("T")


def note(message: str) -> None:
    """``rollingtop: note: MESSAGE`` on stderr."""
    click.echo(f"rollingtop: note: {one_line(message)}", err=True)


@contextlib.contextmanager
def warnings_as_lines() -> Iterator[None]:
    """Python warnings that reach the command line (numerical ones from NumPy, say) as one
    ``rollingtop: warning:`` line each, naming where they arose, instead of two raw lines."""
    previous = warnings.showwarning

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: IO[str] | None = None,
        line: str | None = None,
    ) -> None:
        where = f"{os.path.basename(filename)}:{lineno}"
        click.echo(f"rollingtop: warning: {one_line(f'{message} ({where})')}", err=True)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = previous


def with_warnings_reported(run: Callable[[], T]) -> T:
    """``run()``, then each warning it raised (a lost contact, say) as one
    ``rollingtop: warning:`` line."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ContactLostWarning)
        result = run()
    for w in caught:
        click.echo(f"rollingtop: warning: {w.message}", err=True)
    return result


#: The variables by which rich treats a stream that is no terminal as one.
FORCE_TERMINAL = ("FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE")


def _terminal_stderr() -> Console | None:
    # rich's console and progress modules take a tenth of a second to import: a run whose
    # stderr is a pipe or a file (scripts, CI) asks the stream first
    if not sys.stderr.isatty() and not any(os.environ.get(v) for v in FORCE_TERMINAL):
        return None
    from rich.console import Console

    stderr = Console(stderr=True)
    return stderr if stderr.is_terminal else None


def progress_bar(label: str = "integrating") -> Progress | None:
    """A bar of simulated time on stderr when it is a terminal, else ``None``; ``label`` may
    name the task (``{task.description}``)."""
    stderr = _terminal_stderr()
    if stderr is None:
        return None
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(
        TextColumn(label),
        BarColumn(),
        TextColumn("t = {task.completed:.4g} / {task.total:.4g}"),
        TimeRemainingColumn(),
        console=stderr,
        transient=True,
    )


@contextlib.contextmanager
def timing(total: float) -> Iterator[Callable[[float], None] | None]:
    """``progress(t)`` drawing a bar of simulated time up to ``total`` on a terminal, else
    ``None`` (as long as the block runs)."""
    bar = progress_bar()
    if bar is None:
        yield None
        return
    with bar:
        task = bar.add_task("integrate", total=total)
        yield lambda t: bar.update(task, completed=t)


@contextlib.contextmanager
def counting(label: str, total: int | None) -> Iterator[Callable[[int, int], None] | None]:
    """``progress(done, total)`` drawing a bar of items done (``12/40``) on a terminal, else
    ``None`` (as long as the block runs). ``total`` may be ``None`` until the first call
    says it."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    stderr = _terminal_stderr()
    if stderr is None:
        yield None
        return
    with Progress(
        TextColumn(label), BarColumn(), MofNCompleteColumn(), console=stderr, transient=True
    ) as bar:
        task = bar.add_task(label, total=total)
        yield lambda done, n: bar.update(task, completed=done, total=n)


@contextlib.contextmanager
def status(label: str) -> Iterator[Callable[[str], None] | None]:
    """``show(what)``: a spinner saying ``label what`` on stderr when it is a terminal, else
    ``None`` (as long as the block runs)."""
    stderr = _terminal_stderr()
    if stderr is None:
        yield None
        return
    with stderr.status(label) as spinner:
        yield lambda what: spinner.update(f"{label} {what}")


#: Width of the console on stdout when it is not a terminal (a pipe, a file), unless a command
#: asks for another: wide enough that no table is cut.
PIPED_WIDTH = 160


def console(piped_width: int = PIPED_WIDTH) -> Console:
    """Console on stdout; when stdout is not a terminal, ``piped_width`` columns wide (a table
    wider than that wraps its cells)."""
    from rich.console import Console

    stdout = Console()
    return stdout if stdout.is_terminal else Console(width=piped_width)


def write_figure_and_data(
    fig: Figure, output: str, ds: xr.Dataset | None = None, netcdf: str | None = None
) -> None:
    """Write ``fig`` to ``output`` (its format by suffix, 200 dpi) and, with ``netcdf``, ``ds``
    as NetCDF: both or neither (:func:`rollingtop.io.write_together`; the commands that draw a
    computed Dataset, ``section`` and ``basins``, and ``periodic``'s figure)."""
    from pathlib import Path

    from rollingtop.io import netcdf_bytes, write_together

    fmt = output.rsplit(".", 1)[-1].lower()
    writes: list[tuple[str, Callable[[Path], None]]] = [
        (output, lambda tmp: fig.savefig(tmp, format=fmt, dpi=200))
    ]
    if netcdf is not None and ds is not None:
        data = netcdf_bytes(ds)

        def write_data(tmp: Path) -> None:
            tmp.write_bytes(data)

        writes.append((netcdf, write_data))
    write_together(writes)
