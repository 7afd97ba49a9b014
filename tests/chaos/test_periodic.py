"""Relative periodic orbits (rollingtop.chaos.periodic, ``rollingtop periodic``).

Each orbit of the companion model's example level closes under SciPy's integration of the
independent NumPy equations (tests/dynamics/reference.py, rtol 1e-12); the multipliers of an
attracting orbit agree with the rate at which the section map's own iterates approach it; on the
paper's integrable level the periods are the quadrature's (``rollingtop orbits``) and every
multiplier is trivial.
"""

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import ScenarioError, SphericalTop, simulate
from rollingtop.chaos import periodic_orbits
from rollingtop.chaos._section_map import SectionMap, section_coordinates, section_state
from rollingtop.chaos.level import held_integrals
from rollingtop.scenario import load_scenario

from ..conftest import EXAMPLES
from ..dynamics import reference
from ..test_cli import run_cli

#: One pytest-xdist worker runs this module (its fixture finds the example's orbits once).
pytestmark = pytest.mark.xdist_group("periodic")

#: Section coordinates rebuilt from a state: round-off.
ROUND_TRIP_TOL = 1e-13
#: An orbit's section coordinates after one period of SciPy's integration (rtol = atol = 1e-12)
#: of the reference equations (the issue's bound).
SCIPY_CLOSURE_TOL = 1e-8
#: An orbit through the vertical after one period of the compiled integrator at rtol 1e-12
#: (not the section's located crossings): the flow is steep next to the vertical, where the
#: model's rule continues the motion, and a difference of 1e-12 grows to ~1e-6 across it.
VERTICAL_CLOSURE_TOL = 1e-5
#: The periods of the integrable level against the quadrature of ``rollingtop orbits``.
PERIOD_RTOL = 1e-9
#: Trivial multipliers' distance from 1 (central differences at step 1e-5 of a flow at
#: rtol 1e-11).
TRIVIAL_TOL = 1e-4
#: The variational multipliers (rtol 1e-11) against central differences of the flow at rtol
#: 1e-13, Richardson-extrapolated over the steps 2e-6 and 4e-6 (the issue's bound).
MULTIPLIER_TOL = 1e-6
#: Trivial multipliers' distance from 1 where they come from the variational equations.
VARIATIONAL_TRIVIAL_TOL = 1e-7
#: The steady motion's eigenvalues against those of the reference equations (both central
#: differences of a difference).
EIGENVALUE_TOL = 1e-5
#: The largest multiplier's modulus against the contraction of the map's iterates.
RATE_TOL = 0.02


@pytest.fixture(scope="module")
def parallel():
    sc = load_scenario(EXAMPLES / "parallel.toml")
    return sc, periodic_orbits(sc.body, sc.model, sc.require_state(), returns=4)


def test_section_coordinates_rebuild_the_state(rng):
    sc = load_scenario(EXAMPLES / "parallel.toml")
    for model in ("parallel", "meridian"):
        for _ in range(10):
            x = np.array([rng.uniform(-0.95, 0.95), *rng.normal(size=3)])
            y = section_state(sc.body, model, x)
            assert abs(np.cross(y[3:6], [0.0, 0.0, 1.0]) @ y[12:15]) < ROUND_TRIP_TOL  # w_tau
            np.testing.assert_allclose(section_coordinates(model, y), x, atol=ROUND_TRIP_TOL)


def test_the_example_levels_orbits_are_found_typed_and_closed(parallel):
    """The issue's done-when: the orbits the section's trajectories settle onto (section
    examples/parallel.toml: a fixed point, a 3-cycle, 4-cycles), each attracting, each closing;
    and, from the grid of seeds, an elliptic fixed point, the centre the scenario's own
    trajectory winds around (the model is reversible: symmetric orbits may be elliptic)."""
    sc, found = parallel
    attracting = [o for o in found if o.type == "attracting"]
    assert {o.returns for o in attracting} >= {1, 3, 4}
    assert sum(o.through_vertical for o in found) == 3  # the fixed point and the 4-cycles
    (centre,) = [o for o in found if o.type == "elliptic"]
    assert centre.returns == 1
    np.testing.assert_allclose(np.abs(centre.multipliers), 1.0, atol=1e-6)
    for o in found:
        assert np.max(np.abs(o.trivial - 1.0)) < TRIVIAL_TOL
        if o.through_vertical:  # closes under the integrator's own run at rtol 1e-12
            tr = simulate(sc.body, sc.model, o.state, t_end=o.period, rtol=1e-12, atol=1e-14,
                          samples=2)  # fmt: skip
            end = section_coordinates(sc.model, tr.y[-1])
            assert np.max(np.abs(end - o.x)) < VERTICAL_CLOSURE_TOL


