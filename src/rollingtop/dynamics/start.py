"""Initial conditions as a user gives them, and the state vector they build.

:class:`InitialConditions` holds what a scenario's ``[initial]`` table (or a caller) says:
orientation, angular velocity, position and either the contact model's free velocity
components or a full velocity. :meth:`InitialConditions.state` builds the constraint-consistent
state of :func:`rollingtop.dynamics.state.initial_state`; :meth:`InitialConditions.from_state`
goes back.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._layout import ALPHA, GAMMA, POSITION, V, W
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel
from rollingtop.dynamics.state import initial_state

__all__ = ["InitialConditions"]


def _floats(values: NDArray[np.float64]) -> tuple[float, ...]:
    return tuple(float(x) for x in values)


@dataclass(frozen=True)
class InitialConditions:
    """Initial conditions as given by the user (see :func:`rollingtop.initial_state`).

    Attributes
    ----------
    gamma, omega : sequence of 3 floats
        Upward vertical and angular velocity in the body frame.
    alpha : sequence of 3 floats, optional
        Fixed ``x`` axis in the body frame (default: along the axis' horizontal projection).
    position : sequence of 2 floats
        Horizontal centre-of-mass position.
    v : sequence of 3 floats, optional
        Full body-frame centre-of-mass velocity (exclusive with ``free``).
    free : mapping
        The contact model's free velocity components
        (:attr:`~rollingtop.contact.ContactModel.free_velocity`); missing ones are 0.

    Values are checked when the state is built (:meth:`state`), against a body and a model.
    """

    gamma: Sequence[float]
    omega: Sequence[float]
    alpha: Sequence[float] | None = None
    position: Sequence[float] = (0.0, 0.0)
    v: Sequence[float] | None = None
    free: Mapping[str, float | Sequence[float]] = field(default_factory=dict)

    @classmethod
    def from_state(cls, y: ArrayLike) -> InitialConditions:
        """The initial conditions that rebuild the state ``y`` (full velocity given)."""
        y = np.asarray(y, dtype=float)
        return cls(
            gamma=_floats(y[GAMMA]),
            omega=_floats(y[W]),
            alpha=_floats(y[ALPHA]),
            position=_floats(y[POSITION]),
            v=_floats(y[V]),
        )

    def state(self, body: SphericalTop, model: ContactModel | str) -> NDArray[np.float64]:
        """The constraint-consistent state vector, shape (18,).

        Raises
        ------
        InitialStateError
            Values inconsistent with ``body`` or ``model`` (see
            :func:`rollingtop.dynamics.state.initial_state`).
        """
        return initial_state(
            body,
            model,
            gamma=self.gamma,
            omega=self.omega,
            alpha=self.alpha,
            position=self.position,
            v=self.v,
            free=self.free,
        )
