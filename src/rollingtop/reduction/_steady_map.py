"""Maps of the number of steady motions over the plane ``(C1, C2)`` at fixed ``M3``
(:func:`steady_count_map`; the fold curves of :mod:`rollingtop.reduction.bifurcation` are its
boundaries)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._json import json_ready
from rollingtop.body import SphericalTop
from rollingtop.reduction._critical_curves import (
    BRANCH_POINTS,
    FloatArray,
    _base_level,
    _c2_star,
    _family,
    _interval_grid,
    _intervals,
    folds,
)
from rollingtop.reduction.level import LevelSetError


@dataclass(frozen=True)
class SteadyCountMap:
    """The number of steady motions over the plane ``(C1, C2)`` at fixed ``M3``.

    Attributes
    ----------
    M3 : float
    C1_grid, C2_grid : ndarray, shapes (n1,), (n2,)
    count : ndarray of int, shape (n2, n1)
        Number of critical points of ``U`` (on a pole line ``C1 = +-M3``, in the signed angle's
        domain; -1 for the level without spin, ``M3 = C1 = 0``, which is not classified).
    fold_C1, fold_C2 : ndarray, shape (k,)
        Points of the fold curves: every fold of every ``C1`` of the grid.
    """

    M3: float
    C1_grid: FloatArray
    C2_grid: FloatArray
    count: NDArray[np.int64]
    fold_C1: FloatArray
    fold_C2: FloatArray

    def to_dict(self) -> dict[str, Any]:
        values, cells = np.unique(self.count[self.count >= 0], return_counts=True)
        return json_ready(
            {
                "M3": self.M3,
                "C1_range": [float(self.C1_grid[0]), float(self.C1_grid[-1])],
                "C2_range": [float(self.C2_grid[0]), float(self.C2_grid[-1])],
                "grid": [len(self.C1_grid), len(self.C2_grid)],
                "steady_counts": {str(int(v)): int(c) for v, c in zip(values, cells, strict=True)},
                "fold_curve": [
                    [float(a), float(b)] for a, b in zip(self.fold_C1, self.fold_C2, strict=True)
                ],
            }
        )


def steady_count_map(
    body: SphericalTop,
    M3: float,
    *,
    C1_range: tuple[float, float],
    C2_range: tuple[float, float],
    resolution: tuple[int, int] = (121, 121),
) -> SteadyCountMap:
    """The number of steady motions at each ``(C1, C2)`` of a grid, and the fold curves.

    For each ``C1`` the steady motions of the level ``C2`` are the solutions of
    ``C2*(gamma3) = C2``, counted as sign changes of ``C2* - C2`` on each interval between the
    poles of ``C2*`` (:data:`BRANCH_POINTS` points each).
    """
    n1, n2 = (int(x) for x in resolution)
    if n1 < 2 or n2 < 2:
        raise LevelSetError(f"resolution = {resolution} must be at least (2, 2)")
    C1_grid = np.linspace(*C1_range, n1)
    C2_grid = np.linspace(*C2_range, n2)
    count = np.full((n2, n1), -1, dtype=np.int64)
    fold_c1: list[float] = []
    fold_c2: list[float] = []
    for k, c1 in enumerate(C1_grid):
        try:
            level = _base_level(body, M3, float(c1))
        except LevelSetError:
            continue  # a pole line
        # the family gamma3 = C1/M3 of a body with a3 = 0 is a steady motion at every C2
        total = np.full(n2, 0 if _family(level) is None else 1, dtype=np.int64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for a, e in _intervals(level):
                c2s = _c2_star(level, _interval_grid(a, e, BRANCH_POINTS))
                diff = np.sign(c2s[None, :] - C2_grid[:, None])
                total += np.count_nonzero(diff[:, :-1] * diff[:, 1:] < 0, axis=1)
        count[:, k] = total
        for f in folds(body, M3, float(c1)):
            fold_c1.append(float(c1))
            fold_c2.append(f.C2)
    return SteadyCountMap(float(M3), C1_grid, C2_grid, count, np.array(fold_c1), np.array(fold_c2))
