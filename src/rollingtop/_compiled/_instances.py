"""The compiled packages of the contact models, made from the one template when imported.

Why one package per model: numba compiles a function together with everything it calls. One
stepper that dispatched on a kernel code at run time held every model: compiling it (a
newcomer's first run) compiled all of them, and adding a model made every user's first run
slower. So each group of kernels (:data:`GROUPS`: a model's own kernel, or its variants) gets its
own instance of the compiled core -- the modules of :mod:`rollingtop._compiled._template`
(dynamics, events, dense output, stepper, tangent dynamics, chaos batches) -- in a
package of its own, ``rollingtop._compiled.<package>``, whose ``_dispatch`` calls that group's
model functions alone, written here from the registry (:func:`dispatch_source`).

**How.** :class:`_Finder`, first on :data:`sys.meta_path`, answers the imports of those names in
any process (a command, a Dask worker, numba rebuilding a cached function's environment): it
executes the template's own text under the group's module name, its imports of
``rollingtop._compiled._template`` pointed at the group's package, compiled with the template's
file name, so tracebacks, ``inspect`` and coverage point at the template's lines (the text is
changed within lines only). Two copies of the stepper are compiled apart: ``stepper_held``
(``HELD = True``, ``EVENTS = True``: the projection onto the integrals) and ``stepper_events``
(``EVENTS = True``, which the ``chaos`` batches run); a run that needs neither compiles neither.
Nothing is written to disk and nothing is committed but the template.

**Caching.** The instances' functions are cached by :mod:`rollingtop._kernel_cache`, one folder
per module and stamped with a digest of every source compiled in: numba's own cache, keyed on a
function's file, would give every group one index per template function and load another model's
machine code. The alternatives that were measured: passing the model's functions as arguments
(dispatcher types compare by identity: no cache hits), closures made by a factory (the key pickles
each captured dispatcher's per-process identity: no hits), generated copies committed to the
repository (half the package, and stale cache entries after an edit of a model).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import linecache
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from rollingtop.contact import MODULES, kernel_by_code, kernels_of

__all__ = [
    "GROUPS",
    "SUBMODULES",
    "Group",
    "dispatch_source",
    "install",
    "module_source",
]

PARENT = "rollingtop._compiled"
TEMPLATE = Path(__file__).resolve().parent / "_template"
#: The template's package, replaced by each group's in its instances.
TEMPLATE_PACKAGE = f"{PARENT}._template"
#: The template's modules instantiated in every group's package, under their own names.
MODULES_COPIED = (
    "dynamics",
    "events",
    "dense",
    "invariants",
    "stepper",
    "tangent",
    "chaos",
)
#: The stepper instantiated twice more: with its projection onto the integrals and its event
#: location compiled in (``HELD = True``, ``EVENTS = True``), and with its event location alone.
COPIES = {"stepper_held": "stepper", "stepper_events": "stepper"}
#: The import of the stepper in ``chaos``, pointed at ``stepper_events`` in the instances.
CHAOS_IMPORT = ".stepper import run_rows"
#: Every module of a group's package, in the order the package imports them.
SUBMODULES = ("_dispatch", *MODULES_COPIED, *COPIES)


@dataclass(frozen=True)
class Group:
    """Kernels compiled together, in one package made from the template.

    Attributes
    ----------
    package : str
        The package's name under :mod:`rollingtop._compiled` (``meridian``,
        ``meridian_variants``).
    model : str
        The contact model.
    codes : tuple of int
        The kernel codes it runs.
    base : int
        The code of the model's own kernel (a kernel's variant index is its code minus it).
    label : str
        What it is, in words (``the meridian model's``).
    module : str
        The model's module under :mod:`rollingtop.contact` (``shell_rotor``).
    """

    package: str
    model: str
    codes: tuple[int, ...]
    base: int
    label: str
    module: str


def _groups() -> tuple[Group, ...]:
    out = []
    for module in MODULES:
        name = module.__name__.rsplit(".", 1)[1]
        kernels = kernels_of(module.MODEL)
        base = kernels[0].code
        model = module.MODEL.name
        out.append(Group(name, model, (base,), base, f"the {model} model's", name))
        if len(kernels) > 1:
            variants = ", ".join(str(k.variant) for k in kernels[1:])
            label = f"the {model} model's variants ({variants})"
            codes = tuple(k.code for k in kernels[1:])
            out.append(Group(f"{name}_variants", model, codes, base, label, name))
    return tuple(out)


#: The compiled packages: each model's own kernel, then its variants if it has any.
GROUPS: tuple[Group, ...] = _groups()


def dispatch_source(group: Group) -> str:
    """The text of ``group``'s ``_dispatch`` module (the names of ``_template/_dispatch.py``).

    A group of one kernel passes its variant as a constant (the model's own kernel: 0): its
    code is straight-line, as the paper's model's must be to round as the C limit does (LLVM
    fuses a product into a sum only within a basic block). A group of several variants passes
    the variant read from the code, one copy of the model's code for all of them."""
    module = next(m for m in MODULES if m.MODEL.name == group.model)
    name = group.module
    kernels = [kernel_by_code(c) for c in group.codes]
    variant = str(group.codes[0] - group.base) if len(kernels) == 1 else f"code - {group.base}"
    table = "\n".join(
        f"- {k.code}: ``{k.model}``" + (f", variant ``{k.variant}``" if k.variant else "")
        for k in kernels
    )
    carried = [k.code for k in kernels if k.carries_direction]
    if len(carried) == len(kernels):
        carries = "True"
    elif not carried:
        carries = "False"
    else:
        carries = " or ".join(f"code == {c}" for c in carried)

    def call(attr: str, args: str, returns: bool, fallback: str) -> str:
        if not hasattr(module, attr):
            return f"    {fallback}"
        return f"    {'return ' if returns else ''}{name}.{attr}({args}, {variant})"

    # the variants (rare: the pole levels) keep the shorter compile
    inline_rhs = getattr(module, "INLINE_RHS", False) and group.codes == (group.base,)
    direction_rate = call("direction_rate", "p, y", True, "return _rows.direction_rate(p, y, 0)")
    sync = call("sync_direction", "y", False, "_rows.sync_direction(y, 0)")
    shared = {"_rows"} if "_rows." in direction_rate + sync else set()
    imports = ", ".join(sorted({name} | shared))
    return f'''"""Compiled dispatch of {group.label}, written from the registry by
:func:`rollingtop._compiled._instances.dispatch_source`; the names are those of
:mod:`rollingtop._compiled._template._dispatch`. Kernel codes:

{table}
"""

from __future__ import annotations

from rollingtop._jit import inline, kernel
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact import {imports}

CLOSED_ACCEL = {hasattr(module, "accel")}
CLOSED_PROJECTION = {hasattr(module, "project_velocity")}
INLINE_RHS = {inline_rhs}
CODES: tuple[int, ...] = {tuple(group.codes)!r}


@kernel
def rows(
    code: int, p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray
) -> int:
    """The constraint rows of kernel ``code``, their bias and force directions; their number."""
{call("rows", "p, y, J, bias, dirs", True, "")}


@inline
def accel(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """Closed-form accelerations of kernel ``code`` into ``dy[:6]``; the number of rows."""
{call("accel", "p, y, dy, ws", True, "return -1")}


@inline
def project_velocity(code: int, p: FloatArray, y: FloatArray) -> None:
    """Closed-form velocity projection of kernel ``code``, in place."""
{call("project_velocity", "p, y", False, "return None")}


@inline
def direction_rate(code: int, p: FloatArray, y: FloatArray) -> float:
    """``psi_nu'`` under kernel ``code`` (0 unless it carries a constraint direction)."""
{direction_rate}


@inline
def sync_direction(code: int, y: FloatArray) -> None:
    """Re-synchronise ``psi_nu`` with the axis azimuth after a step, as kernel ``code`` does."""
{sync}


@inline
def carries_direction(code: int) -> bool:
    """Whether kernel ``code`` carries its constraint direction in ``psi_nu``."""
    return {carries}
'''


def _replace_once(text: str, old: str, new: str) -> str:
    if text.count(old) != 1:
        raise RuntimeError(f"the template must contain {old!r} once")
    return text.replace(old, new)


def module_source(group: Group, module: str) -> tuple[str, str]:
    """The text that module ``module`` (:data:`SUBMODULES`) of ``group``'s package is executed
    from, and the file name it is compiled under: the template's file, whose lines it keeps
    (the ``_dispatch`` module: a name in angle brackets, its text in :mod:`linecache`)."""
    if module == "_dispatch":
        return dispatch_source(group), f"<{PARENT}.{group.package}._dispatch>"
    path = TEMPLATE / f"{COPIES.get(module, module)}.py"
    text = path.read_text().replace(TEMPLATE_PACKAGE, f"{PARENT}.{group.package}")
    if module == "chaos":
        text = _replace_once(text, CHAOS_IMPORT, CHAOS_IMPORT.replace("stepper", "stepper_events"))
    if module in COPIES:
        text = _replace_once(text, "\nEVENTS = False\n", "\nEVENTS = True\n")
    if module == "stepper_held":
        text = _replace_once(text, "\nHELD = False\n", "\nHELD = True\n")
    return text, str(path)


class _Loader(importlib.abc.Loader):
    """Executes a group's package (``module`` ``None``) or one of its modules."""

    def __init__(self, group: Group, module: str | None) -> None:
        self.group = group
        self.module = module

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> None:
        return None  # the default module

    def exec_module(self, module: ModuleType) -> None:
        if self.module is None:
            module.MODEL = self.group.model  # type: ignore[attr-defined]
            module.PACKAGE = self.group.package  # type: ignore[attr-defined]
            module.GROUP = self.group  # type: ignore[attr-defined]
            for name in SUBMODULES:  # cheap: numba compiles a function at its first call
                importlib.import_module(f"{module.__name__}.{name}")
            return
        text, filename = module_source(self.group, self.module)
        if filename.startswith("<"):  # tracebacks and numba's messages show its lines
            linecache.cache[filename] = (len(text), None, text.splitlines(True), filename)
        exec(compile(text, filename, "exec", dont_inherit=True), module.__dict__)


class _Finder(importlib.abc.MetaPathFinder):
    """Finds ``rollingtop._compiled.<package>`` and its modules (:data:`SUBMODULES`)."""

    def __init__(self, groups: Sequence[Group]) -> None:
        self.groups = {g.package: g for g in groups}

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None = None,
        target: ModuleType | None = None,
    ) -> importlib.machinery.ModuleSpec | None:
        parts = fullname.split(".")
        if ".".join(parts[:2]) != PARENT or len(parts) not in (3, 4):
            return None
        group = self.groups.get(parts[2])
        if group is None:
            return None
        if len(parts) == 3:
            return importlib.util.spec_from_loader(fullname, _Loader(group, None), is_package=True)
        if parts[3] not in SUBMODULES:
            return None
        if parts[3] == "_dispatch":
            return importlib.util.spec_from_loader(fullname, _Loader(group, parts[3]))
        origin = str(TEMPLATE / f"{COPIES.get(parts[3], parts[3])}.py")
        spec = importlib.util.spec_from_loader(fullname, _Loader(group, parts[3]), origin=origin)
        if spec is not None:
            spec.has_location = True  # __file__: the template's
        return spec


def install(groups: Sequence[Group] = GROUPS) -> None:
    """Put the finder of ``groups``' packages first on :data:`sys.meta_path` (once): before
    the path finder, which would take a folder left by an older installation
    (``_compiled/meridian/__pycache__``) for a namespace package."""
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.insert(0, _Finder(groups))
