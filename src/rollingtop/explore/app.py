"""The explore page: Panel widgets and Bokeh plots over :mod:`rollingtop.explore.view`.

One :class:`ExplorePage` per browser session. A change of a widget (or a click on a plot) makes
a new :class:`~rollingtop.explore.view.ExploreState`; the work it asks for runs in a thread pool,
off the server's event loop, so the page never blocks; each kind of work (the level's plots, the
diagram, a trajectory, the device's frame, a section) keeps only its newest request -- a newer
one supersedes an older one that has not started, and an older result that arrives late is
dropped. Results are applied to the page on the document's next tick (Bokeh's thread-safe way
in).

The page's view is its parameters (``param``): one per key of the URL's query
(``?model=meridian&C2=-1.0&h=0.8``), kept in step with the URL by Panel
(``pn.state.location.sync``): the URL's values arrive as the parameters' values when the page
loads, and each accepted view sets them, which rewrites the URL. A value is the query's text (or
the number Panel read from it), validated once by :func:`rollingtop.explore.view.parse_query`:
a bad value is shown on the page and the previous valid view stays, in the widgets and the URL.
"""

from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Callable
from concurrent.futures import Executor
from typing import Any
from urllib.parse import parse_qsl, urlencode

import numpy as np
import panel as pn
import param
from bokeh.events import Tap

from rollingtop._errors import RollingTopError
from rollingtop.contact import MODELS
from rollingtop.devices import DEVICES
from rollingtop.explore._plots import Plots
from rollingtop.explore._work import Latest, new_executor
from rollingtop.explore.path import PATH_SAMPLES, PATH_T_END, path_view
from rollingtop.explore.section import section_view
from rollingtop.explore.view import (
    BODY_KEYS,
    CONTACT_KEYS,
    H_KEY,
    ExploreState,
    cached_diagram_view,
    cached_level_view,
    parse_query,
)

__all__ = ["ExplorePage", "LOOKS", "QUERY_KEYS"]

#: The keys of the page's URL, each a parameter of :class:`ExplorePage`: the model, the body's
#: numbers, every reduced model's level (:attr:`rollingtop.contact.ContactModel.reduction`) and
#: ``h``.
QUERY_KEYS: tuple[str, ...] = (
    "model",
    *BODY_KEYS,
    *CONTACT_KEYS,
    *dict.fromkeys(k for m in MODELS.values() for k in m.reduction),
    H_KEY,
)

#: Device looks of the frame beside the path (``plain``: the body itself).
LOOKS = ("plain", *DEVICES)


def _ignore(*args: Any) -> None:
    """A result nobody will see."""


def _drop_js_callbacks(layout: Any) -> None:
    """Forget the JavaScript callbacks of ``layout``'s widgets in Panel's registry.

    Panel (1.9) keeps every ``jscallback`` in ``panel.links.Callback.registry``, a
    ``WeakKeyDictionary`` keyed on the source widget whose value (the callback) refers back to
    the widget through its ``args``: the key never dies, and each ``EditableFloatSlider`` (its
    text box's callback moves the slider) kept its whole page alive after the session closed,
    about 1.9 MB a session. Written here because Panel offers no way to remove a callback.
    """
    from panel.links import Callback

    mine = {id(obj) for obj in layout.select()}
    for source in [s for s in list(Callback.registry.keys()) if id(s) in mine]:
        Callback.registry.pop(source, None)


def _query_value(doc: str) -> Any:
    """A parameter of the page's view: the URL's text for one key (``None``: not in this view)."""
    return param.Parameter(default=None, doc=doc)