def test_an_orbit_closes_under_scipy_on_the_reference_equations(parallel):
    """The 3-cycle and the elliptic fixed point stay away from the vertical (where the
    reference's direction tau is undefined): one period of SciPy's DOP853 on the NumPy equations
    brings each state back to its section coordinates."""
    sc, found = parallel
    away = [o for o in found if not o.through_vertical]
    assert {(o.returns, o.type) for o in away} == {(3, "attracting"), (1, "elliptic")}
    p = sc.body.params
    for orbit in away:
        sol = solve_ivp(lambda t, y: reference.rhs("parallel", p, y)[0], (0.0, orbit.period),
                        orbit.state, method="DOP853", rtol=1e-12, atol=1e-12)  # fmt: skip
        end = section_coordinates("parallel", sol.y[:, -1])
        np.testing.assert_allclose(end, orbit.x, atol=SCIPY_CLOSURE_TOL)


def test_the_multipliers_come_from_the_variational_equations(parallel):
    """Issue 38, item 2: the orbits away from the vertical have their multipliers from the
    variational equations, equal to central differences of the section map (at a tighter
    tolerance, the steps' h^2 error extrapolated away) to 1e-6, with trivial multipliers 1 to
    1e-7; those through the vertical, where the flow has no derivative, say theirs come from
    differences."""
    from rollingtop.chaos._section_map import integral_gradients, map_jacobian

    sc, found = parallel
    names = held_integrals(sc.body, sc.model, None)
    P = SectionMap(sc.body, sc.model, names, 1e-13)
    for o in found:
        if o.through_vertical:
            assert o.multipliers_from == "differences"
            continue
        assert o.multipliers_from == "variational"
        assert np.max(np.abs(o.trivial - 1.0)) < VARIATIONAL_TRIVIAL_TOL
        h = 2e-6
        D = (
            4 * map_jacobian(P, o.x, o.returns, h)[1] - map_jacobian(P, o.x, o.returns, 2 * h)[1]
        ) / 3
        _, G = integral_gradients(P, o.x)
        T = np.linalg.svd(G)[2][2:].T  # the level's tangent plane
        want = np.linalg.eigvals(T.T @ D @ T)
        assert len(want) == len(o.multipliers) == 2
        for mu in o.multipliers:
            assert np.min(np.abs(want - mu)) < MULTIPLIER_TOL
        assert o.to_dict(sc.model)["multipliers_from"] == "variational"


def test_the_variational_jacobian_is_the_maps_derivative_off_an_orbit():
    """At a point of the section that is on no orbit, K = 2: the whole
    4 x 4 derivative of P^2, section correction included, against central differences."""
    from rollingtop.chaos._section_map import map_jacobian
    from rollingtop.chaos._variational import variational_jacobian

    sc = load_scenario(EXAMPLES / "parallel.toml")
    names = held_integrals(sc.body, sc.model, None)
    P = SectionMap(sc.body, sc.model, names, 1e-13)
    x = np.array([0.45, -0.9, 2.0, 0.2])
    _, t = P(x[None], 2)
    J = variational_jacobian(P, x, float(t[0, 1]), stop_at_vertical=True)
    h = 2e-6
    D = (4 * map_jacobian(P, x, 2, h)[1] - map_jacobian(P, x, 2, 2 * h)[1]) / 3
    np.testing.assert_allclose(J, D, atol=MULTIPLIER_TOL * max(1.0, np.max(np.abs(D))))


