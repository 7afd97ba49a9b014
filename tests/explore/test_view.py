"""The explore page's numbers (rollingtop.explore.view, .path, .section) without a browser:
each against the command line or an independent computation."""

import json
import math
import threading
import time

import numpy as np
import pytest

from rollingtop import ScenarioError
from rollingtop.explore._work import Latest, new_executor
from rollingtop.explore.path import path_view
from rollingtop.explore.section import section_view
from rollingtop.explore.view import (
    default_scenario,
    diagram_view,
    level_view,
    parse_query,
    state_from_scenario,
)
from rollingtop.reduction import LevelSet, reduction_of
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES
from ..test_cli import run_cli

FIG5 = str(EXAMPLES / "fig5.toml")
ENERGY_RTOL = 1e-9  # the reduced energy of a reconstructed state / a trajectory (rtol 1e-10)


#: The pool of the tests of Latest (a server has one, shared by its sessions).
POOL = new_executor()


@pytest.fixture(scope="module")
def fig5():
    return state_from_scenario(load_scenario(FIG5))


def test_the_first_view_is_the_scenarios_level(fig5):
    assert fig5.model == "meridian"
    assert fig5.level == {"M3": 1.0, "C1": 0.5, "C2": -2.0} and fig5.h == 4.0
    assert state_from_scenario(default_scenario()) == fig5  # no scenario: the paper's Fig. 5


@pytest.mark.parametrize("C2", [-2.0, -1.0, -1.6])
def test_the_readout_counts_what_equilibria_prints(capsys, tmp_path, fig5, C2):
    """steady motions: N on the page is `rollingtop equilibria --json`'s count for the same
    level (a scenario file written here with that C2)."""
    view = level_view(parse_query({"C2": repr(C2)}, fig5))
    text = (EXAMPLES / "fig5.toml").read_text().replace("C2 = -2.0", f"C2 = {C2!r}")
    path = tmp_path / "level.toml"
    path.write_text(text)
    code, out, err = run_cli(capsys, "equilibria", str(path), "--json")
    assert code == 0, err
    count = len(json.loads(out)["equilibria"])
    assert view.count == count and view.readout.endswith(f"steady motions: {count}")
    if C2 == -1.0:  # the example: beyond the fold, one
        assert view.count == 1


def test_the_current_orbit_lies_on_the_energy_level(fig5):
    """Every point of the highlighted orbit has rho w_tau^2 / 2 + U = h (the energy written
    again here from U and rho), and U's curve is U."""
    view = level_view(fig5)
    level = fig5.level_set()
    x, w = view.current
    ok = np.isfinite(x)
    theta = np.arccos(x[ok])
    energy = level.U(theta) + 0.5 * level.rho(theta) * w[ok] ** 2
    np.testing.assert_allclose(energy, fig5.h, rtol=1e-9)
    np.testing.assert_allclose(level.U(np.arccos(view.U_x[:50])), view.U_y[:50], rtol=1e-10)
    assert np.isfinite(view.background[0]).sum() > 1000


