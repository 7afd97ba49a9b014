"""Levels near a pole level, ``0 < |C1 -+ M3|`` small: what the orbits tend to, and what it costs.

On the pole level ``C1 = M3`` itself (south; north alike) the potential is finite at the pole and
the orbit passes through it. On every neighbouring level ``U`` has a wall next to the pole, of
width about ``|C1 - M3| / sqrt(I1 h)``: the orbit reflects there, and inside the wall the axis
swings round the vertical by about ``pi`` in a time of the order of the width, the sense of the
swing set by the sign of ``C1 - M3`` (``psi' ~ (C1 - M3) / (I1 theta^2)`` there). Hence, as
``C1 -> M3`` (in the canonical frame of :func:`rollingtop.reduction.orbits.canonical_orbit`,
``theta`` measured from the pole):

- the period tends to the *reflecting limit* ``T_lim(C2) = 2 int_0^{theta_+} dt`` on the pole level
  (``theta_+`` its turning point), approached like ``|C1 - M3| log(1 / |C1 - M3|)``;
- ``Delta psi`` tends to ``S + 2 arcsin(B / sqrt(B^2 + 4 A E)) - sign(M3 - C1) pi``, with
  ``S = 2 int_0^{theta_+} psi' dt`` on the pole level and the wall's own contribution from
  ``U = U_P(0) + A / z^2 + sign(M3 - C1) B / z`` in the stretched variable ``theta = |C1 - M3| z``:
  ``A = rho(0) / (2 I1^2)``, ``B = m (R + a3) C2 / I1^2``, ``E = h - U_P(0)`` (``U_P`` the pole
  level's potential). Inside the wall ``psi' = -(M3 - C1) / (I1 theta^2)``, and
  ``int psi' dt = -sign(M3 - C1) (pi/2 - arcsin(sign(M3 - C1) B / sqrt(B^2 + 4 A E)))`` per
  crossing. The limits from the two sides differ by ``2 pi`` and neither equals the pole
  level's value;
- the pole level's own period is the sum of the reflecting limits on both sides of the pole,
  which in the paper's unsigned variables are the limits at ``C2`` and at ``-C2`` (tested);
- the friction coefficient the constraint needs grows without bound, like ``1 / |C1 - M3|``:
  the plane must turn the contact force round the vertical within the wall.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from rollingtop._json import json_ready
from rollingtop.reduction._quadrature import WALL_RATIO, half_integral, half_map, period
from rollingtop.reduction.level import Level, LevelSet, LevelSetError
from rollingtop.reduction.orbits import Orbit, canonical_orbit, near_north, orbits

__all__ = ["NEAR_POLE", "NearPole", "near_pole", "friction_needed"]

#: ``|C1 -+ M3|`` below this times ``max(|M3|, |C1|)`` (and an orbit at the wall): the orbits
#: report their limits on the pole level (:func:`near_pole`).
NEAR_POLE = 1e-2


@dataclass(frozen=True)
class NearPole:
    """An orbit next to the wall of a level near a pole level, and its limits (module docstring).

    Attributes
    ----------
    pole : {"south", "north"}
    offset : float
        ``C1 - M3`` (south) or ``C1 + M3`` (north).
    wall_distance : float
        Distance of the orbit's turning point from the pole (``Orbit.pole_distance``).
    period_limit, delta_psi_limit : float
        Limits of the period and of ``Delta psi`` as ``C1 -> +-M3`` from this side.
    pole_level_period, pole_level_delta_psi : float
        The same on the pole level itself, where the orbit passes through the pole (NaN when
        the pole level has no such orbit at this ``h``).
    friction_needed : float
        Largest ratio of tangential to normal contact force on this orbit
        (:func:`friction_needed`).
    min_normal_force : float
        Smallest normal force on the orbit (negative: the body would leave the plane).
    """

    pole: str
    offset: float
    wall_distance: float
    period_limit: float
    delta_psi_limit: float
    pole_level_period: float
    pole_level_delta_psi: float
    friction_needed: float
    min_normal_force: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite values become ``None``)."""
        return json_ready(asdict(self))

    def note(self) -> str:
        """One sentence for the ``orbits`` table."""
        return (
            f"near the {self.pole} pole level (C1 {'-' if self.pole == 'south' else '+'} M3 = "
            f"{self.offset:.3g}): reflects {self.wall_distance:.3g} rad from the pole; as C1 -> "
            f"{'' if self.pole == 'south' else '-'}M3 from this side T -> "
            f"{self.period_limit:.12g}, delta_psi -> {self.delta_psi_limit:.12g} (on the pole "
            f"level itself T = {self.pole_level_period:.12g}); friction coefficient needed "
            f"{self.friction_needed:.3g}"
        )


