"""Griffe extension for the API reference: the docstrings' Sphinx roles as Markdown.

The source's docstrings are numpy style and cross-reference with Sphinx roles
(``:func:`simulate```, ``:class:`~rollingtop.trajectory.Trajectory```, ``:mod:`.level```), which
mkdocstrings would print as they are. Each role becomes an optional autorefs link: a link to the
object's entry when the site documents it, else its name in code font (no warning, so the strict
build is unaffected). A paragraph ending in the reST literal marker ``::`` ends in ``:``, since
Markdown shows the indented block after it as code anyway. Only the rendered site changes;
the source is not touched. Loaded by ``mkdocs.yml`` (handlers.python.options.extensions).
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:func|class|mod|data|attr|meth|exc|obj):`(?P<tilde>~?)(?P<target>[^`]+)`")
LITERAL = re.compile(r"(?<=\S)::[ \t]*$", re.MULTILINE)


def _module_of(obj: griffe.Object) -> griffe.Object:
    while not obj.is_module and obj.parent is not None:
        obj = obj.parent
    return obj


def _resolve(target: str, obj: griffe.Object, collection: Any) -> str:
    """The full path that ``target``, written in ``obj``'s docstring, most likely names."""
    module = _module_of(obj)
    if target.startswith("."):  # relative to the module's package
        dots = len(target) - len(target.lstrip("."))
        base = module if module.is_init_module else module.parent
        for _ in range(dots - 1):
            base = base.parent if base is not None and base.parent is not None else base
        return f"{base.path}.{target.lstrip('.')}" if base is not None else target.lstrip(".")
    if target.startswith("rollingtop"):
        return target
    scopes = [obj, *([obj.parent] if obj.parent is not None else []), module]
    for scope in scopes:
        candidate = f"{scope.path}.{target}"
        try:
            collection[candidate]
        except Exception:  # noqa: BLE001  (any lookup failure: try the next scope)
            continue
        return candidate
    return f"{module.path}.{target}"


def _convert(text: str, obj: griffe.Object, collection: Any) -> str:
    def link(match: re.Match[str]) -> str:
        target = match["target"]
        title = target.rsplit(".", 1)[-1] if match["tilde"] else target.lstrip(".")
        identifier = _resolve(target, obj, collection)
        return (
            f'<autoref identifier="{html.escape(identifier)}" optional>'
            f"<code>{html.escape(title)}</code></autoref>"
        )

    return LITERAL.sub(":", ROLE.sub(link, text))


class SphinxRoles(griffe.Extension):
    """Rewrite every docstring of the loaded package once it is fully loaded."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        collection = loader.modules_collection
        stack: list[griffe.Object] = [pkg]
        while stack:
            obj = stack.pop()
            if obj.docstring is not None:
                obj.docstring.value = _convert(obj.docstring.value, obj, collection)
            stack.extend(m for m in obj.members.values() if not m.is_alias)
