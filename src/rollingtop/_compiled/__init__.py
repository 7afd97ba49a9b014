"""The compiled core, one package per contact model (and one for a model's variants),
compiled on first use.

Each registered contact model has a package here (``rollingtop._compiled.meridian``, ...), made from
the template :mod:`rollingtop._compiled._template` when first imported
(:mod:`rollingtop._compiled._instances`; no file is generated): its right-hand side, projection,
diagnostics, DOP853 stepper (whose loop runs a single run and an ensemble's rows alike), tangent
dynamics and chaos batches, compiled against that model's functions alone. A model with variants
(the meridian model's pole cases, :class:`rollingtop.contact.Kernel`) has a second package for them,
``meridian_variants``: its own kernel's code is then straight-line, with no branch on the variant,
and a run that needs no variant compiles none (:data:`GROUPS`). :func:`for_code` imports the package
of a kernel code (cheap: nothing is compiled at import); numba compiles each function on its first
call, or loads it from the on-disk cache, keyed on every source compiled into it
(:mod:`rollingtop._kernel_cache`), so a command pays only for the kernels it runs and never runs
machine code older than its sources. The modules beside the packages (``_kernel``, ``_dop853``, ...)
are the compiled pieces every model shares, compiled once.

:func:`compiling` wraps a first call that may compile: when numba actually compiles (a cache
miss, not a load), the notifier (:func:`set_notifier`; the command line's prints one line on
stderr and, on a terminal, a spinner with the functions compiled so far) is told once, before
the work starts.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import logging
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from rollingtop import _jit
from rollingtop._compiled._instances import GROUPS, Group, install
from rollingtop._types import IntArray
from rollingtop.contact import ContactModel, get_model

install(GROUPS)

__all__ = [
    "ESTIMATES",
    "GROUPS",
    "PACKAGE_SECONDS",
    "Group",
    "Notifier",
    "before_projection",
    "by_package",
    "compiling",
    "for_code",
    "for_model",
    "packages_of",
    "run_before_projection",
    "set_notifier",
]


_GROUP_OF_CODE: dict[int, Group] = {c: g for g in GROUPS for c in g.codes}

_MEASURED = json.loads((Path(__file__).with_name("estimates.json")).read_text())
#: Seconds a cold compilation of each group of the paper's model's kernels took, measured (each
#: group in a fresh process with an empty cache) by ``benchmarks/compile_estimates.py --write``
#: into ``estimates.json`` beside this file; the models differ by a few seconds. Only the
#: announcement uses them.
ESTIMATES: dict[str, float] = {str(k): float(v) for k, v in _MEASURED["seconds"].items()}
#: Seconds each compiled package (:data:`GROUPS`) took in a worker of :func:`rollingtop.warmup`
#: (measured by the same script, in fresh processes): the order warmup hands them out in.
PACKAGE_SECONDS: dict[str, float] = {
    str(k): float(v) for k, v in _MEASURED.get("packages", {}).items()
}


def group_of(code: int) -> Group:
    """The group of kernel code ``code`` (``ValueError`` for an unknown code)."""
    try:
        return _GROUP_OF_CODE[int(code)]
    except KeyError:
        known = len(_GROUP_OF_CODE)
        raise ValueError(f"unknown kernel code {code} (known: 0 to {known - 1})") from None


def for_code(code: int) -> ModuleType:
    """The compiled package that runs kernel code ``code``.

    Its modules ``dynamics``, ``events``, ``dense``, ``stepper`` (``stepper_held`` with the
    projection onto the integrals), ``tangent`` and ``chaos`` hold the functions of
    :mod:`rollingtop._compiled._template`, compiled for its group's codes only (:data:`GROUPS`;
    a code of another group is not checked by the compiled functions: pick the package by the
    code).
    """
    package = group_of(code).package
    _jit.load_numba()  # compiled code is wanted: its functions numba dispatchers from here on
    return importlib.import_module(f"{__name__}.{package}")


def for_model(model: str | ContactModel) -> ModuleType:
    """The compiled package of ``model``'s own kernel (a name or a
    :class:`~rollingtop.contact.ContactModel`)."""
    return for_code(get_model(model).code)


def packages_of(model: str | ContactModel, *, variants: bool = True) -> list[ModuleType]:
    """The compiled packages of ``model``: its own kernel's, then (``variants``) its variants'."""
    model = get_model(model)
    if not variants:
        return [for_code(model.code)]
    return [for_code(g.codes[0]) for g in GROUPS if g.model == model.name]


def by_package(codes: ArrayLike) -> list[tuple[ModuleType, IntArray]]:
    """The indices of ``codes`` (kernel codes, shape (N,)) run by each compiled package, in the
    order the packages first appear (``ValueError`` for an unknown code)."""
    codes = np.asarray(codes, dtype=np.int64)
    names = np.array([group_of(int(c)).package for c in codes])
    return [
        (for_code(int(codes[names == n][0])), np.flatnonzero(names == n))
        for n in dict.fromkeys(names)
    ]


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

#: Work to do before a package's next constraint projection of an initial state, by package
#: (:func:`run_before_projection`).
_before_projection: dict[str, Callable[[], None]] = {}


def run_before_projection(package: str, work: Callable[[], None]) -> None:
    """Do ``work`` before the next projection of an initial state onto the constraints of
    ``package`` (:func:`before_projection`), once: there, an initial state has passed every
    check of its values, so a bad one is still refused at once (before numba loads). The
    command line's ``simulate`` leaves :func:`~rollingtop.integrate.driver.compile_ahead` there:
    the stepper's loop compiles while a helper compiles the projection it is about to load."""
    _before_projection[package] = work