def test_the_multipliers_give_the_rate_of_approach(parallel):
    """A start on the level beside the 3-cycle approaches it at the rate of the largest
    multiplier's modulus per period (the map's own iterates, no differences)."""
    sc, found = parallel
    (orbit,) = [o for o in found if o.returns == 3]
    assert orbit.type == "attracting"
    names = held_integrals(sc.body, sc.model, None)
    P = SectionMap(sc.body, sc.model, names, 1e-11)
    # a displacement along gamma3 compensated in w3 and v_nu to stay on the level (first order)
    x = orbit.x.copy()
    h = 1e-6
    G = np.array([(P.integrals((x + h * e)[None])[0] - P.integrals((x - h * e)[None])[0]) / (2 * h)
                  for e in np.eye(4)]).T  # fmt: skip
    d = np.array([1.0, 0.0, 0.0, 0.0])
    d[2:] = -np.linalg.solve(G[:, 2:], G[:, :2] @ d[:2])
    pts, _ = P((x + 1e-4 * d)[None], 3 * 24)
    dist = np.max(np.abs(pts[0, 2::3] - x), axis=-1)
    rate = math.exp(np.polyfit(np.arange(4, 20), np.log(dist[4:20]), 1)[0])
    assert rate == pytest.approx(abs(orbit.multipliers[0]), abs=RATE_TOL)


def test_the_integrable_level_has_the_quadratures_periods_and_trivial_multipliers(capsys):
    path = str(EXAMPLES / "fig5.toml")
    code, out, err = run_cli(capsys, "periodic", path, "--json", "--returns", "2")
    # (the meridian model's level meets the section in points: no grid of seeds there)
    assert code == 0, err
    got = json.loads(out)
    code, out, err = run_cli(capsys, "orbits", path, "--json")
    assert code == 0, err
    want = sorted(o["period"] for o in json.loads(out)["orbits"] if o["kind"] == "periodic")
    orbits = got["orbits"]
    assert sorted(o["period"] for o in orbits) == pytest.approx(want, rel=PERIOD_RTOL)
    for o in orbits:
        assert o["returns"] == 1 and o["type"] == "neutral" and o["multipliers"] == []
        assert o["trivial_multipliers_off_one"] < TRIVIAL_TOL
        assert set(o) >= {"returns", "period", "initial", "multipliers", "type",
                          "through_vertical", "closure"}  # fmt: skip
        assert set(o["initial"]) == {"gamma", "omega", "v_tau"}
    assert set(got) >= {"level", "orbits", "steady"}


def test_bad_input_is_refused_in_one_line(capsys, tmp_path):
    sc = load_scenario(EXAMPLES / "parallel.toml")
    y = sc.require_state()
    lopsided = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I2=0.35, I3=0.5)
    with pytest.raises(ScenarioError, match="dynamically symmetric"):
        periodic_orbits(lopsided, "parallel", y)
    with pytest.raises(ScenarioError, match="smooth model"):
        periodic_orbits(sc.body, "smooth", y)
    with pytest.raises(ScenarioError, match="returns = 0"):
        periodic_orbits(sc.body, "parallel", y, returns=0)
    with pytest.raises(ScenarioError, match="grid = -1"):
        periodic_orbits(sc.body, "parallel", y, grid=-1)
    for args in (("--returns", "0"), ("--settle", "5"), ("-o", str(tmp_path / "x.txt")),
                 ("--grid-seeds", "-1")):  # fmt: skip
        code, out, err = run_cli(capsys, "periodic", str(EXAMPLES / "parallel.toml"), *args)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
        assert "Traceback" not in err


