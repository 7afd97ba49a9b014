"""The habits of the codebase that a test can hold: no module over MAX_LINES lines, no
formatting escapes (``# fmt: skip``) packing lines to stay under it, no
comparison of a contact model's name outside the contact package (each model has one home:
rollingtop.contact), and no circle of imports between modules, at any depth and counting imports
inside functions (lint-imports holds the layers)."""

import ast
import re
from pathlib import Path

import rollingtop
from rollingtop.contact import MODELS

SRC = Path(rollingtop.__file__).parent
#: ``../shared/STYLE.md``: split a file along a seam when it grows past about 600 lines.
MAX_LINES = 600


def test_no_module_is_over_the_line_limit():
    long = {str(p.relative_to(SRC)): n for p in SRC.rglob("*.py")
            if (n := len(p.read_text().splitlines())) > MAX_LINES}  # fmt: skip
    assert not long, f"modules over {MAX_LINES} lines: {long}"


#: Issue 37: ``ruff format`` formats the package; an escape needs its reason on its line.
MAX_FMT_SKIPS = 20


def test_the_formatter_formats_the_package():
    skips = [f"{p.relative_to(SRC)}:{k}" for p in SRC.rglob("*.py")
             for k, line in enumerate(p.read_text().splitlines(), 1) if "fmt: skip" in line
             or "fmt: off" in line]  # fmt: skip
    assert len(skips) <= MAX_FMT_SKIPS, f"{len(skips)} formatting escapes: {skips}"


def test_no_model_name_is_compared_outside_the_contact_package():
    names = "|".join(re.escape(n) for n in MODELS)
    quoted = rf"""["']({names})["']"""
    compare = re.compile(rf"(==|!=|\bin)\s*[\(\[\{{]?\s*{quoted}|{quoted}\s*(==|!=|\bin\b)")
    found = []
    for p in SRC.rglob("*.py"):
        if "contact" in p.relative_to(SRC).parts[:1]:
            continue
        for k, line in enumerate(p.read_text().splitlines(), 1):
            if compare.search(line):
                found.append(f"{p.relative_to(SRC)}:{k}: {line.strip()}")
    assert not found, "model names compared outside rollingtop.contact:\n" + "\n".join(found)


def _import_graph() -> dict[str, set[str]]:
    """Every import between modules of rollingtop, at module level or inside a function."""
    modules = {}
    for p in SRC.rglob("*.py"):
        parts = list(p.relative_to(SRC.parent).with_suffix("").parts)
        package = parts[-1] == "__init__"
        modules[".".join(parts[:-1] if package else parts)] = (p, package)

    def owner(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {m: set() for m in modules}
    for m, (p, package) in modules.items():
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = m.split(".")[: len(m.split(".")) - node.level + (1 if package else 0)]
                    base = ".".join(up + ([node.module] if node.module else []))
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
                         for a in node.names]  # fmt: skip
            else:
                continue
            graph[m] |= {o for n in names if (o := owner(n)) and o != m}
    return graph


def test_no_import_circle_between_modules():
    """Issue 37: none, not even through an import inside a function (the objects that draw
    themselves name their drawers, rollingtop._figures; their HTML views are registered,
    rollingtop._html.register_view). Annotations-only imports (``if TYPE_CHECKING:``) count."""
    graph = _import_graph()
    assert graph["rollingtop.reduction.level"]  # the walk sees the package's imports
    state: dict[str, int] = {}  # 1: on the path, 2: done
    circles = []

    def visit(m: str, path: list[str]) -> None:
        state[m] = 1
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                circles.append(" -> ".join(path[path.index(n) :] + [n]))
            elif n not in state:
                visit(n, [*path, n])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    assert not circles, "import circles:\n" + "\n".join(circles)