class ExplorePage(pn.viewable.Viewer):
    """The widgets, plots and callbacks of one session; :attr:`layout` is what Panel serves.

    Its parameters (:data:`QUERY_KEYS`) are the view as the URL's query carries it: the text
    of each value (``repr`` of a float), or the number Panel read from the URL; ``None`` for a
    key the view does not have (another model's level).

    Parameters
    ----------
    base : ExploreState
        The scenario's view; the URL's query is applied to it.
    look : str
        The device look of the frame beside the path (:data:`LOOKS`).
    query : mapping, optional
        The URL's query parameters (default: the session's, from ``pn.state.location``).
    executor : concurrent.futures.Executor, optional
        Where the page's work runs: the server's pool, shared by its sessions (default: a pool
        of the page's own, shut down by :meth:`close`).
    location : panel.io.location.Location, optional
        The URL kept in step with the view (default: the session's, ``pn.state.location``).
    """

    model = _query_value("the contact model's name")
    R = _query_value("the sphere's radius")
    m = _query_value("the body's mass")
    a3 = _query_value("the centre of mass's offset along the axis")
    I1 = _query_value("the body's equatorial moment of inertia (I2 = I1)")
    I3 = _query_value("the body's axial moment of inertia")
    g = _query_value("gravity")
    angle = _query_value("the oblique model's constraint angle phi (radians)")
    M3 = _query_value("level: Lagrange's integral I3 w3")
    C1 = _query_value("level: the area integral")
    C2 = _query_value("level: the paper's F6 (meridian, shell-rotor)")
    p_horizontal = _query_value("level: the horizontal momentum (smooth)")
    jellett = _query_value("level: Jellett's integral")
    routh = _query_value("level: Routh's integral (rough)")
    rubber_spin = _query_value("level: the rubber model's spin integral")
    h = _query_value("the reduced energy")

    def __init__(
        self,
        base: ExploreState,
        look: str = "plain",
        query: dict[str, Any] | None = None,
        executor: Executor | None = None,
        location: Any = None,
    ) -> None:
        super().__init__()  # type: ignore[no-untyped-call]
        self.doc = pn.state.curdoc
        self.location = pn.state.location if location is None else location
        self.muted = False
        self.state = base
        self.look = look
        self.message = pn.pane.Alert(
            "", alert_type="danger", visible=False, css_classes=["rt-message"]
        )
        self.readout = pn.pane.HTML("", css_classes=["rt-readout"])
        self.path_summary = pn.pane.HTML(
            "click the phase portrait to start a trajectory", css_classes=["rt-path"]
        )
        self.drawn: ExploreState | None = None  # the last view whose plots were drawn
        self.last_traj: Any = None  # the last clicked trajectory (for the device's frame)
        self.last_section: tuple[Any, Any] | None = None  # a section's points and states
        self.plots = Plots()
        self.plots.portrait.on_event(Tap, self._on_portrait_tap)
        self.plots.diagram.on_event(Tap, self._on_diagram_tap)
        self._build_widgets()
        self.own_executor = executor is None
        pool = new_executor() if executor is None else executor
        self.executor = pool
        self.level_work = Latest(pool, self.on_document, self._compute_level, self._apply_level)
        self.diagram_work = Latest(pool, self.on_document, cached_diagram_view, self._apply_diagram)
        self.path_work = Latest(pool, self.on_document, self._compute_path, self._apply_path)
        self.frame_work = Latest(pool, self.on_document, self._compute_frame, self._apply_frame)
        self.synced: list[str] = []  # the parameters kept in step with the URL
        self.loading = True  # the URL's view is read: nothing drawn yet
        self.quiet = False  # the page sets its own parameters
        self._set_query(self.state)
        # after Panel's own watcher (precedence 0), which writes each change into the URL: a
        # value this page refuses and sets back is then written over, not left there
        self.param.watch(self._on_query, list(QUERY_KEYS), precedence=1)
        if query is None and self.location is not None:  # the URL's values arrive (Panel)
            asked = dict(self.location.query_params)
            self._refuse_unknown(asked)
            self._resync([k for k in QUERY_KEYS if k in asked or getattr(self, k) is not None])
        elif query:
            self._refuse_unknown(query)
            self.param.update(**{k: v for k, v in query.items() if k in QUERY_KEYS})
        self.loading = False
        self._set_query(self.state)
        self._prune_url()
        self._sync_widgets()
        self.layout = self._layout()
        self._refresh(diagram=True)

    def __panel__(self) -> Any:
        return self.layout

    # ---- the view's parameters and the URL -----------------------------------------------
    def _keys(self) -> list[str]:
        """The keys of the current view's query."""
        return [k for k in QUERY_KEYS if getattr(self, k) is not None]

    def _set_query(self, state: ExploreState) -> None:
        """The parameters set to ``state`` (without the page reacting); Panel rewrites the URL,
        without the keys of another view."""
        self.quiet = True
        try:
            self.param.update(**(dict.fromkeys(QUERY_KEYS) | state.to_query()))
        finally:
            self.quiet = False
        if not self.loading:
            self._resync(self._keys())

    def _resync(self, keys: list[str]) -> None:
        """Keep exactly ``keys`` in step with the URL: a key that leaves the view leaves the
        URL (``unsync``), and the URL's values of the new keys are read (``sync``)."""
        if self.location is None or keys == self.synced:
            return
        if self.synced:
            self.location.unsync(self)
        self.synced = keys
        self.location.sync(self, keys, on_error=self._on_url_error)

    def _prune_url(self) -> None:
        """Drop the URL's keys that no view has (reported when the page loaded): Panel keeps
        the keys it does not sync."""
        if self.location is None:
            return
        query = dict(parse_qsl(self.location.search.lstrip("?"), keep_blank_values=True))
        kept = {k: v for k, v in query.items() if k in QUERY_KEYS}
        if kept != query:
            self.quiet = True  # the same view: the parameters may take Panel's numbers
            try:
                self.location.search = "?" + urlencode(kept) if kept else ""
            finally:
                self.quiet = False

    def _refuse_unknown(self, query: dict[str, Any]) -> None:
        """A key of the URL that no view has: said by name (:func:`parse_query`'s message)."""
        unknown = {k: v for k, v in query.items() if k not in QUERY_KEYS}
        if unknown:
            try:
                parse_query(unknown, self.state)
            except RollingTopError as err:
                self._show_error(f"URL: {err}")

    def _on_url_error(self, values: dict[str, Any]) -> None:  # pragma: no cover - Panel's
        self._show_error(f"URL: cannot read {', '.join(values)}")

    def _on_query(self, *events: Any) -> None:
        """The URL's values arrived (or a script set the parameters): the view they ask for,
        the changed values applied to the current view (:func:`parse_query`: ``model`` first)."""
        if self.quiet:
            return
        changes = {e.name: e.new for e in events if e.new is not None}
        if self.loading:
            try:
                self.state = parse_query(changes, self.state)
            except RollingTopError as err:
                self._show_error(f"URL: {err}")
            return
        if not self._accept(changes):
            self._set_query(self.state)

    # ---- running on the document -------------------------------------------------------
    def on_document(self, fn: Callable[[], None]) -> None:
        """Run ``fn`` on the session's document (next tick), or now without a document (tests);
        a result for a session that has gone is dropped."""
        if self.doc is None:
            fn()
        elif getattr(self.doc, "session_context", None) is not None:
            self.doc.add_next_tick_callback(fn)

    def close(self) -> None:
        """Drop what the page holds (its session has gone): its plots' data, the last
        trajectory and section, the widgets' callbacks."""
        for work in (self.level_work, self.diagram_work, self.path_work, self.frame_work):
            work.apply = _ignore
        self.last_traj = None
        self.last_section = None
        self.plots.clear()
        _drop_js_callbacks(self.layout)
        if self.location is not None and self.synced:  # the URL's watchers hold the page
            # (Panel may have unsynced it already, as its session went: ValueError then)
            with contextlib.suppress(ValueError):
                self.location.unsync(self)
            self.synced = []
        if self.own_executor:
            self.executor.shutdown(wait=False, cancel_futures=True)

    def _show_error(self, text: str) -> None:
        self.message.object = text
        self.message.visible = True

    def _clear_error(self) -> None:
        self.message.visible = False

    # ---- widgets -------------------------------------------------------------------------
    def _slider(self, name: str, value: float, lo: float, hi: float) -> Any:
        w = pn.widgets.EditableFloatSlider(
            label=name, value=value, start=lo, end=hi, step=(hi - lo) / 400, width=260
        )
        w.param.watch(self._on_widget, "value")
        return w

    def _build_widgets(self) -> None:
        names = [m.name for m in MODELS.values() if m.own_inertia == self.state.body.has_shell]
        self.model_select = pn.widgets.Select(
            label="contact model", options=names, value=self.state.model, width=260
        )
        self.model_select.param.watch(self._on_model, "value")
        self.look_select = pn.widgets.Select(
            label="device look", options=list(LOOKS), value=self.look, width=260
        )
        self.look_select.param.watch(self._on_look, "value")
        b = self.state.body
        self.body_sliders = {}
        for key in BODY_KEYS:
            v = float(getattr(b, key))
            lo, hi = (-b.R, b.R) if key == "a3" else (0.0, 3.0 * max(v, 0.1))
            self.body_sliders[key] = self._slider(key, v, lo, hi)
        self.level_box = pn.Column()
        self.level_sliders: dict[str, Any] = {}
        self._build_level_sliders()
        self.contact_box = pn.Column()
        self.contact_sliders: dict[str, Any] = {}
        self._build_contact_sliders()

    def _build_contact_sliders(self) -> None:
        """A slider for each of the model's parameters on the page (the oblique model's angle,
        over ``[-pi/2, pi/2]``: ``phi`` and ``phi + pi`` are one constraint)."""
        self.contact_sliders = {
            key: self._slider(key, v, -math.pi / 2, math.pi / 2) for key, v in self.state.contact
        }
        self.contact_box.objects = (
            [pn.pane.Markdown("**contact**"), *self.contact_sliders.values()]
            if self.contact_sliders
            else []
        )

    def _build_level_sliders(self) -> None:
        self.level_sliders = {}
        items = {**self.state.level, **({"h": self.state.h} if self.state.level else {})}
        for key, v in items.items():
            span = max(1.0, 2.0 * abs(v))
            self.level_sliders[key] = self._slider(key, v, v - span, v + span)
        header = [pn.pane.Markdown("**level**")] if self.level_sliders else []
        self.level_box.objects = [*header, *self.level_sliders.values()]

    def _sync_widgets(self) -> None:
        """The widgets set to :attr:`state`, without their callbacks."""
        self.muted = True
        try:
            self.model_select.value = self.state.model
            for key, w in self.body_sliders.items():
                w.value = float(getattr(self.state.body, key))
            if set(dict(self.state.contact)) != set(self.contact_sliders):
                self._build_contact_sliders()
            for key, v in self.state.contact:
                w = self.contact_sliders[key]
                w.start, w.end = min(w.start, v), max(w.end, v)
                w.value = float(v)
            items = {**self.state.level, **({"h": self.state.h} if self.state.level else {})}
            if set(items) != set(self.level_sliders):
                self._build_level_sliders()
            for key, v in items.items():
                w = self.level_sliders[key]
                if not w.start <= v <= w.end:  # widen the slider to take the value
                    span = max(1.0, 2.0 * abs(v))
                    w.start, w.end = min(w.start, v - span), max(w.end, v + span)
                w.value = float(v)
        finally:
            self.muted = False

    def _layout(self) -> Any:
        controls = pn.Column(
            self.model_select,
            self.look_select,
            pn.pane.Markdown("**body**"),
            *self.body_sliders.values(),
            self.contact_box,
            self.level_box,
            width=290,
        )
        plots = pn.Column(
            pn.Row(self.plots.portrait_pane, self.plots.diagram_pane),
            pn.Row(self.plots.potential_pane, self.plots.path_pane, self.plots.frame),
            self.path_summary,
        )
        title = pn.pane.Markdown("## rollingtop explore: a rolling spherical top, reduced")
        return pn.Column(title, self.message, self.readout, pn.Row(controls, plots))

    # ---- callbacks -----------------------------------------------------------------------
    def _query_of_widgets(self) -> dict[str, str]:
        """The widgets' values as a URL query (an emptied text field: ``""``, which
        :func:`parse_query` refuses by name)."""
        query = {"model": self.state.model}
        sliders = (self.body_sliders, self.contact_sliders, self.level_sliders)
        for k, w in (item for group in sliders for item in group.items()):
            query[k] = "" if w.value is None else repr(float(w.value))
        return query

    def _accept(self, query: dict[str, str], base: ExploreState | None = None) -> bool:
        """Apply ``query`` to the current view: the new view, or a message and the old view."""
        try:
            state = parse_query(query, base or self.state)
        except RollingTopError as err:
            self._show_error(str(err))
            self._sync_widgets()  # back to the previous valid view
            return False
        self._clear_error()
        axis = self._axis()
        diagram = (
            state.model != self.state.model
            or state.contact != self.state.contact
            or state.body != self.state.body
            or {k: v for k, v in state.level.items() if k != axis}
            != {k: v for k, v in self.state.level.items() if k != axis}
            or not self.plots.shows_mark(state.level.get(axis, 0.0), state.h)
        )
        self.state = state
        self._refresh(diagram=diagram)
        return True

    def _axis(self) -> str:
        from rollingtop.reduction.classify import AXES

        return AXES.get(self.state.model, "")

    def _on_widget(self, event: Any) -> None:
        if self.muted:
            return
        self._accept(self._query_of_widgets())

    def _on_model(self, event: Any) -> None:
        if self.muted:
            return
        try:
            state = self.state.with_model(event.new)
        except RollingTopError as err:
            self._show_error(f"model {event.new}: {err}")
            self._sync_widgets()
            return
        self._clear_error()
        self.state = state
        self._sync_widgets()
        self._refresh(diagram=True)

    def _on_look(self, event: Any) -> None:
        self.look = event.new
        traj = self.last_traj
        if traj is not None:
            self.frame_work.request(traj)

    def _on_portrait_tap(self, event: Any) -> None:
        if not self.state.reduces:
            self._on_section_tap(event)
            return
        self.plots.start.data = {"x": [event.x], "y": [event.y]}
        self.path_summary.object = "integrating ..."
        self.path_work.request((self.state, float(event.x), float(event.y)))

    def _on_diagram_tap(self, event: Any) -> None:
        if not self.state.reduces:
            return
        axis = self._axis()
        query = self._query_of_widgets() | {axis: repr(float(event.x)), "h": repr(float(event.y))}
        if self._accept(query):
            self._sync_widgets()

    def _on_section_tap(self, event: Any) -> None:
        section = self.last_section
        if section is None or self.drawn != self.state:  # the section of another view
            return
        points, states = section
        k = int(np.argmin(np.hypot(points[:, 0] - event.x, points[:, 1] - event.y)))
        self.plots.start.data = {"x": [points[k, 0]], "y": [points[k, 1]]}
        self.path_summary.object = "integrating ..."
        self.path_work.request((self.state, states[k], None))

    def _refresh(self, diagram: bool) -> None:
        """Ask for the plots of :attr:`state`; the parameters, and so the URL, follow. A clicked
        orbit belonged to the previous view: it goes."""
        self.plots.clear_clicked()
        self.level_work.request(self.state)
        if diagram and self.state.reduces:
            self.diagram_work.request(self.state)
        elif self.state.reduces:  # the same curves: only the marker moves
            self._move_mark()
        self._set_query(self.state)

    def _move_mark(self) -> None:
        self.plots.move_mark(self.state.level[self._axis()], self.state.h)

    # ---- work and its results ------------------------------------------------------------
    def _compute_level(self, state: ExploreState) -> Any:
        if state.reduces:
            return cached_level_view(state)
        return section_view(state)

    def _apply_level(self, state: ExploreState, view: Any) -> None:
        if isinstance(view, Exception):  # the analysis refuses the view: the last drawn stays
            self._show_error(str(view))
            if self.drawn is not None and self.drawn != state:
                self.state = self.drawn
                self._sync_widgets()
                self._set_query(self.state)
            return
        self.drawn = state
        self.readout.object = f"<b>{view.readout}</b>"
        if not state.reduces:
            self.last_section = (view.points, view.states)
            self.plots.show_section(view)
            return
        if view.note:
            self.readout.object += f" ({view.note})"
        self.plots.show_level(state, view)
        self._move_mark()

    def _apply_diagram(self, state: ExploreState, view: Any) -> None:
        if isinstance(view, Exception):  # no diagram for this level: said in its title
            self.plots.no_diagram(str(view))
            return
        self.plots.show_diagram(view)
        self._move_mark()

    def _compute_path(self, request: tuple[ExploreState, Any, Any]) -> Any:
        state, x, w = request
        if w is None:  # a crossing of the section: its state as it is
            import warnings

            from rollingtop._errors import ContactLostWarning
            from rollingtop.simulate import simulate

            with warnings.catch_warnings():  # in the page's summary instead
                warnings.simplefilter("ignore", ContactLostWarning)
                model = state.contact_model
                traj = simulate(state.body, model, x, t_end=PATH_T_END, samples=PATH_SAMPLES)
            return traj, None
        view = path_view(state, x, w)
        return view.trajectory, view

    def _apply_path(self, request: Any, result: Any) -> None:
        if isinstance(result, Exception):
            self.path_summary.object = f"no trajectory: {result}"
            return
        traj, view = result
        self.last_traj = traj
        pos = traj.y[:, 15:17]
        self.plots.show_path(pos[:, 0], pos[:, 1], view.orbit if view is not None else None)
        text = view.summary if view is not None else "from the clicked crossing"
        lost = traj.contact_lost_at
        if lost is not None:
            text += f"; the normal force turns negative at t = {lost:.6g} (the contact is lost)"
        self.path_summary.object = f"trajectory: t = 0 .. {traj.t[-1]:g}, {text}"
        self.frame_work.request(traj)

    def _compute_frame(self, traj: Any) -> Any:
        from rollingtop.plot.animation import frame_figure

        look = self.look
        if look != "plain":
            from rollingtop.devices import check_device

            check_device(look, traj.model)
        fig = frame_figure(traj, float(traj.t[-1]), look=look, size=(4.0, 4.0), dpi=75)
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return buf.getvalue()

    def _apply_frame(self, traj: Any, png: Any) -> None:
        if isinstance(png, Exception):
            self.path_summary.object += f" (device: {png})"
            return
        self.plots.frame.object = png
