"""The devices of the paper's Sec. 1 (rollingtop.devices) against computations from the state
made here independently: tau and nu from the axis (docs/model.md, "Reduced variables"), the
shell's spin from solve_ivp on the full equations."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rollingtop import ContactModelError, simulate
from rollingtop.contact import MODELS
from rollingtop.devices import (
    check_device,
    roller_layout,
    roller_spin,
    shell_spin_angle,
    shell_spin_rate,
    skate_layout,
    tau_slip,
)
from rollingtop.scenario import load_scenario
from tests import kernels as _kernel

from .conftest import EXAMPLES

#: Geometry and formulas that are exact up to round-off.
EXACT = 1e-12
#: The shell's turn by the quintic-spline quadrature at h = 0.01 against solve_ivp at
#: rtol = 1e-12 (measured 6e-12 over 0 <= t <= 10; the docstring of shell_spin_angle).
SHELL_ANGLE_TOL = 1e-9


@pytest.fixture(scope="module")
def paper():
    """examples/paper.toml over 0 <= t <= 3, h = 0.01, integrated tightly."""
    sc = load_scenario(EXAMPLES / "paper.toml")
    return simulate(sc, t_end=3.0, samples=301, rtol=1e-12, atol=1e-14)


def axis_frame(gamma):
    """tau = e3 x gamma / s and nu = (e3 - gamma3 gamma) / s, rows (n, 3)."""
    s = np.hypot(gamma[:, 0], gamma[:, 1])[:, None]
    e3 = np.array([0.0, 0.0, 1.0])
    return np.cross(e3, gamma) / s, (e3 - gamma[:, 2:3] * gamma) / s


def contact_velocity(body, y):
    """vp = v + w x r, r = -R gamma - a."""
    r = -body.R * y[:, 12:15] - np.array([0.0, 0.0, body.a3])
    return y[:, 0:3] + np.cross(y[:, 3:6], r)


def test_the_slip_is_along_tau(paper):
    body, y = paper.body, paper.y
    vp = contact_velocity(body, y)
    tau, nu = axis_frame(y[:, 12:15])
    np.testing.assert_allclose(tau_slip(body, y), np.einsum("ij,ij->i", vp, tau), atol=EXACT)
    assert np.max(np.abs(np.einsum("ij,ij->i", vp, nu))) < EXACT  # the constraint holds
    assert np.min(np.abs(tau_slip(body, y))) > 0.1  # and this motion slips throughout


def test_the_shell_rolls_without_slipping(paper):
    """Omega = w + delta e3 puts the shell's contact point at rest: v_O + Omega x (-R gamma) = 0
    with the geometric centre's velocity v_O = v + w x (-a)."""
    body, y = paper.body, paper.y
    delta = shell_spin_rate(body, y)
    omega = y[:, 3:6] + delta[:, None] * np.array([0.0, 0.0, 1.0])
    v_centre = y[:, 0:3] + np.cross(y[:, 3:6], [0.0, 0.0, -body.a3])
    shell_contact = v_centre + np.cross(omega, -body.R * y[:, 12:15])
    assert np.max(np.abs(shell_contact)) < EXACT


def test_the_shell_angle_against_solve_ivp(paper):
    body, y = paper.body, paper.y
    p, ws, code = body.params, _kernel.new_workspace(), paper.kernel_code

    def f(t, z):
        dy = np.zeros(18)
        _kernel.rhs(code, p, z[:18], dy, ws)
        tau, _ = axis_frame(z[None, 12:15])
        s = np.hypot(z[12], z[13])
        return np.append(dy, contact_velocity(body, z[None, :18])[0] @ tau[0] / (body.R * s))

    sol = solve_ivp(f, (0.0, 3.0), np.append(y[0], 0.0), method="DOP853", t_eval=paper.t,
                    rtol=1e-12, atol=1e-14)  # fmt: skip
    chi = shell_spin_angle(paper.t, body, y)
    assert abs(chi[-1]) > 1.0  # the shell does turn against the rotor
    np.testing.assert_allclose(chi, sol.y[18], atol=SHELL_ANGLE_TOL)


def test_the_shell_refuses_a_pole_passage():
    traj = simulate(load_scenario(EXAMPLES / "pole.toml"), t_end=2.0, samples=201)
    sigma = np.cos(traj.y[:, 17]) * traj.y[:, 8] + np.sin(traj.y[:, 17]) * traj.y[:, 11]
    i = np.argmax(sigma < 0)  # (nu, e3) changes sign: the axis passed the vertical
    with pytest.raises(ContactModelError, match=f"between t = {traj.t[i - 1]:.6g} and "):
        shell_spin_angle(traj.t, traj.body, traj.y)


def test_rollers_lie_on_meridians_with_axes_along_them():
    layout = roller_layout()
    c, a = layout.centre, layout.axis
    e3 = np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(np.linalg.norm(c, axis=1), 1.0, atol=EXACT)
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), 1.0, atol=EXACT)
    assert np.max(np.abs(np.einsum("ij,ij->i", a, c))) < EXACT  # tangent to the sphere
    assert np.max(np.abs(a @ np.cross(e3, c).T).diagonal()) < EXACT  # in the meridian plane
    assert np.all(a[:, 2] > 0)  # towards the pole +e3