def before_projection(kernels: ModuleType) -> None:
    """What :func:`run_before_projection` left for ``kernels``' package, if anything (called by
    :mod:`rollingtop.dynamics.state` before it projects an initial state)."""
    work = _before_projection.pop(kernels.PACKAGE, None)
    if work is not None:
        work()


def set_notifier(notifier: Notifier | None) -> Notifier:
    """Install ``notifier`` (``None``: the default, a ``logging`` record); returns the previous
    one."""
    global _notifier
    previous = _notifier
    _notifier = _LogNotifier() if notifier is None else notifier
    return previous


def message(label: str, what: str) -> str:
    """The announcement of a cold compilation of ``what`` kernels of ``label`` (a
    :attr:`Group.label`, or a model's name)."""
    if not label.startswith("the "):
        label = f"the {label} model's"
    estimate = ESTIMATES.get(what)
    about = f", about {estimate:.0f} s" if estimate else ""
    if _jit.caching_disabled():
        return (
            f"compiling {label} {what} kernels (numba cannot save its cache: every run "
            f"compiles them{about})"
        )
    return f"compiling {label} {what} kernels (first run only{about})"


@contextlib.contextmanager
def compiling(target: str | ContactModel | ModuleType, what: str) -> Iterator[None]:
    """Announce (through the notifier, once per process for a package and group) that numba
    compiles ``what`` kernels of ``target`` -- a model (its own kernel's package) or a compiled
    package (:func:`for_code`) -- while the block runs, if it does: a block whose functions all
    load from numba's cache says nothing."""
    from numba.core import event

    if isinstance(target, ModuleType):
        name = group_of(target._dispatch.CODES[0]).label
    else:
        name = group_of(get_model(target).code).label
    started: list[float] = []

    # numba's listeners are global and its events come from any thread's compile; a listener
    # must never raise into a compile (numba would fail it): a notifier's error is logged
    class Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            if not started:
                started.append(time.perf_counter())
                first = (name, what) not in _announced
                _announced.add((name, what))
                _tell(_notifier.start, message(name, what), first)

        def on_end(self, ev: Any) -> None:
            if not started:  # the end of a compile that began before the block
                return
            dispatcher = ev.data.get("dispatcher")
            func = getattr(getattr(dispatcher, "py_func", None), "__qualname__", "?")
            _tell(_notifier.step, func, time.perf_counter() - started[0])

    listener = Listener()
    event.register("numba:compile", listener)  # type: ignore[no-untyped-call]
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)  # type: ignore[no-untyped-call]
        if started:
            _tell(_notifier.done, time.perf_counter() - started[0])


def _tell(method: Any, *args: Any) -> None:
    """Call a notifier's ``method``, logging (not raising) what it raises."""
    try:
        method(*args)
    except Exception:  # a notifier must not fail a compilation
        logging.getLogger("rollingtop").exception("the compile notifier failed")
