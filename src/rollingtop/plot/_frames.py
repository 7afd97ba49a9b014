"""What every frame of an animation shows, from the trajectory's samples."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rollingtop._types import FloatArray

if TYPE_CHECKING:
    from rollingtop.trajectory import Trajectory

__all__ = ["FrameGeometry", "frame_geometry"]


@dataclass(frozen=True)
class FrameGeometry:
    """The body's placement at each frame time, fixed frame.

    Attributes
    ----------
    times : ndarray, shape (n,)
    Q : ndarray, shape (n, 3, 3)
        Body components to fixed ones (rows ``alpha, beta, gamma``; column 3 is ``e3``).
    centre, com, contact : ndarray, shape (n, 3)
        Geometric centre, centre of mass, contact point (on the plane).
    R, a3 : float
    """

    times: FloatArray
    Q: FloatArray
    centre: FloatArray
    com: FloatArray
    contact: FloatArray
    R: float
    a3: float

    def at(self, values: FloatArray, t: FloatArray) -> FloatArray:
        """Sampled ``values`` (len(t), ...) interpolated linearly at the frame times."""
        flat = np.asarray(values, dtype=float).reshape(len(t), -1)
        out = np.stack([np.interp(self.times, t, flat[:, k]) for k in range(flat.shape[1])], 1)
        return out.reshape((len(self.times), *np.shape(values)[1:]))


def frame_geometry(traj: Trajectory, times: FloatArray) -> FrameGeometry:
    """The states interpolated linearly at ``times``, the frames re-orthonormalised."""
    Y = np.stack([np.interp(times, traj.t, traj.y[:, k]) for k in range(traj.y.shape[1])], 1)
    R, a3 = traj.body.R, traj.body.a3
    Q = Y[:, 6:15].reshape(-1, 3, 3)
    U, _, Vt = np.linalg.svd(Q)
    Q = U @ Vt  # interpolated frames re-orthonormalised
    com = np.concatenate([Y[:, 15:17], (R + a3 * Q[:, 2, 2])[:, None]], 1)  # height R + a3 g3
    centre = com - a3 * Q[:, :, 2]  # geometric centre = CoM - Q a
    contact = np.concatenate([centre[:, :2], np.zeros((len(times), 1))], 1)
    return FrameGeometry(np.asarray(times, float), Q, centre, com, contact, R, a3)