def test_the_orbits_show_themselves_in_a_notebook(parallel, tmp_path):
    """_repr_html_: a row per orbit with its type; .plot(): the orbits' crossings on the section
    plane, on the caller's axes."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    _, found = parallel
    html = found._repr_html_()
    assert html.count("<tr>") == len(found) + 3  # the two tables' headers, the level, the orbits
    assert "elliptic" in html and "attracting" in html
    ax = Figure().add_subplot()
    assert found.plot(ax) is ax
    drawn = [line for line in ax.get_lines() if line.get_marker() in ("o", "D")]
    assert sum(len(line.get_xdata()) for line in drawn) == sum(o.returns for o in found)
    ax.figure.savefig(tmp_path / "periodic.png")


def test_a_relative_equilibrium_is_found_on_its_level():
    """A steady motion of the companion model (gamma3 constant), found here with SciPy's root
    on the independent NumPy equations (tests/dynamics/reference.py) carried to the reduced
    coordinates: on its level the library finds it, with the same nonzero eigenvalues, and the
    compiled integrator keeps its gamma3 constant."""
    from scipy.optimize import root

    from rollingtop.chaos._section_map import reduced_coordinates, reduced_state
    from rollingtop.chaos.steady import relative_equilibria

    sc = load_scenario(EXAMPLES / "parallel.toml")
    body, p = sc.body, sc.body.params

    def field(z):
        y = reduced_state(body, "parallel", z)
        dy = reference.rhs("parallel", p, y)[0]
        e = 1e-7 / np.max(np.abs(dy))
        return (reduced_coordinates("parallel", y + e * dy)
                - reduced_coordinates("parallel", y - e * dy)) / (2 * e)  # fmt: skip

    def steady(q):  # (gamma3, w_n, w3, u) with w_tau = 0
        return field(np.array([q[0], 0.0, *q[1:]]))[1:]

    sol = root(steady, [-0.19, -2.8, -0.25, 0.0], method="lm", tol=1e-14)
    assert sol.success and np.max(np.abs(steady(sol.x))) < 1e-10
    z_ref = np.array([sol.x[0], 0.0, *sol.x[1:]])
    names = held_integrals(body, sc.model, None)
    P = SectionMap(body, sc.model, names, 1e-11)
    target = P.integrals(np.delete(z_ref, 1)[None])[0]
    found = relative_equilibria(P, target, np.linspace(-0.9, 0.9, 10), np.linspace(-4, 1, 10))
    (eq,) = [e for e in found if np.max(np.abs(e.z - z_ref)) < 1e-6]
    A = np.array([(field(z_ref + h) - field(z_ref - h)) / 2e-4 for h in 1e-4 * np.eye(5)]).T
    ref = [e for e in np.linalg.eigvals(A) if abs(e) > 1e-4]
    assert len(ref) == len(eq.eigenvalues)
    for e in eq.eigenvalues:
        assert min(abs(e - r) for r in ref) < EIGENVALUE_TOL
    assert eq.type == "unstable" and eq.eigenvalues[0].real > 1.0
    tr = simulate(body, sc.model, eq.state, t_end=2.0, rtol=1e-12, samples=201)
    assert np.ptp(tr.y[:, 14]) < 1e-8  # steady (an unstable one: a short run)


def test_a_reduced_models_steady_motion_on_the_level_is_listed():
    """On the paper's level at the energy of its centre (the reduction's steady motion), the
    steady list has it: its gamma3, a centre, eigenvalues on the imaginary axis."""
    from rollingtop.reduction import reduction_of, steady_motions
    from rollingtop.reduction.variables import state_from_level

    sc = load_scenario(EXAMPLES / "fig5.toml")
    level = reduction_of("meridian").level_of_state(sc.body, sc.require_state())
    centre = next(m for m in steady_motions(level) if m.type == "center")
    y = state_from_level(level, centre.U, centre.gamma3, branch=1)
    found = periodic_orbits(sc.body, "meridian", y, returns=1, trajectories=2)
    (steady,) = [e for e in found.steady if abs(e.z[0] - centre.gamma3) < 1e-12]
    assert steady.type == "centre" and len(steady.eigenvalues) == 2
    np.testing.assert_allclose(steady.eigenvalues.real, 0.0, atol=1e-9)
    tr = simulate(sc.body, "meridian", steady.state, t_end=5.0, rtol=1e-12, samples=51)
    assert np.ptp(tr.y[:, 14]) < 1e-9


def test_the_type_is_decided_outside_the_margin():
    """A modulus within the margin of 1 counts as on the unit circle: the linearisation does not
    decide there (neutral), unless every multiplier is on it (elliptic for a complex pair)."""
    from rollingtop.chaos._multipliers import classify as _classify

    c = np.array
    assert _classify(c([0.5, 0.2 + 0j])) == "attracting"
    assert _classify(c([2.0, 1.5 + 0j])) == "repelling"
    assert _classify(c([2.0, 0.5 + 0j])) == "saddle"
    assert _classify(c([np.exp(0.3j), np.exp(-0.3j)])) == "elliptic"
    assert _classify(c([1.0, 1.0 + 0j])) == "neutral"
    assert _classify(c([0.989, 0.185 + 0j]), margin=0.09) == "neutral"  # 0.989: undecided
    assert _classify(c([0.989, 0.185 + 0j]), margin=0.001) == "attracting"
    assert _classify(c([1.05, 0.5 + 0j]), margin=0.09) == "neutral"
    assert _classify(c([], dtype=complex)) == "neutral"  # the integrable level's
