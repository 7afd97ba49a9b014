"""The reduction's objects in a notebook: the HTML views (``_repr_html_``) of a level set
(:class:`~rollingtop.reduction.LevelSet`, every model's kind), of its steady motions
(:class:`~rollingtop.reduction.SteadyMotions`) and orbits (:class:`~rollingtop.reduction.Orbits`),
and of a bifurcation diagram (:class:`~rollingtop.reduction.bifurcation.BifurcationDiagram`).

Each view is registered for its type (:func:`rollingtop._html.register_view`) when
:mod:`rollingtop.reduction` is imported, and each type's ``_repr_html_`` asks
:func:`rollingtop._html.html_view` for it: the types' modules never import this one, which
imports them. Their ``.plot()`` draws with :mod:`rollingtop.plot` by name
(:mod:`rollingtop._figures`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from html import escape

from rollingtop._html import Num, block, count, register_view, row_table, table
from rollingtop.contact import get_model
from rollingtop.reduction._orbit import Orbits
from rollingtop.reduction.bifurcation import BifurcationDiagram
from rollingtop.reduction.level import Level, LevelSetError
from rollingtop.reduction.steady import SteadyMotion, SteadyMotions, steady_motions

__all__ = [
    "diagram_html",
    "level_html",
    "orbits_html",
    "steady_count",
    "steady_html",
]


def steady_count(motions: Sequence[SteadyMotion]) -> str:
    """``"3 steady motions: 2 centres, 1 saddle"`` (degenerate ones named where there are)."""
    kinds = Counter(m.type for m in motions)
    parts = [count(kinds["center"], "centre"), count(kinds["saddle"], "saddle")]
    if kinds["degenerate"]:
        parts.append(count(kinds["degenerate"], "degenerate"))
    return f"{count(len(motions), 'steady motion')}: {', '.join(parts)}"


def _title(obj: object) -> str:
    """The name a user imports the object's type by."""
    public = {
        "SteadyMotions": "rollingtop.reduction",
        "Orbits": "rollingtop.reduction",
        "BifurcationDiagram": "rollingtop.reduction.bifurcation",
    }
    name = type(obj).__name__
    return f"{public.get(name, 'rollingtop.reduction')}.{name}"


def _model(level: Level) -> str:
    return f"{level.model} model ({get_model(level.model).description})"


def level_html(level: Level) -> str:
    """A level set: its model, its integrals and pole case, the body, and how many steady
    motions it has (or why it has no isolated one)."""
    try:
        motions = steady_motions(level)
        steady = steady_count(motions)
        if motions:
            steady += f"; the lowest U = {min(m.U for m in motions):.6g}"
    except LevelSetError as err:
        steady = str(err)
    sections = [
        ("level", row_table({**level.values(), "pole case": level.pole or "none"})),
        ("body", row_table(level.body.to_dict())),
        ("steady motions", f"<div>{escape(steady)}</div>"),
    ]
    return block(_title(level), _model(level), sections)


def steady_html(motions: SteadyMotions) -> str:
    """The steady motions of a level: the count by type, then ``rollingtop equilibria``'s
    columns, one row per motion."""
    level = motions.level
    header = [
        "gamma3",
        "U",
        "type",
        "omega",
        "period",
        "psi'",
        "|v_CoM|",
        "CoM radius",
        "linearly stable",
    ]
    rows = [
        [
            m.gamma3,
            m.U,
            m.type,
            m.frequency,
            m.period,
            m.precession_rate,
            m.com_speed,
            m.com_radius,
            m.linearly_stable,
        ]
        for m in motions
    ]
    sections = [("", table(header, rows)), ("", f"<div>{escape(_model(level))}</div>")]
    return block(_title(motions), f"{steady_count(motions)} on {level.describe()}", sections)


def orbits_html(found: Orbits) -> str:
    """The orbits of a level at one energy: the level with ``h`` and the full energy, then a
    row per orbit (``rollingtop orbits``' turning points, period and its error, kind)."""
    level, h = found.level, found.h
    values = {**level.values(), "h": h, "energy E": level.full_energy(h)}
    header = ["gamma3_min", "gamma3_max", "period", "+-", "kind", "through the pole", "note"]
    rows = [
        [
            Num(o.gamma3_min, 10),
            Num(o.gamma3_max, 10),
            Num(o.period, 12),
            Num(o.period_error, 2),
            o.kind,
            o.pole_passage,
            o.note,
        ]
        for o in found
    ]
    return block(
        _title(found),
        f"{count(len(found), 'orbit')} on {level.describe()} at h = {h:g}",
        [
            ("level", row_table(values)),
            ("", table(header, rows)),
            ("", f"<div>{escape(_model(level))}</div>"),
        ],
    )


def diagram_html(diagram: BifurcationDiagram) -> str:
    """A bifurcation diagram: the body, ``(M3, C1)`` and the window, the counts, the folds and
    the regions (what orbits each holds, a representative level)."""
    c2, h = diagram.C2_grid, diagram.h_grid
    window = {
        "M3": diagram.M3,
        "C1": diagram.C1,
        "C2 from": c2[0],
        "C2 to": c2[-1],
        "h from": h[0],
        "h to": h[-1],
        "grid": f"{len(c2)} x {len(h)}",
    }
    folds = [[f.C2, f.h, f.gamma3, f.kind] for f in diagram.folds]
    regions = [[r.name, r.label, r.C2, r.h, r.cells] for r in diagram.regions]
    branches = count(len(diagram.branches), "branch", "branches")
    summary = (
        f"{branches} of critical values, {count(len(diagram.folds), 'fold')}, "
        f"{count(len(diagram.regions), 'region')}"
    )
    return block(
        _title(diagram),
        "meridian model, the (C2, h) plane of " + summary,
        [
            ("body", row_table(diagram.body.to_dict())),
            ("window", row_table(window)),
            ("folds", table(["C2", "h", "gamma3", "kind"], folds)),
            ("regions", table(["region", "a level in it holds", "C2", "h", "grid cells"], regions)),
        ],
    )


register_view(Level, level_html)
register_view(SteadyMotions, steady_html)
register_view(Orbits, orbits_html)
register_view(BifurcationDiagram, diagram_html)
