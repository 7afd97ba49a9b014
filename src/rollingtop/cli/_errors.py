"""How the command line reports an error: one line on stderr, an exit status, no traceback.

Every error a command can meet becomes one :class:`Reported` (a :class:`click.ClickException`)
in one place, :func:`reported`; click's standalone mode then shows it
(``rollingtop: error: ...``) and exits with its status:

- :class:`BadInput`, status 2: a :class:`~rollingtop.RollingTopError` (bad scenario, table,
  value, output path) or click's own usage errors (bad option, missing argument);
- :class:`RunFailed`, status 1: an :class:`~rollingtop.IntegrationError`, or an output not
  written (:class:`~rollingtop.io.WriteFailed`, any other ``OSError``); :class:`NotHeld`, a run
  that finished without holding its integrals (its outputs are written);
- :class:`Stopped`, status ``128 + signum``: SIGINT or SIGTERM
  (:class:`~rollingtop._errors.Interrupted`, raised by :mod:`rollingtop._signals`).
"""

from __future__ import annotations

import contextlib
import functools
import re
from collections.abc import Iterator
from typing import IO, Any

import click

from rollingtop._errors import (
    IntegrationError,
    Interrupted,
    RollingTopError,
    short_path,
)
from rollingtop.io import WriteFailed

__all__ = ["BadInput", "NotHeld", "Reported", "RunFailed", "Stopped", "one_line", "reported"]

_LINE_BREAKS = {
    ord(c): c.encode("unicode_escape").decode() for c in "\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029"
}
_LONG_QUOTE = re.compile(r"'([^']{80})[^']+'")
_SIGNAL_NAMES = {2: "SIGINT", 15: "SIGTERM"}
#: Longest line reported.
MAX_MESSAGE = 2000


def one_line(message: str) -> str:
    """``message`` with line breaks escaped and long quoted values cut (click's messages quote
    the whole value given): every report is one line of reasonable length."""
    message = _LONG_QUOTE.sub(r"'\1…'", message.strip().translate(_LINE_BREAKS))
    return message if len(message) <= MAX_MESSAGE else message[: MAX_MESSAGE - 1] + "…"


class Reported(click.ClickException):
    """An error shown as one line ``rollingtop: error: MESSAGE`` on stderr."""

    exit_code = 1

    def show(self, file: IO[Any] | None = None) -> None:
        click.echo(f"rollingtop: error: {one_line(self.format_message())}", file=file, err=True)


class BadInput(Reported):
    """Input refused (an option, a scenario, a table, an output path): exit status 2."""

    exit_code = 2


class RunFailed(Reported):
    """The run could not finish (integration failed, output not written): exit status 1."""

    exit_code = 1


class NotHeld(RunFailed):
    """The run finished but did not hold what it claimed (its integrals, by projection): exit
    status 1, its outputs written (:func:`rollingtop.io.published_on_success`)."""

    keeps_outputs = True


class Stopped(Reported):
    """A signal stopped the run: exit status ``128 + signum`` (130 SIGINT, 143 SIGTERM).

    click reads the status from the class (``ClickException.exit_code`` is a class variable), so
    :meth:`of` makes one subclass per signal.
    """

    def __init__(self, signum: int) -> None:
        name = _SIGNAL_NAMES.get(signum, f"signal {signum}")
        super().__init__(f"interrupted by {name}; no output was written")

    @classmethod
    @functools.cache
    def of(cls, signum: int) -> type[Stopped]:
        """The subclass whose exit status is ``128 + signum``."""
        return type(f"Stopped{signum}", (cls,), {"exit_code": 128 + signum})


@contextlib.contextmanager
def reported() -> Iterator[None]:
    """Within the block, every error a command can meet leaves as the :class:`Reported` that
    shows it (see the module docstring); others pass unchanged (a bug shows its traceback)."""
    try:
        yield
    except Reported:
        raise
    except click.UsageError as exc:
        raise BadInput(exc.format_message()) from None
    except RollingTopError as exc:
        raise BadInput(str(exc)) from None
    except (IntegrationError, WriteFailed) as exc:
        raise RunFailed(str(exc)) from None
    except Interrupted as exc:
        raise Stopped.of(exc.signum)(exc.signum) from None
    except OSError as exc:
        where = "" if exc.filename is None else f"{short_path(exc.filename)}: "
        raise RunFailed(f"{where}{exc.strerror or exc}") from None
    except OverflowError:  # Python's float arithmetic raises where numpy's gives inf
        raise BadInput(
            "a derived quantity overflows double precision (a product or power "
            "of the inputs beyond 1e308): rescale the scenario's units"
        ) from None
    except MemoryError:
        raise RunFailed(
            "not enough memory for what was asked (fewer samples, a smaller grid)"
        ) from None
