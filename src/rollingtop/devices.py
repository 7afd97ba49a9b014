"""The devices that realise the paper's constraint, and what their moving parts do.

Kilin & Ivanova (2023), Sec. 1 and Figs. 1-3: the meridian model's contact point does not slip
along ``nu`` (the horizontal projection of the axis ``e3``) and slips freely along
``tau = nu x gamma``. Its slip is ``vp = u_tau tau`` with ``vp = v + w x r``, ``r = -R gamma - a``
(docs/model.md, "Constraints"). Three devices take up that slip:

- **roller-bearing sphere** (Fig. 1): rollers along the meridians, each axis tangent to its
  meridian, so the roller at the contact has its axis along ``nu``; it turns about its axis at
  ``u_tau / rho`` (``rho``: its radius at the contact) and the sphere slides along ``tau``
  (:func:`roller_layout`, :func:`roller_spin`);
- **spherical shell with a rotor** (Fig. 2): a weightless shell rolling without slipping with the
  heavy axisymmetric body inside, free to turn about the shell-fixed axis ``e3``. The shell's
  angular velocity is ``Omega = w + delta e3``; its contact point is at rest,
  ``v_O + Omega x (-R gamma) = 0``, and the rotor's is ``vp = v_O + w x (-R gamma)``, so
  ``vp = R delta e3 x gamma = R delta sigma tau``: ``delta = u_tau / (R sigma)`` with
  ``sigma = (e3, nu) = s = sqrt(1 - gamma3^2)`` (:func:`shell_spin_rate`, :func:`shell_spin_angle`);
- **sphere of skates on ice** (Fig. 3): thin disks threaded onto the axis ``e3``, so each disk's
  edge is a parallel of the sphere; the disk at the contact slides freely in its own plane (along
  ``tau``) and cannot move across it (along its normal ``e3``, whose horizontal part is along
  ``nu``); the sphere rolls over from disk to disk along the meridian (:func:`skate_layout`).

A model declares the devices that realise it (:attr:`rollingtop.contact.ContactModel.devices`:
the meridian model all three, the ``shell-rotor`` pair its shell, whose spin is then the
pair's own state variable); :func:`check_device` refuses the others. ``nu`` and
``tau`` are taken from the state's carried direction ``psi_nu``
(``nu = cos(psi_nu) alpha + sin(psi_nu) beta``, :mod:`rollingtop._layout`), which is
regular through a pole passage, where ``sigma`` changes sign.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import make_interp_spline

from rollingtop._errors import ContactModelError
from rollingtop._layout import ALPHA, BETA, GAMMA, PSI_NU, V, W
from rollingtop._types import FloatArray, IntArray
from rollingtop.body import SphericalTop
from rollingtop.contact import MODELS, ContactModel

__all__ = [
    "DEVICES",
    "RollerLayout",
    "SkateLayout",
    "check_device",
    "constraint_directions",
    "roller_layout",
    "roller_spin",
    "shell_spin_angle",
    "shell_spin_rate",
    "skate_layout",
    "tau_slip",
]

#: The devices of the paper's Sec. 1 (a model lists those that realise it:
#: :attr:`rollingtop.contact.ContactModel.devices`).
DEVICES: dict[str, str] = {
    "roller": "roller-bearing sphere (Fig. 1)",
    "shell": "spherical shell with a rotor (Fig. 2)",
    "skates": "sphere of skates on ice (Fig. 3)",
}


def check_device(device: str, model: ContactModel) -> None:
    """A :class:`~rollingtop.ContactModelError` unless ``device`` realises ``model``'s
    constraint (:attr:`~rollingtop.contact.ContactModel.devices`)."""
    if device not in DEVICES:
        raise ContactModelError(f"unknown device {device!r} (known: {', '.join(DEVICES)})")
    if device not in model.devices:
        realised = [m.name for m in MODELS.values() if device in m.devices]
        raise ContactModelError(
            f"the {device} device realises the constraint of model "
            f"{' or '.join(map(repr, realised))} (no slip along nu, free slip along tau), not "
            f"that of model {model.name!r}"
        )


def constraint_directions(y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Body-frame ``nu`` and ``tau = nu x gamma`` of states ``y`` (n, 18), each (n, 3), from the
    carried azimuth ``psi_nu``."""
    c, s = np.cos(y[:, PSI_NU])[:, None], np.sin(y[:, PSI_NU])[:, None]
    nu = c * y[:, ALPHA] + s * y[:, BETA]
    return nu, np.cross(nu, y[:, GAMMA])


