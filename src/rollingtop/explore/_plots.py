"""The explore page's Bokeh figures and what each view puts into them: the phase portrait (or a
Poincare section), ``U``, the bifurcation diagram, the contact point's path, the device's frame.
Data go through ``ColumnDataSource`` objects, so a redraw sends arrays, not a new figure."""

from __future__ import annotations

from typing import Any

import numpy as np
import panel as pn
from bokeh.models import ColumnDataSource, Range1d
from bokeh.models.annotations import Span
from bokeh.plotting import figure

from rollingtop.explore.section import SectionView
from rollingtop.explore.view import DiagramView, ExploreState, LevelView

__all__ = ["Plots"]

_CENTRE, _SADDLE, _CURRENT, _PATH = "#1b7837", "#762a83", "#d6604d", "#2166ac"
#: The periodic orbits marked on a section, by type (rollingtop.plot.periodic's colours).
_ORBIT_COLOURS = {
    "attracting": "#2ca02c",
    "repelling": "#d62728",
    "saddle": "#ff7f0e",
    "elliptic": "#1f77b4",
    "neutral": "#7f7f7f",
}


def _figure(title: str, x_label: str, y_label: str, **kw: Any) -> Any:
    fig = figure(
        title=title,
        height=300,
        width=380,
        tools="pan,wheel_zoom,reset,tap",
        toolbar_location="above",
        **kw,
    )
    fig.xaxis.axis_label, fig.yaxis.axis_label = x_label, y_label
    return fig


def _source(*columns: str) -> Any:
    return ColumnDataSource({c: [] for c in columns})


