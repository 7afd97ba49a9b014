"""HTML for notebooks (the objects' ``_repr_html_``): a title line and a few compact tables, in
the spirit of xarray's HTML view. Built from plain values (numbers, strings, dicts): each
object puts its own rows together, so this module knows none of rollingtop's types."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from html import escape
from numbers import Integral, Real
from typing import Any, NamedTuple

__all__ = [
    "Num",
    "block",
    "count",
    "html_view",
    "number",
    "register_view",
    "row_table",
    "table",
    "trajectory_html",
]

#: The HTML view of each type that has one registered (:func:`register_view`).
_VIEWS: dict[type, Callable[[Any], str]] = {}


def register_view(cls: type, view: Callable[[Any], str]) -> None:
    """Make ``view(obj)`` the HTML view (:func:`html_view`) of ``cls`` and its subclasses.

    The module that composes a type's view registers it (``rollingtop.reduction._display``,
    imported by ``rollingtop.reduction``), so the type's own module, whose ``_repr_html_``
    calls :func:`html_view`, never imports the module that reads it: no import cycle."""
    _VIEWS[cls] = view


def html_view(obj: object) -> str:
    """The registered HTML view of ``obj``'s type, or of its nearest base that has one."""
    for cls in type(obj).__mro__:
        if cls in _VIEWS:
            return _VIEWS[cls](obj)
    raise LookupError(f"no HTML view is registered for {type(obj).__name__}")


#: Scoped to the ``rollingtop-repr`` block; Jupyter's theme variables where they exist.
STYLE = (
    "<style>"
    ".rollingtop-repr{font-family:var(--jp-content-font-family,sans-serif);font-size:12px;"
    "line-height:1.35;margin:2px 0}"
    ".rollingtop-repr .rt-title{font-weight:600}"
    ".rollingtop-repr .rt-sub{color:var(--jp-content-font-color2,#555)}"
    ".rollingtop-repr .rt-section{font-weight:600;margin:6px 0 1px 0}"
    ".rollingtop-repr table{border-collapse:collapse;margin:0 0 2px 0;font-size:12px;"
    "display:table}"
    ".rollingtop-repr th,.rollingtop-repr td{padding:1px 10px 1px 0;border:none;"
    "text-align:right;white-space:nowrap}"
    ".rollingtop-repr th{font-weight:600}"
    ".rollingtop-repr .rt-text{text-align:left;white-space:normal}"
    "</style>"
)


def number(x: Any, digits: int = 6) -> str:
    """``x`` for a table: a float to ``digits`` significant digits (``inf``, ``-inf``; NaN and
    ``None`` as a dash), an integer as it is, a bool as yes/no, anything else as text."""
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, Integral):
        return str(int(x))
    if isinstance(x, Real):
        v = float(x)
        return "–" if math.isnan(v) else f"{v:.{digits}g}"
    return str(x)


class Num(NamedTuple):
    """A number for a table cell shown to ``digits`` significant digits (:func:`number`)."""

    value: Any
    digits: int


def _cell(x: Any) -> str:
    if isinstance(x, str):
        return f'<td class="rt-text">{escape(x)}</td>'
    if isinstance(x, Num):
        return f"<td>{escape(number(x.value, x.digits))}</td>"
    return f"<td>{escape(number(x))}</td>"


def table(header: Sequence[str] | None, rows: Iterable[Sequence[Any]]) -> str:
    """A table: a header row (if given), then ``rows``; numbers go through :func:`number`
    (:class:`Num` to other digits), strings are escaped and left-aligned."""
    listed = [list(row) for row in rows]
    text = [isinstance(x, str) for x in listed[0]] if listed else []  # each column's alignment
    head = "".join(
        ('<th class="rt-text">' if k < len(text) and text[k] else "<th>") + f"{escape(h)}</th>"
        for k, h in enumerate(header or ())
    )
    body = "".join("<tr>" + "".join(_cell(x) for x in row) + "</tr>" for row in listed)
    # a class of its own: themes that style every bare table (mkdocs-material) leave it alone
    return f'<table class="rt-table">{f"<tr>{head}</tr>" if head else ""}{body}</table>'


def row_table(values: Mapping[str, Any]) -> str:
    """``values`` as a table of one row under a header of their names (a body's parameters, a
    level's integrals)."""
    return table(list(values), [list(values.values())])


def count(n: int, one: str, many: str | None = None) -> str:
    """``"1 centre"``, ``"2 centres"`` (``many`` defaults to ``one + "s"``)."""
    return f"{n} {one if n == 1 else (many or one + 's')}"


def block(title: str, subtitle: str, sections: Sequence[tuple[str, str]]) -> str:
    """The whole view: the title (the object's type), a line saying what it is, then each
    ``(name, html)`` section under its name (an empty name: no heading)."""
    parts = [
        f'<div class="rollingtop-repr">{STYLE}',
        f'<div><span class="rt-title">{escape(title)}</span> '
        f'<span class="rt-sub">{escape(subtitle)}</span></div>',
    ]
    for name, html in sections:
        if name:
            parts.append(f'<div class="rt-section">{escape(name)}</div>')
        parts.append(html)
    return "".join(parts) + "</div>"


def trajectory_html(
    summary: Mapping[str, Any], body: Mapping[str, float], head: Mapping[str, Any]
) -> str:
    """The view of a :class:`~rollingtop.Trajectory` from its :meth:`summary`, its body's
    parameters and ``head`` (``model, description, samples, rtol, atol``): the motion, each first
    integral's initial value and largest drift (absolute, and relative to ``|initial|``), the
    constraints' residuals, the reactions."""
    stats, react, cons = summary["stats"], summary["reactions"], summary["constraints"]
    motion = {
        "t_end": summary["t_end"],
        "samples": head["samples"],
        "steps": stats["steps"],
        "rejected": stats["rejected_steps"],
        "rtol": head["rtol"],
        "atol": head["atol"],
        "wall time (s)": stats["wall_time_s"],
    }
    if "projection_passes" in stats:  # [integration] project_integrals
        motion["projection passes"] = stats["projection_passes"]
    rows = [
        [name, v["initial"], v["final"], Num(v["max_abs_drift"], 3), Num(v["max_rel_drift"], 3)]
        for name, v in summary["integrals"].items()
    ]
    contact = {
        "min normal force": react["min_normal_force"],
        "max friction ratio": react["max_friction_ratio"],
        "contact lost at": react["contact_lost_at"],
        "max constraint residual": Num(cons["max_abs_residual"], 3),
        "frame orthonormality error": Num(cons["orthonormality_max_error"], 3),
    }
    header = ["integral", "initial", "final", "max |I - I0|", "max |I - I0| / size"]
    return block(
        "rollingtop.Trajectory",
        f"{head['model']} model ({head['description']})",
        [
            ("body", row_table(body)),
            ("motion", row_table(motion)),
            ("first integrals along the samples", table(header, rows)),
            ("contact", row_table(contact)),
        ],
    )