def tau_slip(body: SphericalTop, y: FloatArray) -> FloatArray:
    """Slip ``u_tau = (vp, tau)`` of the contact point, shape (n,): ``vp = v + w x r`` with
    ``r = -R gamma - a`` (docs/model.md)."""
    r = -body.R * y[:, GAMMA]
    r[:, 2] -= body.a3
    vp = y[:, V] + np.cross(y[:, W], r)
    _, tau = constraint_directions(y)
    return np.asarray(np.einsum("ij,ij->i", vp, tau), dtype=np.float64)


def shell_spin_rate(
    body: SphericalTop, y: FloatArray, model: ContactModel | None = None
) -> FloatArray:
    """Spin ``delta = Omega3 - w3 = u_tau / (R sigma)`` of the rolling shell relative to the rotor
    (module docstring), shape (n,). Infinite or large where the axis passes the vertical
    (``sigma = 0``) with slip. A ``model`` with its own inertia (the ``shell-rotor`` pair) keeps
    ``delta`` in the state's last slot: that is returned."""
    if model is not None and model.own_inertia:
        return np.asarray(y[:, PSI_NU], dtype=np.float64)
    nu, _ = constraint_directions(y)
    with np.errstate(divide="ignore", invalid="ignore"):
        return tau_slip(body, y) / (body.R * nu[:, 2])


def shell_spin_angle(
    t: FloatArray, body: SphericalTop, y: FloatArray, model: ContactModel | None = None
) -> FloatArray:
    """The shell's turn about ``e3`` relative to the rotor, ``chi(t) = int_{t0}^t delta dt``, at
    the sample times ``t`` (n,), from the rate at the samples ``y`` (n, 18).

    Quadrature of the quintic interpolating spline of :func:`shell_spin_rate` through the
    samples: its error is ``O(h^6)`` in the sample spacing ``h``. Measured on
    ``examples/paper.toml`` over ``0 <= t <= 10`` (``chi`` reaches -15.5) against ``solve_ivp``
    (DOP853, ``rtol = 1e-12``) on the full equations with ``chi`` appended: 6e-12 off at
    ``h = 0.01`` (the animation's 4 samples per frame at 25 fps), 6e-8 at ``h = 0.05``, 6e-6 at
    ``h = 0.1`` (``tests/test_devices.py`` holds the first).

    Raises :class:`~rollingtop.ContactModelError` where the axis passes the vertical (``sigma``
    changes sign, a pole case of the meridian model): the rotor's contact point slips there
    (``u_tau != 0``), so the shell would have to spin infinitely fast; the shell cannot realise
    that motion. The ``shell-rotor`` pair (``model`` with its own inertia) has a shell of mass
    and its spin in the state: finite everywhere.
    """
    t = np.asarray(t, dtype=float)
    own = model is not None and model.own_inertia
    nu, _ = constraint_directions(y)
    sigma = nu[:, 2]
    if not own and (np.any(sigma <= 0) or not np.all(np.isfinite(sigma))):
        i = int(np.argmax(~(sigma > 0)))
        when = f"at t = {t[i]:.6g}" if i == 0 else f"between t = {t[i - 1]:.6g} and {t[i]:.6g}"
        raise ContactModelError(
            f"the axis passes the vertical {when}, where the contact slips "
            f"(u_tau = {tau_slip(body, y[i : i + 1])[0]:.3g}): a shell would spin infinitely fast"
        )
    if t.size < 2:
        return np.zeros_like(t)
    rate = shell_spin_rate(body, y, model)
    k = 5 if t.size > 5 else (3 if t.size > 3 else 1)
    spline = make_interp_spline(t, rate, k=k).antiderivative()
    return np.asarray(spline(t) - spline(t[0]), dtype=float)


@dataclass(frozen=True)
class RollerLayout:
    """Rollers on the meridians of the unit sphere, body frame (Fig. 1).

    Attributes
    ----------
    centre : ndarray, shape (k, 3)
        Unit vectors to each roller's outer point (where it touches the plane).
    axis : ndarray, shape (k, 3)
        Unit axes, tangent to the meridian through ``centre``, pointing towards the pole ``+e3``.
    radius : ndarray, shape (k,)
        Each roller's radius at ``centre``, in units of ``R``.
    half_angle : float
        Half the arc of the meridian each roller covers (its profile is that arc).
    """

    centre: FloatArray
    axis: FloatArray
    radius: FloatArray
    half_angle: float

    def nearest(self, point: FloatArray) -> IntArray:
        """Index of the roller whose outer point is nearest each unit vector ``point`` (n, 3)."""
        return np.asarray(np.argmax(point @ self.centre.T, axis=1), dtype=np.int64)