class Plots:
    """The figures of one page and their sources; :meth:`show_level`, :meth:`show_diagram`,
    :meth:`show_section` and :meth:`show_path` draw a view into them."""

    def __init__(self) -> None:
        self.back, self.current, self.section = (
            _source("x", "y"),
            _source("x", "y"),
            _source("x", "y"),
        )
        self.steady = _source("x", "y", "U", "colour")
        self.orbits = _source("x", "y", "colour")
        self.start, self.clicked, self.U = _source("x", "y"), _source("x", "y"), _source("x", "y")
        p = self.portrait = _figure("phase portrait (click: start a trajectory)", "gamma3", "w_tau")
        p.line("x", "y", source=self.back, color="#9ab", line_width=1)
        p.scatter("x", "y", source=self.section, color=_PATH, size=3)
        p.scatter(
            "x",
            "y",
            source=self.orbits,
            color="colour",
            marker="diamond",
            size=13,
            line_color="black",
        )
        p.line(
            "x", "y", source=self.current, color=_CURRENT, line_width=2.5, legend_label="current h"
        )
        p.scatter("x", "y", source=self.steady, color="colour", size=8)
        p.line(
            "x", "y", source=self.clicked, color=_PATH, line_width=2, legend_label="clicked orbit"
        )
        p.scatter("x", "y", source=self.start, marker="x", color="black", size=12)
        p.legend.location = "top_left"
        u = self.potential = _figure(
            "effective potential U", "gamma3", "U", y_range=Range1d(start=0.0, end=1.0)
        )
        u.line("x", "y", source=self.U, color="black", line_width=1.5)
        u.scatter("x", "U", source=self.steady, color="colour", size=8)
        self.h_line = Span(location=0.0, dimension="width", line_color=_CURRENT, line_dash="dashed")
        u.add_layout(self.h_line)
        self.centres, self.saddles = _source("x", "y"), _source("x", "y")
        self.folds, self.floor, self.mark = _source("x", "y"), _source("x", "y"), _source("x", "y")
        d = self.diagram = _figure(
            "bifurcation diagram (click: move the level)",
            "C2",
            "h",
            x_range=Range1d(start=0.0, end=1.0),
            y_range=Range1d(start=0.0, end=1.0),
        )
        d.line("x", "y", source=self.floor, color="gray", line_dash="dotted")
        d.line("x", "y", source=self.centres, color=_CENTRE, line_width=2, legend_label="centres")
        d.line(
            "x",
            "y",
            source=self.saddles,
            color=_SADDLE,
            line_width=2,
            line_dash="dashed",
            legend_label="saddles",
        )
        d.scatter("x", "y", source=self.folds, color="black", size=6)
        d.scatter(
            "x",
            "y",
            source=self.mark,
            marker="star",
            color=_CURRENT,
            size=16,
            legend_label="current level",
        )
        d.legend.location = "top_left"
        self.path_source = _source("x", "y")
        self.path = _figure("contact point's path on the plane", "X", "Y", match_aspect=True)
        self.path.line("x", "y", source=self.path_source, color=_PATH, line_width=1.5)
        self.frame = pn.pane.PNG(None, width=280, height=280)
        self.portrait_pane = pn.pane.Bokeh(self.portrait)
        self.diagram_pane = pn.pane.Bokeh(self.diagram)
        self.potential_pane = pn.pane.Bokeh(self.potential)
        self.path_pane = pn.pane.Bokeh(self.path)

    def clear_clicked(self) -> None:
        """Forget the clicked point and its orbit (they belong to the previous view)."""
        self.clicked.data = {"x": [], "y": []}
        self.start.data = {"x": [], "y": []}

    def shows_mark(self, x: float, h: float) -> bool:
        """Whether the diagram's window holds the point ``(x, h)``."""
        xr, yr = self.diagram.x_range, self.diagram.y_range
        return bool(xr.start <= x <= xr.end and yr.start <= h <= yr.end)

    def no_diagram(self, reason: str) -> None:
        """No diagram for this level: its curves cleared, the reason in its title."""
        for src in (self.centres, self.saddles, self.folds, self.floor):
            src.data = {"x": [], "y": []}
        self.diagram.title.text = f"no bifurcation diagram: {reason[:70]}"

    def clear(self) -> None:
        """Every source emptied (the page's session has gone)."""
        for src in (
            self.back,
            self.current,
            self.section,
            self.start,
            self.clicked,
            self.U,
            self.centres,
            self.saddles,
            self.folds,
            self.floor,
            self.mark,
            self.path_source,
        ):
            src.data = {"x": [], "y": []}
        self.steady.data = {"x": [], "y": [], "U": [], "colour": []}
        self.orbits.data = {"x": [], "y": [], "colour": []}
        self.frame.object = None

    def move_mark(self, x: float, h: float) -> None:
        """The current level's point on the diagram."""
        self.mark.data = {"x": [x], "y": [h]}

    def show_reduced(self, reduced: bool) -> None:
        """The plots of a reduction (U, the diagram) shown or hidden; the portrait's titles."""
        self.potential_pane.visible = self.diagram_pane.visible = reduced
        self.portrait.legend.visible = reduced
        if reduced:
            self.portrait.title.text = "phase portrait (click: start a trajectory)"
            self.portrait.yaxis.axis_label = "w_tau"
        else:
            self.portrait.title.text = "Poincare section w_tau = 0 (click: start from a crossing)"
            self.portrait.xaxis.axis_label, self.portrait.yaxis.axis_label = "gamma3", "w_n"

    def show_level(self, state: ExploreState, view: LevelView) -> None:
        """The portrait (background orbits, the current energy's, the steady motions) and U
        with the current ``h`` (cut a little above it, where U runs off to the walls)."""
        self.show_reduced(True)
        self.section.data = {"x": [], "y": []}
        self.orbits.data = {"x": [], "y": [], "colour": []}
        self.back.data = {"x": view.background[0], "y": view.background[1]}
        self.current.data = {"x": view.current[0], "y": view.current[1]}
        colours = [_CENTRE if t == "center" else _SADDLE for _, _, t in view.steady]
        self.steady.data = {
            "x": [s[0] for s in view.steady],
            "y": [0.0] * len(view.steady),
            "U": [s[1] for s in view.steady],
            "colour": colours,
        }
        finite = np.isfinite(view.U_y)
        low = float(np.min(view.U_y[finite])) if finite.any() else state.h
        top = max(state.h, low) + max(1.0, abs(state.h - low))
        shown = np.where(finite & (view.U_y <= top), view.U_y, np.nan)  # a gap where U is high
        self.U.data = {"x": view.U_x, "y": shown}
        lo, hi = min(low, state.h), top
        pad = 0.05 * (hi - lo) or 1.0
        self.potential.y_range.start, self.potential.y_range.end = lo - pad, hi + pad
        self.h_line.location = state.h
        for fig in (self.portrait, self.potential):
            fig.xaxis.axis_label = view.x_label

    def show_diagram(self, view: DiagramView) -> None:
        """The critical values (centres solid, saddles dashed), folds, ``min U`` and the
        current level's point, in the diagram's window."""
        self.diagram.xaxis.axis_label = view.axis
        self.diagram.title.text = "bifurcation diagram (click: move the level)"
        self.centres.data = {"x": view.centres[0], "y": view.centres[1]}
        self.saddles.data = {"x": view.saddles[0], "y": view.saddles[1]}
        self.folds.data = {"x": view.folds[0], "y": view.folds[1]}
        self.floor.data = {"x": view.floor[0], "y": view.floor[1]}
        self.diagram.x_range.start, self.diagram.x_range.end = view.x_range
        self.diagram.y_range.start, self.diagram.y_range.end = view.y_range
        self.move_mark(*view.mark)

    def show_section(self, view: SectionView) -> None:
        """A model without a reduction: its section's points in place of the portrait."""
        self.section.data = {"x": view.points[:, 0], "y": view.points[:, 1]}
        marks = [(p, _ORBIT_COLOURS.get(t, _SADDLE)) for _, t, pts in view.orbits for p in pts]
        self.orbits.data = {
            "x": [float(p[0]) for p, _ in marks],
            "y": [float(p[1]) for p, _ in marks],
            "colour": [c for _, c in marks],
        }
        for src in (self.back, self.current, self.clicked):
            src.data = {"x": [], "y": []}
        self.steady.data = {"x": [], "y": [], "U": [], "colour": []}
        self.show_reduced(False)

    def show_path(self, x: Any, y: Any, orbit: tuple[Any, Any] | None) -> None:
        """The contact point's path, and the clicked orbit on the portrait."""
        self.path_source.data = {"x": x, "y": y}
        if orbit is not None:
            self.clicked.data = {"x": orbit[0], "y": orbit[1]}
