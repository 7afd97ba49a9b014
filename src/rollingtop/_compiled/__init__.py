"""The compiled core, one package per contact model, compiled on first use.

Each registered contact model has a package here (``rollingtop._compiled.meridian``, ...),
generated from :mod:`rollingtop._compiled._template` by :mod:`rollingtop._compiled._codegen`:
its right-hand side, projection, diagnostics, DOP853 stepper, ensemble kernel, tangent dynamics
and chaos batches, compiled against that model's functions alone. :func:`for_model` imports a
model's package (cheap: nothing is compiled at import); numba compiles each function on its
first call, or loads it from its on-disk cache, so a command pays only for the models it runs.

:func:`compiling` wraps a first call that may compile: when numba actually compiles (a cache
miss, not a load), the notifier (:func:`set_notifier`; the command line's prints one line on
stderr and, on a terminal, a spinner with the functions compiled so far) is told once, before
the work starts.
"""

from __future__ import annotations

import contextlib
import importlib
import logging
import time
from collections.abc import Iterator
from types import ModuleType
from typing import Any, Protocol

from rollingtop import _jit
from rollingtop.contact import MODULES, ContactModel, get_model, kernel_by_code

__all__ = [
    "ESTIMATES",
    "PACKAGES",
    "Notifier",
    "compiling",
    "for_code",
    "for_model",
    "set_notifier",
]

#: Compiled package of each model, by model name (the model module's own name).
PACKAGES: dict[str, str] = {m.MODEL.name: m.__name__.rsplit(".", 1)[1] for m in MODULES}

#: Rough seconds a cold compilation of one model's group of kernels takes on a 2-core machine,
#: rounded from the paper's model's (``benchmarks/run_benchmarks.py --only cold_start`` measures
#: whole commands); the models differ by a few seconds. Only the announcement uses them.
ESTIMATES: dict[str, float] = {
    "dynamics": 4.0,
    "integrator": 9.0,
    "ensemble": 6.0,
    "chaos": 20.0,
}


def for_model(model: str | ContactModel) -> ModuleType:
    """The compiled package of ``model`` (a name or a :class:`~rollingtop.contact.ContactModel`).

    Its modules ``dynamics``, ``events``, ``dense``, ``stepper``, ``ensemble``, ``tangent`` and
    ``chaos`` hold the functions of :mod:`rollingtop._compiled._template`, compiled for this
    model's kernel codes only (a code of another model is not checked: the caller picks the
    package by the code, :func:`for_code`).
    """
    name = get_model(model).name
    return importlib.import_module(f"{__name__}.{PACKAGES[name]}")


def for_code(code: int) -> ModuleType:
    """The compiled package of the model whose kernel has code ``code``."""
    return for_model(kernel_by_code(int(code)).model)


class Notifier(Protocol):
    """Told when numba starts compiling (not loading) a group of kernels."""

    def start(self, message: str, first: bool) -> None:
        """Compilation begins; ``message`` says what, and about how long it takes; ``first``:
        the first time in this process for this model and group (later blocks compile what the
        first did not reach, and need no second announcement)."""

    def step(self, function: str, seconds: float) -> None:
        """One more function compiled (``function``), ``seconds`` since :meth:`start`."""

    def done(self, seconds: float) -> None:
        """The group is compiled."""


class _LogNotifier:
    """The library's default: one ``logging`` record at INFO level (logger ``rollingtop``)."""

    def start(self, message: str, first: bool) -> None:
        if first:
            logging.getLogger("rollingtop").info(message)

    def step(self, function: str, seconds: float) -> None:
        pass

    def done(self, seconds: float) -> None:
        logging.getLogger("rollingtop").info("compiled in %.1f s", seconds)


_notifier: Notifier = _LogNotifier()
#: (model, group) pairs announced in this process.
_announced: set[tuple[str, str]] = set()


def set_notifier(notifier: Notifier | None) -> Notifier:
    """Install ``notifier`` (``None``: the default, a ``logging`` record); returns the previous
    one."""
    global _notifier
    previous = _notifier
    _notifier = _LogNotifier() if notifier is None else notifier
    return previous


def message(model: str, what: str) -> str:
    """The announcement of a cold compilation of ``model``'s group ``what``."""
    estimate = ESTIMATES.get(what)
    about = f", about {estimate:.0f} s" if estimate else ""
    if _jit.caching_disabled():
        return (f"compiling the {model} model's {what} kernels (numba cannot save its cache: "
                f"every run compiles them{about})")  # fmt: skip
    return f"compiling the {model} model's {what} kernels (first run only{about})"


@contextlib.contextmanager
def compiling(model: str | ContactModel, what: str) -> Iterator[None]:
    """Announce (through the notifier, once per process for a model and group) that numba
    compiles ``model``'s kernels of group ``what`` while the block runs, if it does: a block
    whose functions all load from numba's cache says nothing."""
    from numba.core import event

    name = get_model(model).name
    started: list[float] = []

    class Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            if not started:
                started.append(time.perf_counter())
                first = (name, what) not in _announced
                _announced.add((name, what))
                _notifier.start(message(name, what), first)

        def on_end(self, ev: Any) -> None:
            dispatcher = ev.data.get("dispatcher")
            func = getattr(getattr(dispatcher, "py_func", None), "__qualname__", "?")
            _notifier.step(func, time.perf_counter() - started[0])

    listener = Listener()
    event.register("numba:compile", listener)  # type: ignore[no-untyped-call]
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)  # type: ignore[no-untyped-call]
        if started:
            _notifier.done(time.perf_counter() - started[0])