def roller_layout(
    n_meridians: int = 16, n_rollers: int = 7, polar_gap: float = 0.3
) -> RollerLayout:
    """``n_rollers`` rollers on each of ``n_meridians`` meridians, between the polar angles
    ``polar_gap`` and ``pi - polar_gap`` (the poles hold the hub). Radii shrink with the
    distance to the axis so that neighbouring meridians' rollers do not overlap."""
    arc = (np.pi - 2 * polar_gap) / n_rollers
    theta = polar_gap + arc * (np.arange(n_rollers) + 0.5)
    phi = 2 * np.pi * np.arange(n_meridians) / n_meridians
    th, ph = np.meshgrid(theta, phi)  # (meridian, roller)
    st, ct, sp, cp = np.sin(th), np.cos(th), np.sin(ph), np.cos(ph)
    centre = np.stack([st * cp, st * sp, ct], -1).reshape(-1, 3)
    axis = np.stack([-ct * cp, -ct * sp, st], -1).reshape(-1, 3)  # -d/dtheta: towards +e3
    spacing = np.minimum(np.pi / n_meridians * st, arc / 2)  # half the gap to the neighbours
    radius = (0.75 * spacing).reshape(-1)
    return RollerLayout(centre, axis, radius, 0.36 * arc)


def roller_spin(
    t: FloatArray, body: SphericalTop, y: FloatArray, layout: RollerLayout
) -> tuple[IntArray, FloatArray, FloatArray]:
    """Which roller touches the plane, and every roller's spin, at the samples.

    The roller in contact is the one nearest the contact point ``-gamma``; it turns about its
    axis, relative to the sphere, at ``u_tau / (rho R)`` (``rho`` its radius, in units of ``R``):
    then its point on the plane does not move along ``tau``, and along its axis (``nu`` in the
    limit of a dense layout) the sphere rolls. Off the plane a weightless roller's spin is not
    determined by the model; here one that leaves the plane keeps the rate it had (small inertia,
    frictionless bearings), a choice of the drawing that lets the turning rollers be seen.

    Returns
    -------
    contact : ndarray of int, shape (n,)
        The roller in contact at each sample.
    rate : ndarray, shape (n, k)
        Spin rate of every roller about its own axis.
    angle : ndarray, shape (n, k)
        Its turn since ``t[0]`` (trapezoidal rule on ``rate``).
    """
    contact = layout.nearest(-y[:, GAMMA])
    driven = tau_slip(body, y) / (body.R * layout.radius[contact])
    n, k = len(t), len(layout.radius)
    rate = np.zeros((n, k))
    current = np.zeros(k)
    for i in range(n):
        current[contact[i]] = driven[i]
        rate[i] = current
    angle = np.zeros((n, k))
    if n > 1:
        angle[1:] = np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t)[:, None], axis=0)
    return contact, rate, angle


@dataclass(frozen=True)
class SkateLayout:
    """Disks (skates) threaded onto the axis ``e3`` of the unit sphere, body frame (Fig. 3).

    Attributes
    ----------
    height : ndarray, shape (k,)
        Each disk's plane ``x3 = height``; its edge, of radius ``sqrt(1 - height^2)``, is a
        parallel of the sphere. Every disk's normal is ``e3``.
    thickness : float
        Disk thickness, in units of ``R``.
    """

    height: FloatArray
    thickness: float

    @property
    def radius(self) -> FloatArray:
        """Edge radius of each disk, in units of ``R``."""
        return np.sqrt(1 - self.height**2)

    def nearest(self, point: FloatArray) -> IntArray:
        """Index of the disk whose plane is nearest each unit vector ``point`` (n, 3)."""
        return np.asarray(
            np.argmin(np.abs(point[:, 2:3] - self.height[None, :]), axis=1), dtype=np.int64
        )


def skate_layout(n_disks: int = 9, thickness: float = 0.03) -> SkateLayout:
    """``n_disks`` disks evenly spaced along the axis, the outermost at 0.88 of the radius."""
    return SkateLayout(np.linspace(-0.88, 0.88, n_disks), thickness)