def test_the_diagram_marks_the_level_and_its_curves_are_critical_values(fig5):
    """Each centre point (C2, h) of the diagram is a steady motion's energy on the level
    (M3, C1, C2): a critical point of that level's U with U = h."""
    from rollingtop.reduction import steady_motions

    view = diagram_view(fig5)
    assert view.mark == (-2.0, 4.0) and view.axis == "C2"
    assert view.x_range[0] <= -2.0 <= view.x_range[1]
    C2, h = view.centres
    ok = np.flatnonzero(np.isfinite(C2))
    for k in ok[:: max(1, ok.size // 7)]:
        motions = steady_motions(LevelSet(fig5.body, 1.0, 0.5, float(C2[k])))
        assert min(abs(m.U - h[k]) for m in motions) < 1e-8 * max(1.0, abs(h[k]))
    from rollingtop.reduction._critical_curves import folds

    lo, hi = view.x_range
    inside = [f for f in folds(fig5.body, 1.0, 0.5) if lo <= f.C2 <= hi]
    # the diagram's folds are folds()'s: one computation, so exact
    assert sorted(view.folds[0]) == sorted(f.C2 for f in inside) and inside


def test_a_click_starts_the_motion_of_that_point(fig5):
    """The point (gamma3, w_tau) of the portrait: the trajectory's reduced energy is
    rho w_tau^2 / 2 + U there (written again), to ENERGY_RTOL over the run, and its level is the
    page's; the contact point's path is the trajectory's."""
    level = fig5.level_set()
    g3, w = -0.3, 0.4
    view = path_view(fig5, g3, w, t_end=5.0)
    theta = math.acos(g3)
    h = float(level.U(theta) + 0.5 * level.rho(theta) * w * w)
    assert view.h == pytest.approx(h, rel=1e-14)
    traj = view.trajectory
    reduction = reduction_of("meridian")
    for y in traj.y[[0, -1]]:
        assert reduction.reduced_energy(fig5.body, y) == pytest.approx(h, rel=ENERGY_RTOL)
        values = reduction.level_of_state(fig5.body, y).values()
        for k, v in fig5.level.items():
            assert values[k] == pytest.approx(v, rel=1e-9, abs=1e-9)
    np.testing.assert_array_equal(view.x, traj.y[:, 15])
    assert "rotation number N = " in view.summary
    ox, ow = view.orbit  # the clicked orbit: on the energy h
    ok = np.isfinite(ox)
    th = np.arccos(ox[ok])
    np.testing.assert_allclose(level.U(th) + 0.5 * level.rho(th) * ow[ok] ** 2, h, rtol=1e-9)


def test_a_click_outside_the_domain_is_refused(fig5):
    with pytest.raises(ScenarioError, match="outside"):
        path_view(fig5, 1.2, 0.0)


@pytest.mark.parametrize(
    ("query", "message"),
    [
        ({"C2": "abc"}, "C2 = 'abc' is not a number"),
        ({"C2": "nan"}, "must be finite"),
        ({"Q": "1"}, "unknown parameter 'Q'"),
        ({"model": "ice"}, "not a contact model"),
        ({"I3": "0.9"}, "body:"),  # I3 > I1 + I2
        ({"jellett": "1"}, "unknown parameter 'jellett' for the meridian"),
        # issue 36 row 8: Panel hands an all-digit value over as an int
        ({"C2": 10**4999}, r"C2 = <integer of .*digits> is beyond double precision"),
    ],
)
def test_a_bad_url_is_one_line_naming_the_parameter(fig5, query, message):
    with pytest.raises(ScenarioError, match=message) as err:
        parse_query(query, fig5)
    assert "\n" not in str(err.value)


def test_the_url_restores_the_view(fig5):
    """to_query then parse_query from another view: the same view (floats by repr)."""
    changed = parse_query({"C2": "-1.25", "h": "0.9", "a3": "0.05"}, fig5)
    assert changed.level["C2"] == -1.25 and changed.h == 0.9 and changed.body.a3 == 0.05
    assert parse_query(changed.to_query(), fig5) == changed
    rough = parse_query({"model": "rough"}, fig5)
    assert parse_query(rough.to_query(), fig5) == rough


def test_another_model_takes_its_level_from_the_same_state(fig5):
    """model=rough: the level of the page's reference state under the rough model, as
    compare-classification builds it (initial_state of the same gamma, omega)."""
    from rollingtop import initial_state

    rough = parse_query({"model": "rough"}, fig5)
    gamma, omega = fig5.start
    y = initial_state(fig5.body, "rough", gamma=gamma, omega=omega)
    reduction = reduction_of("rough")
    assert rough.level == pytest.approx(reduction.level_of_state(fig5.body, y).values())
    assert rough.h == pytest.approx(reduction.reduced_energy(fig5.body, y))
    view = diagram_view(rough)
    assert view.axis == "jellett" and view.mark == (rough.level["jellett"], rough.h)


def test_a_model_without_a_reduction_shows_its_section():
    """parallel: the section's crossings are states of the reference state's energy level
    (energy written again from one state: (I w, w)/2 + m v^2/2 + m g (R + a3 gamma3))."""
    from rollingtop.dynamics.integrals import energy

    sc = load_scenario(str(EXAMPLES / "section_parallel.toml"))
    state = state_from_scenario(sc)
    assert not state.reduces and state.level == {}
    view = section_view(state)
    assert view.points.shape[0] > 100 and np.all(np.abs(view.points[:, 0]) <= 1.0)
    e0 = float(energy(sc.body, sc.require_state()))
    np.testing.assert_allclose(energy(sc.body, view.states[:20]), e0, rtol=1e-8)
    b = sc.body
    y = view.states[0]
    w, v, g = y[3:6], y[0:3], y[12:15]
    r = -b.R * g - np.array([0.0, 0.0, b.a3])  # from the CoM to the contact point
    plain = 0.5 * (b.I1 * w[0] ** 2 + b.I2 * w[1] ** 2 + b.I3 * w[2] ** 2) + 0.5 * b.m * v @ v
    plain += b.m * b.g * -(r @ g)
    assert plain == pytest.approx(e0, rel=1e-8)


def test_the_newest_request_supersedes_the_older_ones():
    """Latest: requests made while one runs replace each other; only the newest result is
    applied, and a result that arrives after a newer request is dropped."""
    applied, started = [], []
    gate = threading.Event()

    def compute(x):
        started.append(x)
        gate.wait(5)
        return x * 10

    work = Latest(POOL, lambda fn: fn(), compute, lambda arg, res: applied.append((arg, res)))
    work.request(1)
    time.sleep(0.05)
    for k in (2, 3, 4):
        work.request(k)
    gate.set()
    deadline = time.time() + 5
    while (not applied or work.running) and time.time() < deadline:
        time.sleep(0.01)
    assert started == [1, 4]  # 2 and 3 never ran
    assert applied == [(4, 40)]  # 1's result arrived after newer requests: dropped


def test_an_error_in_the_work_is_a_message_not_a_traceback():
    applied = []
    work = Latest(POOL, lambda fn: fn(), lambda x: 1 / x, lambda a, r: applied.append(r))
    work.request(0)
    deadline = time.time() + 5
    while not applied and time.time() < deadline:
        time.sleep(0.01)
    assert isinstance(applied[0], RuntimeError) and "ZeroDivisionError" in str(applied[0])


@pytest.mark.parametrize(
    "name", ["paper", "smooth", "rough", "rubber", "shell_rotor", "pole", "parallel"]
)
def test_every_example_opens_on_the_page(name):
    """Each example's first view: a reduced model's readout counts its steady motions
    (steady_motions of the scenario's own level) and a click starts a motion on its level (the
    reduced energy of the trajectory's last state is the clicked point's); parallel shows its
    section."""
    sc = load_scenario(str(EXAMPLES / f"{name}.toml"))
    state = state_from_scenario(sc)
    if not state.reduces:
        assert section_view(state).points.shape[1] == 2
        return
    from rollingtop.reduction import steady_motions

    view = level_view(state)
    assert view.count == len(steady_motions(sc.level_set()))
    x = view.steady[0][0] + 0.05
    path = path_view(state, x, 0.1, t_end=2.0)
    y = path.trajectory.y[-1]
    assert reduction_of(state.model).reduced_energy(state.body, y) == pytest.approx(
        path.h, rel=ENERGY_RTOL, abs=ENERGY_RTOL)  # fmt: skip


def test_a_closed_page_is_freed(fig5):
    """Issue 36, item 6: a closed session's page is garbage (its plots, trajectories and
    widgets go with it). Panel's registry of JavaScript callbacks kept every page whose
    editable sliders it had seen: about 1.9 MB a session, 188 MB after 100 sessions."""
    import gc
    import weakref

    from rollingtop.explore.app import ExplorePage

    def open_and_close():
        page = ExplorePage(fig5, "plain", query={})
        deadline = time.time() + 30
        while any(w.running for w in (page.level_work, page.diagram_work)):
            assert time.time() < deadline, "the page's first plots took over 30 s"
            time.sleep(0.02)
        assert page.drawn == fig5  # its plots were drawn
        page.close()
        return weakref.ref(page)

    refs = [open_and_close() for _ in range(3)]
    gc.collect()
    assert [r() for r in refs] == [None, None, None]


def test_a_servers_pages_share_its_pool_and_a_page_alone_owns_one(fig5):
    """Issue 37, item 5: one executor per server, passed to each of its pages (a second server
    in the same process has its own); a page made without one owns a pool that its close()
    shuts down, and closing a page of a server leaves the server's pool running."""
    from rollingtop.explore.app import ExplorePage

    shared = new_executor()
    pages = [ExplorePage(fig5, "plain", query={}, executor=shared) for _ in range(2)]
    alone = ExplorePage(fig5, "plain", query={})
    for page in pages:
        assert all(w.executor is shared for w in (page.level_work, page.path_work))
    assert alone.level_work.executor is not shared
    for page in (*pages, alone):
        page.close()
    assert shared.submit(lambda: 7).result(timeout=10) == 7  # still running
    with pytest.raises(RuntimeError, match="shutdown"):
        alone.executor.submit(lambda: 7)
    shared.shutdown()


def test_the_loops_python_calls_release_the_gil():
    """Issue 37, item 5: every compiled loop that Python calls for a long piece of work is
    compiled ``nogil``, so the page's event loop runs while a worker integrates (measured: a
    worker's 2000-time-unit simulate stalled the main thread 105 ms before, 7 ms after)."""
    from rollingtop._compiled import for_model
    from rollingtop.contact import MODELS

    for name in MODELS:
        k = for_model(name)
        steppers = (k.stepper, k.stepper_events, k.stepper_held)
        loops = [s.run_rows for s in steppers] + [k.tangent.indicators_chunk]
        loops.append(k.chaos.section_batch)
        assert all(f.targetoptions.get("nogil") is True for f in loops), name


def test_views_are_cached_on_the_state(fig5):
    """Issue 37, item 5: the page's views are kept per state for the whole server. Equal states
    (the level's keys in another order) hash alike and get the same view; it is the uncached
    computation's, with read-only arrays (a cached view is shared by every session)."""
    from dataclasses import replace

    from rollingtop.explore.view import cached_diagram_view, cached_level_view, diagram_view

    other = replace(fig5, level=dict(reversed(list(fig5.level.items()))))
    assert list(other.level) != list(fig5.level)
    assert other == fig5 and hash(other) == hash(fig5)
    assert hash(replace(fig5, h=fig5.h + 0.1)) != hash(fig5)
    lv, dv = cached_level_view(fig5), cached_diagram_view(fig5)
    assert cached_level_view(other) is lv and cached_diagram_view(other) is dv
    fresh = level_view(fig5)
    assert lv.readout == fresh.readout and lv.steady == fresh.steady
    np.testing.assert_array_equal(lv.U_y, fresh.U_y)
    np.testing.assert_array_equal(dv.centres[1], diagram_view(fig5).centres[1])
    with pytest.raises(ValueError, match="read-only"):
        lv.U_y[0] = 0.0
    with pytest.raises(ValueError, match="read-only"):
        dv.centres[0][0] = 0.0


def _settled(page):
    deadline = time.time() + 60
    while any(w.running for w in (page.level_work, page.diagram_work)):
        assert time.time() < deadline, "the page's plots took over 60 s"
        time.sleep(0.02)


def test_the_pages_view_is_its_parameters(fig5):
    """Issue 37, item 5: the page's state is its param parameters, one per key of the URL
    (QUERY_KEYS, every model's level keys among them). A query's values arrive as parameters
    (the URL's text or Panel's number); a new valid value there is the new view; a bad one is a
    message, and the parameters go back to the last valid view; another model's keys are None."""
    from rollingtop.contact import MODELS
    from rollingtop.explore.app import QUERY_KEYS, ExplorePage

    assert {k for m in MODELS.values() for k in m.reduction} < set(QUERY_KEYS)
    assert set(QUERY_KEYS) <= set(ExplorePage.param)
    page = ExplorePage(fig5, "plain", query={"C2": -1.0, "h": "0.8"})
    try:
        assert page.state.level["C2"] == -1.0 and page.state.h == 0.8
        assert page.C2 == repr(-1.0) and page.h == repr(0.8) and page.model == "meridian"
        assert page.jellett is None and page.routh is None
        page.param.update(C2="-1.5")  # a script (or the URL) sets a parameter: the new view
        assert page.state.level["C2"] == -1.5 and not page.message.visible
        page.param.update(C2="abc")
        assert page.message.visible and "C2 = 'abc' is not a number" in page.message.object
        assert page.state.level["C2"] == -1.5 and page.C2 == repr(-1.5)  # the last valid view
        page.param.update(I3="0.9")  # a body the model refuses (I3 > I1 + I2)
        assert "body:" in page.message.object and page.I3 == repr(fig5.body.I3)
        page.param.update(model="rough")
        assert page.state.model == "rough" and page.M3 is None and page.C2 is None
        assert float(page.jellett) == page.state.level["jellett"]
        _settled(page)
    finally:
        page.close()


def test_a_bad_or_unknown_query_key_is_a_message_and_the_scenarios_view_stays(fig5):
    from rollingtop.explore.app import ExplorePage

    for query, text in (({"C2": "abc"}, "C2 = 'abc' is not a number"),
                        ({"foo": "1"}, "unknown parameter 'foo'"),
                        ({"jellett": "1"}, "unknown parameter 'jellett' for the meridian"),
                        ({"C2": 10**400}, "beyond double precision")):  # fmt: skip
        page = ExplorePage(fig5, "plain", query=query)
        try:
            assert page.message.visible and text in page.message.object, query
            assert page.state == fig5 and page.C2 == repr(-2.0)
        finally:
            _settled(page)
            page.close()


def test_the_url_follows_the_view_and_keeps_no_refused_or_unknown_value(fig5):
    """Review of issue 37 item 5, with Panel's own Location (no server): the URL's values load
    the view; an unknown key is reported and leaves the URL; a value refused after the load
    (from a script) is a message and the URL keeps the last valid view; another model's keys
    leave the URL; a closed page is unsynced and freed."""
    import gc
    import weakref

    from panel.io.location import Location

    from rollingtop.explore.app import ExplorePage

    loc = Location(search="?C2=-1.0&foo=1")
    page = ExplorePage(fig5, "plain", location=loc)
    _settled(page)
    assert page.state.level["C2"] == -1.0
    assert "unknown parameter 'foo'" in page.message.object
    assert "foo" not in loc.search and "C2=-1.0" in loc.search
    page.param.update(C2="abc")
    assert "C2 = 'abc' is not a number" in page.message.object
    assert "abc" not in loc.search and "C2=-1.0" in loc.search
    page.param.update(h=True)  # Panel reads ?h=true as a bool
    assert "h = True is not a number" in page.message.object and page.state.h == fig5.h
    page.param.update(model="rough")
    assert "model=rough" in loc.search and "jellett=" in loc.search and "C2" not in loc.search
    _settled(page)
    page.close()
    assert not loc._synced
    ref = weakref.ref(page)
    del page
    gc.collect()
    assert ref() is None


def test_the_section_view_marks_the_orbits_in_its_own_plane():
    """Issue 38, item 6: the companion model's section on the page has the periodic orbits its
    trajectories settle onto, typed, and drawn in the plane of the section's points (each
    orbit's crossings lie among them: the same coordinates, not the carried direction's
    signs)."""
    sc = load_scenario(EXAMPLES / "parallel.toml")
    view = section_view(state_from_scenario(sc))
    assert view.orbits and "periodic orbits:" in view.readout
    for returns, kind, points in view.orbits:
        assert points.shape == (returns, 2) and kind == "attracting"
        gaps = np.min(np.max(np.abs(view.points[None, :, :] - points[:, None, :]), axis=-1), 1)
        # within the approach still left after the page's short runs (about 2e-2); in the
        # carried direction's signs (the plane before) the 4-cycles' points were 0.12 away
        assert np.all(gaps < 0.05), (returns, gaps)


def test_the_oblique_models_angle_is_a_parameter_of_the_view(fig5):
    """Issue 39, item 4: choosing ``oblique`` gives its registered angle; the URL's ``angle``
    sets it (the section runs under that angle: its crossings hold the energy of the state
    built under it, and a different angle gives different crossings); a bad angle is one
    line; another model has no ``angle``."""
    from rollingtop.contact.oblique import DEFAULT_ANGLE, oblique
    from rollingtop.dynamics.integrals import energy

    state = fig5.with_model("oblique")
    assert state.contact == (("angle", DEFAULT_ANGLE),) and not state.reduces
    tilted = parse_query({"angle": "0.3"}, state)
    assert tilted.contact_model.parameter_values["angle"] == 0.3
    assert tilted.to_query()["angle"] == repr(0.3)
    assert parse_query(tilted.to_query(), fig5.with_model("oblique")) == tilted
    view = section_view(tilted)
    y = tilted.reference_state()
    np.testing.assert_allclose(energy(fig5.body, view.states[:10]), energy(fig5.body, y), rtol=1e-8)
    assert "angle = 0.3" in view.readout
    other = section_view(parse_query({"angle": "1.2"}, state))
    assert other.points.shape != view.points.shape or not np.allclose(
        other.points[:20], view.points[:20]
    )
    # the state's field is the model's at that angle: the model the section ran is oblique(0.3)
    assert tilted.contact_model.parameter_values == oblique(0.3).parameter_values
    with pytest.raises(ScenarioError, match="angle = 'x' is not a number"):
        parse_query({"angle": "x"}, state)
    with pytest.raises(ScenarioError, match="unknown parameter 'angle' for the meridian"):
        parse_query({"angle": "0.3"}, fig5)
    assert fig5.with_model("oblique").with_model("meridian").contact == ()


def test_the_scenarios_own_rule_and_angle_are_kept():
    """A scenario with oblique, an angle and a passage rule of its own: the view's model has
    them all; another model and back restores the scenario's angle and rule."""
    from rollingtop.scenario import Scenario

    sc = Scenario.from_dict(
        {
            "body": {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5},
            "contact": {"model": "oblique", "angle": 0.7, "pole_disk": 1e-5},
            "initial": {"gamma": [0.0, 0.6, 0.8], "omega": [0.7, -0.3, 2.0], "v_slip": 0.25},
        }
    )
    state = state_from_scenario(sc)
    values = state.contact_model.parameter_values
    assert values["angle"] == 0.7 and values["pole_disk"] == 1e-5
    back = state.with_model("meridian").with_model("oblique")
    assert back.contact == (("angle", 0.7),)
    assert back.contact_model.parameter_values == values
    np.testing.assert_array_equal(back.reference_state(), state.reference_state())
