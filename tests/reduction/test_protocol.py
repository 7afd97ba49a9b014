"""The reduction's protocol (issue 37, item 1): a reduced model is one Level kind and one
Reduction; everything downstream (steady motions, orbits and periods, the portrait's curves)
asks the level and needs nothing of the meridian model's.

The toy model here is Lagrange's top on a fixed point (not a model of rollingtop): on a level
``(M3, C1)`` its nutation is a particle of constant mass ``I1`` in
``U = (C1 - M3 cos)^2 / (2 I1 sin^2) + m g l cos`` (Goldstein, Classical Mechanics, Sec. 5.7).
Its steady motions and periods are checked against mpmath, written here from that formula.
"""

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import mpmath as mp
import numpy as np
import pytest

from rollingtop import SphericalTop
from rollingtop.contact import MODELS
from rollingtop.reduction import Level, orbits, steady_motions
from rollingtop.reduction.classify import AXES
from rollingtop.reduction.curves import default_h_levels, portrait_curves
from rollingtop.reduction.models import ATLAS_MODELS, REDUCTIONS, Reduction

from ..conftest import PAPER_BODY

#: Steady motions against mpmath's roots of U', relative.
ROOT_RTOL = 1e-10
#: Periods against mpmath's quadrature of sqrt(I1 / (2 (h - U))), relative.
PERIOD_RTOL = 1e-10
#: h = U + I1 w^2 / 2 along each curve of the portrait, relative.
ENERGY_RTOL = 1e-12

BODY = SphericalTop(**PAPER_BODY)
#: The toy's pivot-to-centre-of-mass distance.
ARM = 0.4


@dataclass(frozen=True)
class LagrangeTopLevel(Level):
    """A level ``(M3, C1)`` of the heavy symmetric top on a fixed point: every abstract method
    of Level, nothing else."""

    model: ClassVar[str] = "toy"
    integrals: ClassVar[tuple[str, ...]] = ("M3", "C1")
    energy_formula: ClassVar[str] = "h + M3^2/(2 I3)"

    body: SphericalTop
    M3: float
    C1: float
    scale: float = 0.0
    pole: str | None = field(default=None, init=False)

    def _q(self, theta):
        return (self.C1 - self.M3 * np.cos(theta)) / np.sin(theta)

    def U(self, theta):
        b = self.body
        return self._q(theta) ** 2 / (2 * b.I1) + b.m * b.g * ARM * np.cos(theta)

    def dU(self, theta):
        b = self.body
        q = self._q(theta)
        dq = (self.M3 - self.C1 * np.cos(theta)) / np.sin(theta) ** 2
        return q * dq / b.I1 - b.m * b.g * ARM * np.sin(theta)

    def rho(self, theta):
        return self.body.I1 + 0.0 * theta

    def drho(self, theta):
        return 0.0 * theta

    def P(self, theta):
        return 0.0 * theta  # the pivot does not move

    def w_n(self, theta):
        return -self._q(theta) / self.body.I1

    def spin(self, theta):
        return self.M3 / self.body.I3 + 0.0 * theta

    def psi_dot(self, theta):
        return self._q(theta) / (self.body.I1 * np.sin(theta))

    def full_energy(self, h):
        return h + self.M3**2 / (2 * self.body.I3)

    def pole_offsets(self):
        return self.C1 - self.M3, self.C1 + self.M3

    def mirrored(self):
        return LagrangeTopLevel(replace(self.body, a3=-self.body.a3), -self.M3, self.C1)

    linearised_eigenvalues = Level.curvature_eigenvalues

    def describe(self):
        return f"M3 = {self.M3:g}, C1 = {self.C1:g} (Lagrange's top)"


def _mp_U(M3, C1, g3):
    g3 = mp.mpf(g3)
    return (C1 - M3 * g3) ** 2 / (2 * BODY.I1 * (1 - g3**2)) + BODY.m * BODY.g * ARM * g3


def test_a_level_without_one_of_its_methods_cannot_be_made():
    """A kind that forgets a method of the protocol (its eigenvalues, say) is refused at
    construction, naming it: no meridian formula stands in for it."""

    del_name = "linearised_eigenvalues"
    attrs = {k: v for k, v in vars(LagrangeTopLevel).items()
             if k != del_name and k not in ("__dict__", "__weakref__")}  # fmt: skip
    Incomplete = type("Incomplete", (Level,), attrs)
    with pytest.raises(TypeError, match=del_name):
        Incomplete(BODY, 2.0, 0.5)
    assert LagrangeTopLevel(BODY, 2.0, 0.5).M3 == 2.0  # the complete kind is made


def test_a_reduction_of_the_toy_builds_its_levels_by_name():
    toy = Reduction(
        "toy", LagrangeTopLevel, lambda body, Y: {}, "E - I3 w3^2/2", "Goldstein", axis="C1"
    )
    level = toy.level(BODY, {"M3": 2.0, "C1": 0.5})
    assert isinstance(level, LagrangeTopLevel) and level.values() == {"M3": 2.0, "C1": 0.5}
    with pytest.raises(Exception, match="fixed by M3, C1"):
        toy.level(BODY, {"M3": 2.0})


def test_the_toys_steady_motions_orbits_and_curves_come_from_its_level_alone():
    M3, C1 = 2.0, 0.5
    level = LagrangeTopLevel(BODY, M3, C1)
    (centre,) = steady_motions(level)
    with mp.workdps(30):
        root = mp.findroot(lambda g: mp.diff(lambda x: _mp_U(M3, C1, x), g), centre.gamma3)
    assert centre.type == "center"
    assert centre.gamma3 == pytest.approx(float(root), rel=ROOT_RTOL)
    assert centre.spin == pytest.approx(M3 / BODY.I3, rel=1e-15)
    h = centre.U + 0.5
    (orbit,) = orbits(level, h)
    with mp.workdps(30):
        lo, hi = (mp.findroot(lambda g: _mp_U(M3, C1, g) - h, x)
                  for x in (orbit.gamma3_min, orbit.gamma3_max))  # fmt: skip
        # dt = I1^(1/2) dgamma3 / sqrt(2 (h - U) (1 - gamma3^2)), twice over [lo, hi]
        T = 2 * mp.quad(lambda g: mp.sqrt(BODY.I1 / (2 * (h - _mp_U(M3, C1, g)) * (1 - g**2))),
                        [lo, hi])  # fmt: skip
    assert orbit.period == pytest.approx(float(T), rel=PERIOD_RTOL)
    found = portrait_curves(level, default_h_levels(level))
    for c in found.curves:
        h_on = level.energy(np.arccos(c.x[::25]), c.w[::25])
        np.testing.assert_allclose(h_on, c.h, rtol=ENERGY_RTOL)
    assert level.full_energy(h) == pytest.approx(h + M3**2 / (2 * BODY.I3), rel=1e-15)
    assert math.isclose(float(level.v_tau(1.0)), 0.0, abs_tol=0.0)


def test_the_model_tables_come_from_the_registry():
    """Issue 37, item 2: each model's classification axis and atlas support are its Reduction's;
    the atlas classifies every reduced model whose body needs no shell, in registry order."""
    assert ATLAS_MODELS == tuple(
        m.name for m in MODELS.values() if m.reduction and not m.own_inertia
    )
    for name, reduction in REDUCTIONS.items():
        assert AXES[name] == reduction.axis and reduction.axis in reduction.names
