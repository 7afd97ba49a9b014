"""What every contact model declares: its name, constraints, free velocities and integrals."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactModel:
    """A set of ideal constraints at the contact point, with what follows from it.

    Attributes
    ----------
    name : str
        Name used in scenario files and on the command line.
    code : int
        Selector of the model's constraint kernel in the compiled right-hand side.
    description : str
        One line, for help texts.
    constraints : tuple of str
        Human-readable name of each constraint row, in kernel order.
    free_velocity : dict of str to int
        Velocity components the constraints leave free, each with its length (1: scalar).
    integrals_symmetric, integrals_general : tuple of str
        First integrals that hold for a dynamically symmetric body (``I1 == I2``) and for a
        general one (names of :mod:`rollingtop.dynamics.integrals`).
    singular : callable or None
        ``singular(gamma) -> str | None``: why the model's constraint directions are undefined at
        this orientation (``None`` where they are defined).
    velocity : callable
        ``velocity(body, gamma, omega, alpha, beta, free) -> v``: the body-frame CoM velocity,
        shape (3,), that satisfies the constraints for the given free components.
    """

    name: str
    code: int
    description: str
    constraints: tuple[str, ...]
    free_velocity: dict[str, int]
    integrals_symmetric: tuple[str, ...]
    integrals_general: tuple[str, ...]
    velocity: Callable[..., np.ndarray]
    singular: Callable[[np.ndarray], str | None] | None = None

    def integrals(self, symmetric: bool) -> tuple[str, ...]:
        """Names of the first integrals of this model for a (non-)symmetric body."""
        return self.integrals_symmetric if symmetric else self.integrals_general


def contact_arm(body, gamma: np.ndarray) -> np.ndarray:
    """Contact point seen from the centre of mass, ``r = -R gamma - a``, shape (3,)."""
    return -body.R * np.asarray(gamma, dtype=float) - np.array([0.0, 0.0, body.a3])
