"""Writes :mod:`rollingtop.contact._dispatch` from the registry (run as a module).

Why generated code: the integrator is compiled once for every model, and selects a model's
compiled functions by an integer kernel code at run time (one compiled integrator, no compile per
model). numba needs the calls spelled out (a branch per kernel, each calling a module's function
with its variant as a constant), and numba's on-disk cache needs them in a source file. The
source is committed; a test checks that it matches this generator and the registry.

    python -m rollingtop.contact._codegen
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from rollingtop.contact import KERNELS, MODULES

TARGET = Path(__file__).with_name("_dispatch.py")

HEADER = '''"""Compiled dispatch: kernel code -> its model's functions (GENERATED: do not edit).

Written by ``python -m rollingtop.contact._codegen`` from the registry
(:data:`rollingtop.contact.MODULES`); see that generator for why. Kernel codes:

{table}
"""

from __future__ import annotations

from rollingtop._jit import inline, kernel
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact import {imports}
'''


def _module(name: str) -> ModuleType:
    return next(m for m in MODULES if m.MODEL.name == name)


def _branches() -> list[tuple[int, str, int, ModuleType]]:
    """``(code, module name, variant index, module)`` of every kernel."""
    out: list[tuple[int, str, int, ModuleType]] = []
    for k in KERNELS:
        mod = _module(k.model)
        variant = 0 if k.variant is None else 1 + mod.MODEL.variants.index(k.variant)
        out.append((k.code, mod.__name__.rsplit(".", 1)[1], variant, mod))
    return out


def _function(decorator: str, signature: str, doc: str, body: list[str], tail: list[str]) -> str:
    """A function of the generated module; ``signature`` is laid out as ``ruff format`` would
    lay it out (the generated file is checked by ``ruff format --check`` too)."""
    lines = ["", "", decorator, f"def {signature}:", f'    """{doc}"""', *body, *tail]
    return "\n".join(lines) + "\n"


def source() -> str:
    """The text of :mod:`rollingtop.contact._dispatch`."""
    branches = _branches()
    table = "\n".join(
        f"- {code}: ``{k.model}``" + (f", variant ``{k.variant}``" if k.variant else "")
        for (code, *_), k in zip(branches, KERNELS, strict=True)
    )
    imports = ", ".join(["_rows", *sorted({name for _, name, _, _ in branches})])
    text = HEADER.format(table=table, imports=imports)

    def calls(attr: str, call: str, then: str | None = None) -> list[str]:
        """A branch per kernel whose module has ``attr``: ``return module.attr(call)``, or the
        call followed by ``then``."""
        body = []
        for code, name, variant, mod in branches:
            if hasattr(mod, attr):
                expr = f"{name}.{attr}({call.format(v=variant)})"
                body.append(f"    if code == {code}:")
                body += [f"        return {expr}"] if then is None else [f"        {expr}", then]
        return body

    text += _function(
        "@kernel",
        "rows(\n    code: int, p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, "
        "dirs: FloatArray\n) -> int",
        "The constraint rows of kernel ``code``; returns their number (-1: unknown code).",
        calls("rows", "p, y, J, bias, dirs, {v}"),
        ["    return -1"],
    )
    text += _function(
        "@inline",
        "accel(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int",
        "Closed-form accelerations of kernel ``code``; returns the number of rows, or -1 where "
        "the\n    model has no closed form (then the general path applies).",
        calls("accel", "p, y, dy, ws, {v}"),
        ["    return -1"],
    )
    text += _function(
        "@inline",
        "project_velocity(code: int, p: FloatArray, y: FloatArray) -> bool",
        "Closed-form velocity projection of kernel ``code``; ``False`` where the model has none.",
        calls("project_velocity", "p, y, {v}", "        return True"),
        ["    return False"],
    )
    text += _function(
        "@inline",
        "direction_rate(code: int, p: FloatArray, y: FloatArray) -> float",
        "``psi_nu'`` under kernel ``code`` (0 unless it carries a constraint direction).",
        calls("direction_rate", "p, y, {v}"),
        ["    return _rows.direction_rate(p, y, 0)"],
    )
    text += _function(
        "@inline",
        "sync_direction(code: int, y: FloatArray) -> None",
        "Re-synchronise ``psi_nu`` with the axis azimuth after a step, as kernel ``code`` does.",
        calls("sync_direction", "y, {v}", "        return"),
        ["    _rows.sync_direction(y, 0)"],
    )
    carried = " or ".join(f"code == {k.code}" for k in KERNELS if k.carries_direction)
    text += _function(
        "@inline",
        "carries_direction(code: int) -> bool",
        "Whether kernel ``code`` carries its constraint direction in ``psi_nu``.",
        [],
        [f"    return {carried or 'False'}"],
    )
    return text


def main() -> None:
    """Write :data:`TARGET`."""
    TARGET.write_text(source())
    print(f"wrote {TARGET}")
    print(
        "numba's cache does not notice this change in the functions that call the dispatch: "
        "clear __pycache__ (or point NUMBA_CACHE_DIR at a new folder) before the next run "
        "outside the test suite, which keys its cache by the sources"
    )


if __name__ == "__main__":
    main()