def friction_needed(
    level: Level, h: float, orbit: Orbit, samples: int = 400
) -> tuple[float, float]:
    """``(max |F_t| / N, min N)`` over the orbit: the friction coefficient the meridian
    constraint needs and the smallest normal force, from the contact reaction of the full
    equations at states of the orbit (both senses of motion).

    The states are sampled at ``dist_pole = dist_end cosh u`` near a wall (where the force
    peaks) and uniformly in the nutation angle elsewhere.
    """
    lv, o = canonical_orbit(level, h, orbit)
    return _friction(lv, h, o, samples)


def _friction(lv: Level, h: float, o: Orbit, samples: int = 400) -> tuple[float, float]:
    """:func:`friction_needed` on the canonical level and orbit (``canonical_orbit``)."""
    from rollingtop._compiled import compiling, for_model
    from rollingtop._jit import call
    from rollingtop.contact.meridian import MODEL
    from rollingtop.reduction.variables import state_from_level

    t1, t2 = o.theta_min, o.theta_max
    if not 0.0 < t1 < t2 < math.pi:
        raise LevelSetError("friction_needed: the orbit must lie inside 0 < theta < pi")
    mid = (t1 + t2) / 2
    ends = []
    for t_end, left in ((t1, True), (t2, False)):  # the quadrature's wall variable at each end
        half = half_map(t_end, mid, True, left)
        ends.append(half.theta(np.linspace(0.0, half.u_max, samples)))
    thetas = np.unique(np.concatenate([*ends, np.linspace(t1, t2, samples)]))
    thetas = thetas[(thetas >= t1) & (thetas <= t2)]
    states = []
    for theta in thetas:
        for branch in (1, -1):
            hh = max(h, float(lv.U(theta)))  # round-off at the turning points
            states.append(state_from_level(lv, hh, 0.0, theta=float(theta), branch=branch))
    Y = np.ascontiguousarray(states)
    out = np.zeros((Y.shape[0], 2))
    with compiling(MODEL, "dynamics"):
        call(for_model(MODEL).dynamics.contact_forces, MODEL.code, lv.body.params, Y, out)
    N, F = out[:, 0], out[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(N > 0, np.abs(F) / N, np.inf)
    return float(np.max(ratio)), float(np.min(N))


def near_pole(level: Level, h: float, orbit: Orbit) -> NearPole | None:
    """The limits of ``orbit`` on the pole level it is near (module docstring), or ``None``:
    for another model's level (its own limits are not derived), when the level is not within
    :data:`NEAR_POLE` of a pole level, or when the orbit does not reach the wall (its end is
    not within ``WALL_RATIO`` of its width from the pole)."""
    if level.pole is not None or orbit.kind != "periodic" or not level.near_pole_limits:
        return None  # the limits are the meridian model's (its pole levels, its reactions)
    assert isinstance(level, LevelSet)  # the one kind with near_pole_limits
    M3, C1 = level.M3, level.C1
    north = near_north(level)
    offset = C1 + M3 if north else C1 - M3
    if abs(offset) > NEAR_POLE * max(abs(M3), abs(C1)):
        return None
    lv, o = canonical_orbit(level, h, orbit)  # the pole at theta = 0
    assert isinstance(lv, LevelSet)  # the mirror image of a meridian level is one
    if not o.theta_min < WALL_RATIO * (o.theta_max - o.theta_min):
        return None
    pole_level = LevelSet(lv.body, lv.M3, lv.M3, lv.C2)
    found = [c for c in orbits(pole_level, h) if c.kind == "periodic" and c.pole_passage]
    T_lim = dpsi_lim = T_pole = dpsi_pole = math.nan
    if found:
        c = found[0]
        T_lim, _ = half_integral(pole_level, h, c.theta_max, 0.0, False, False)
        S, _ = half_integral(pole_level, h, c.theta_max, 0.0, False, False, weight="psi_dot")
        b = lv.body
        A = float(lv.rho(0.0)) / (2 * b.I1**2)
        B = b.m * (b.R + b.a3) * lv.C2 / b.I1**2
        E = h - float(pole_level.U(0.0))
        wall = 2 * math.asin(B / math.sqrt(B * B + 4 * A * E))
        dpsi_lim = S + wall - math.copysign(math.pi, lv.M3 - lv.C1)
        T_pole = c.period
        dpsi_pole, _ = period(
            pole_level, h, c.theta_min, c.theta_max, peaks=[0.0], weight="psi_dot"
        )
    mu, n_min = _friction(lv, h, o)
    return NearPole(
        "north" if north else "south",
        offset,
        o.theta_min,
        T_lim,
        dpsi_lim,
        T_pole,
        dpsi_pole,
        mu,
        n_min,
    )