def test_the_roller_at_the_contact_has_its_axis_along_nu():
    """With the contact point on a roller (gamma = -its centre), that roller is the one in
    contact and its axis is nu."""
    layout = roller_layout()
    for k in (0, 20, 45, 111):
        gamma = -layout.centre[k][None, :]
        (found,) = layout.nearest(-gamma)
        assert found == k
        _, nu = axis_frame(gamma)
        np.testing.assert_allclose(layout.axis[k], nu[0], atol=EXACT)


def test_the_roller_in_contact_turns_at_slip_over_radius(paper):
    body, y = paper.body, paper.y
    layout = roller_layout()
    contact, rate, angle = roller_spin(paper.t, body, y, layout)
    tau, _ = axis_frame(y[:, 12:15])
    slip = np.einsum("ij,ij->i", contact_velocity(body, y), tau)
    rows = np.arange(len(y))
    np.testing.assert_allclose(rate[rows, contact], slip / (body.R * layout.radius[contact]),
                               rtol=EXACT)  # fmt: skip
    assert len(set(contact)) > 1
    # the others keep the rate they left with; none turns before it first touches
    for k in set(contact):
        first = np.argmax(contact == k)
        assert np.all(rate[:first, k] == 0)
        left = np.flatnonzero((contact[:-1] == k) & (contact[1:] != k))
        for i in left:
            assert rate[i + 1, k] == rate[i, k]
    np.testing.assert_allclose(np.diff(angle, axis=0),
                               0.5 * (rate[1:] + rate[:-1]) * np.diff(paper.t)[:, None],
                               atol=EXACT)  # fmt: skip


def test_skates_are_disks_on_the_axis_whose_edges_are_parallels():
    """Every edge point (r cos u, r sin u, h) lies on the unit sphere; at the contact the disk's
    edge runs along tau and its normal e3 projects on the plane along nu."""
    layout = skate_layout()
    np.testing.assert_allclose(layout.radius**2 + layout.height**2, 1.0, atol=EXACT)
    for k, u in ((0, 0.3), (4, 2.0), (8, -1.0)):
        h, r = layout.height[k], layout.radius[k]
        point = np.array([r * np.cos(u), r * np.sin(u), h])
        gamma = -point[None, :]
        (found,) = layout.nearest(-gamma)
        assert found == k
        tau, nu = axis_frame(gamma)
        edge = np.array([-np.sin(u), np.cos(u), 0.0])  # the edge's tangent at the contact
        np.testing.assert_allclose(abs(edge @ tau[0]), 1.0, atol=EXACT)
        e3 = np.array([0.0, 0.0, 1.0])
        horizontal = e3 - (e3 @ gamma[0]) * gamma[0]
        np.testing.assert_allclose(horizontal / np.linalg.norm(horizontal), nu[0], atol=EXACT)


@pytest.mark.parametrize("device", ["roller", "shell", "skates"])
def test_devices_realise_only_the_models_that_declare_them(device):
    """Every device the meridian model's; the shell also the shell-rotor pair's (whose shell
    spin is its state's); no other model's."""
    check_device(device, MODELS["meridian"])
    assert (device in MODELS["shell-rotor"].devices) == (device == "shell")
    for name in ("smooth", "rough", "parallel", "rubber"):
        with pytest.raises(ContactModelError, match=f"not that of model '{name}'"):
            check_device(device, MODELS[name])
    with pytest.raises(ContactModelError, match="unknown device"):
        check_device("sled", MODELS["meridian"])


def test_the_pairs_shell_angle_is_its_own_spin_integrated():
    """For the shell-rotor pair the shell's spin is a state variable (finite through the
    vertical): the angle is its quadrature, held to solve_ivp's integral of the same motion."""
    from scipy.integrate import solve_ivp

    from rollingtop import SphericalTop, initial_state, simulate
    from tests import kernels as _kernel

    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5, shell_mass=0.2,
                        shell_inertia=0.2 * 2 / 3)  # fmt: skip
    model = MODELS["shell-rotor"]
    y0 = initial_state(body, model, gamma=[0.0, 0.6, 0.8], omega=[0.7, -0.3, 2.0],
                       free={"v_tau": 0.25})  # fmt: skip
    tr = simulate(body, model, y0, t_end=5.0, rtol=1e-12, atol=1e-14, samples=501)
    chi = shell_spin_angle(tr.t, body, tr.y, model)
    ws, dy = _kernel.new_workspace(), np.empty(18)

    def rhs(t, z):
        _kernel.rhs(model.code, body.params, z[:18], dy, ws)
        return np.concatenate([dy, [z[17]]])

    sol = solve_ivp(rhs, (0.0, 5.0), np.concatenate([y0, [0.0]]), method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=tr.t)  # fmt: skip
    np.testing.assert_allclose(chi, sol.y[18], rtol=0, atol=1e-8)
