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
    velocity : callable
        ``velocity(body, gamma, omega, alpha, beta, free) -> v``: the body-frame CoM velocity,
        shape (3,), that satisfies the constraints for the given free components.
    singular : callable or None
        ``singular(body, gamma) -> str | None``: why no motion of this model can start at this
        orientation (``None`` where one can).
    vertical_tolerance : float
        Below this ``sqrt(gamma1^2 + gamma2^2)`` an initial axis counts as vertical and is set
        exactly vertical, ``gamma = (0, 0, +-1)`` (0: never; the models whose constraint
        directions are regular at the vertical need no such rule).
    vertical_direction : callable or None
        ``vertical_direction(omega, alpha, beta, psi_nu) -> psi_nu``: for a model that carries a
        constraint direction in the state (the meridian model's pole variants), its azimuth
        ``psi_nu`` in the fixed frame (``nu = cos(psi_nu) alpha + sin(psi_nu) beta``) at an
        exactly vertical axis, given the angular velocity and the frame; ``psi_nu`` is the value
        to keep where the model leaves the direction free. ``None``: the state's ``psi_nu`` is
        the axis azimuth, 0 at the vertical (unused by the model).
    select_code : callable or None
        ``select_code(body, y) -> int``: the kernel code for a motion from state ``y`` where the
        model has variants (:func:`rollingtop.contact.meridian.kernel_code`); ``None``: always
        :attr:`code`. See :meth:`kernel_code`.
    has_reduction : bool
        Whether the model's motions of a dynamically symmetric body reduce to one degree of
        freedom (:mod:`rollingtop.reduction`, the paper's Sec. 3): the level sets, orbits,
        portraits and absolute-motion quadratures apply.
    colour : str
        Matplotlib colour of the model in figures that compare models.
    """

    name: str
    code: int
    description: str
    constraints: tuple[str, ...]
    free_velocity: dict[str, int]
    integrals_symmetric: tuple[str, ...]
    integrals_general: tuple[str, ...]
    velocity: Callable[..., np.ndarray]
    singular: Callable[..., str | None] | None = None
    vertical_tolerance: float = 0.0
    vertical_direction: Callable[..., float] | None = None
    select_code: Callable[..., int] | None = None
    has_reduction: bool = False
    colour: str = "#7f7f7f"

    def integrals(self, symmetric: bool) -> tuple[str, ...]:
        """Names of the first integrals of this model for a (non-)symmetric body."""
        return self.integrals_symmetric if symmetric else self.integrals_general

    def kernel_code(self, body, y: np.ndarray) -> int:
        """The kernel code for a motion of ``body`` from state ``y`` (:attr:`code` unless the
        model has variants, see :attr:`select_code`)."""
        return self.code if self.select_code is None else int(self.select_code(body, y))


def contact_arm(body, gamma: np.ndarray) -> np.ndarray:
    """Contact point seen from the centre of mass, ``r = -R gamma - a``, shape (3,)."""
    return -body.R * np.asarray(gamma, dtype=float) - np.array([0.0, 0.0, body.a3])
