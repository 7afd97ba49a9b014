"""The spherical top: parameters, validation and derived quantities.

Notation of Kilin & Ivanova (2023), Sec. 2 (see also ``docs/model.md``, "Body and frames"): a
sphere of radius ``R`` and mass ``m`` whose centre of mass lies on the symmetry axis ``e3`` at
``a = (0, 0, a3)`` from the geometric centre, with central inertia ``diag(I1, I2, I3)``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import overload

import numpy as np
from numpy.typing import NDArray

from rollingtop._errors import BodyError

__all__ = ["OVERFLOW_DECADES", "SphericalTop", "largest_input"]

#: Names and meanings of the parameters, in the order of the compiled parameter vector.
PARAMETERS = {
    "R": "radius of the sphere",
    "m": "mass",
    "g": "gravitational acceleration",
    "a3": "offset of the centre of mass along the symmetry axis e3",
    "I1": "central moment of inertia about e1",
    "I2": "central moment of inertia about e2",
    "I3": "central moment of inertia about the symmetry axis e3",
    "shell_mass": "mass of the spherical shell around the body (model shell-rotor)",
    "shell_inertia": "moment of inertia of the shell about a diameter (model shell-rotor)",
}


def _is_real(x: object) -> bool:
    return isinstance(x, int | float | np.floating | np.integer) and not isinstance(x, bool)


@dataclass(frozen=True)
class SphericalTop:
    """A sphere with its centre of mass on its symmetry axis (a spherical top).

    Parameters
    ----------
    R : float
        Radius, ``R > 0``.
    m : float
        Mass, ``m > 0``.
    g : float
        Gravitational acceleration, ``g >= 0``.
    a3 : float
        Centre of mass offset along ``e3`` from the geometric centre, ``|a3| < R``.
    I1, I3 : float
        Central moments of inertia about ``e1`` and the symmetry axis ``e3``, positive.
    I2 : float, optional
        Central moment about ``e2``; defaults to ``I1`` (dynamically symmetric body, the case of
        the paper). The triangle inequalities of a rigid body must hold.
    shell_mass, shell_inertia : float, optional
        Mass of a spherical shell of radius ``R`` around the body and its moment of inertia
        about a diameter (a thin shell: ``2/3 shell_mass R^2``), ``>= 0`` (the inertia ``> 0``
        where the mass is), default 0: the ``shell-rotor`` model
        (:mod:`rollingtop.contact.shell_rotor`), where the body is the rotor inside the shell.
        Other models ignore them.

    Raises
    ------
    BodyError
        Listing *every* violated rule at once, each with the field, its value and the rule.

    Notes
    -----
    All parameters are in one consistent unit system of the user's choice; nothing is
    non-dimensionalised.
    """

    R: float
    m: float
    g: float
    a3: float
    I1: float
    I3: float
    I2: float | None = field(default=None)
    shell_mass: float = 0.0
    shell_inertia: float = 0.0

    def __post_init__(self) -> None:
        problems = []
        values = {}
        for name in ("R", "m", "g", "a3", "I1", "I3", "I2", "shell_mass", "shell_inertia"):
            x = getattr(self, name)
            if name == "I2" and x is None:
                continue
            if not _is_real(x) or not math.isfinite(float(x)):
                problems.append(f"{name} = {x!r} must be a finite real number")
                continue
            values[name] = float(x)
            object.__setattr__(self, name, float(x))
        if self.I2 is None and "I1" in values:
            object.__setattr__(self, "I2", values["I1"])
            values["I2"] = values["I1"]
        for name in ("R", "m", "I1", "I2", "I3"):
            if name in values and values[name] <= 0:
                problems.append(f"{name} = {values[name]:g} must be > 0 ({PARAMETERS[name]})")
        for name in ("g", "shell_mass", "shell_inertia"):
            if name in values and values[name] < 0:
                problems.append(f"{name} = {values[name]:g} must be >= 0")
        if values.get("shell_mass", 0.0) > 0 and values.get("shell_inertia") == 0.0:
            problems.append(
                f"shell_inertia = 0 with shell_mass = {values['shell_mass']:g} > 0: a shell has "
                "inertia about its diameters (a thin one 2/3 shell_mass R^2); without it the "
                "shell-rotor pair is singular at a vertical axis"
            )
        if all(k in values and values[k] > 0 for k in ("I1", "I2", "I3")):
            i1, i2, i3 = values["I1"], values["I2"], values["I3"]
            for name, lhs, a, b, rest in (
                ("I1", i1, "I2", "I3", i2 + i3),
                ("I2", i2, "I1", "I3", i1 + i3),
                ("I3", i3, "I1", "I2", i1 + i2),
            ):
                if lhs > rest * (1.0 + 1e-12):
                    problems.append(
                        f"{name} = {lhs:g} violates the rigid-body triangle inequality "
                        f"{name} <= {a} + {b} = {rest:g}"
                    )
        if "a3" in values and "R" in values and values["R"] > 0:
            if abs(values["a3"]) >= values["R"]:
                problems.append(
                    f"a3 = {values['a3']:g} violates |a3| < R = {values['R']:g} "
                    "(the centre of mass must lie inside the sphere)"
                )
        if problems:
            raise BodyError("inadmissible body: " + "; ".join(problems))

    @property
    def symmetric(self) -> bool:
        """``True`` when ``I1 == I2`` (dynamical symmetry, the case of the paper)."""
        return self.I1 == self.I2

    @property
    def inertia(self) -> NDArray[np.float64]:
        """Central inertia diagonal ``(I1, I2, I3)``, shape (3,)."""
        return np.array([self.I1, self.I2, self.I3])

    @property
    def has_shell(self) -> bool:
        """Whether a shell with mass or inertia surrounds the body (``shell-rotor``)."""
        return self.shell_mass > 0.0 or self.shell_inertia > 0.0

    @property
    def params(self) -> NDArray[np.float64]:
        """Parameters ``(R, m, g, a3, I1, I2, I3, shell_mass, shell_inertia)`` for the compiled
        kernels, then the contact model's four slots at 0 (each model's defaults:
        :meth:`rollingtop.contact.ContactModel.params` sets them), shape (13,)."""
        return np.array(
            [
                self.R,
                self.m,
                self.g,
                self.a3,
                self.I1,
                self.I2,
                self.I3,
                self.shell_mass,
                self.shell_inertia,
                0.0,
                0.0,
                0.0,
                0.0,
            ],
            dtype=float,
        )

    @overload
    def rho(self, gamma3: float) -> float: ...
    @overload
    def rho(self, gamma3: NDArray[np.float64]) -> NDArray[np.float64]: ...
    def rho(self, gamma3: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """Invariant-measure density ``rho = I1 + m (a3^2 + R^2 + 2 a3 R gamma3)`` (eq. 3.3), of
        the shape of ``gamma3`` (a numpy float for a float)."""
        return self.I1 + self.m * (
            self.a3**2 + self.R**2 + 2 * self.a3 * self.R * np.asarray(gamma3)
        )

    def to_dict(self) -> dict[str, float]:
        """Parameters as a plain dictionary (``I2`` included; the shell's where there is one)."""
        keys: tuple[str, ...] = ("R", "m", "g", "a3", "I1", "I2", "I3")
        if self.has_shell:
            keys += ("shell_mass", "shell_inertia")
        return {k: float(getattr(self, k)) for k in keys}


#: An input at least this many decades from 1 is named where a product of the equations
#: overflows (they multiply several inputs and their squares: R^2 m w^2, I w^2 R, ...); an input
#: nearer to 1 is not blamed, and the refusal stays generic.
OVERFLOW_DECADES = 50


def largest_input(
    body: SphericalTop, y: Sequence[float] | NDArray[np.float64]
) -> tuple[str, float]:
    """The body parameter or speed of the state ``y`` (shape (18,)) farthest from 1 in magnitude,
    as ``("name = value", |log10 value|)``: the input to blame for an overflow."""
    named = {
        k: float(getattr(body, k))
        for k in ("R", "m", "g", "a3", "I1", "I2", "I3", "shell_mass", "shell_inertia")
    }
    named |= {"|v|": math.hypot(*map(float, y[0:3])), "|omega|": math.hypot(*map(float, y[3:6]))}
    sizes = {k: abs(math.log10(abs(v))) for k, v in named.items() if v != 0 and math.isfinite(v)}
    worst = max(sizes, key=sizes.__getitem__)
    return f"{worst} = {named[worst]:g}", sizes[worst]
