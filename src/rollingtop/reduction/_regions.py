"""The regions of a bifurcation diagram (:mod:`rollingtop.reduction.bifurcation`): a
:class:`Region`, which periodic orbits a level ``h`` holds, grouped by the centres they enclose,
and which pass through the pole."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rollingtop.reduction._critical_curves import FloatArray, _base_level, _critical
from rollingtop.reduction.level import LevelSet


@dataclass(frozen=True)
class Region:
    """A connected region of the ``(C2, h)`` plane in which every level holds the same orbits.

    Attributes
    ----------
    name : str
        ``"A"``, ``"B"``, ... in order of the representative point's ``C2``, then ``h``.
    signature : tuple of int
        Centres inside each periodic orbit, in order of increasing ``gamma3``
        (:func:`region_signature`).
    label : str
        The signature in words.
    C2, h : float
        A representative level: the middle of the region's interval of ``h`` in its middle
        column.
    centre_gamma3 : tuple of tuple of float
        At the representative level: ``gamma3`` of the centres inside each orbit.
    through_pole : tuple of bool
        Whether each orbit passes through the pole (pole levels ``C1 = +-M3`` only).
    C2_range, h_range : tuple of float
        The extent of the region on the grid.
    cells : int
        The number of columns (values of ``C2`` on the grid) it spans.
    """

    name: str
    signature: tuple[int, ...]
    label: str
    C2: float
    h: float
    centre_gamma3: tuple[tuple[float, ...], ...]
    through_pole: tuple[bool, ...]
    C2_range: tuple[float, float]
    h_range: tuple[float, float]
    cells: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "label": self.label,
            "orbits": len(self.signature),
            "centres_per_orbit": list(self.signature),
            "C2": self.C2,
            "h": self.h,
            "centre_gamma3": [list(g) for g in self.centre_gamma3],
            "through_pole": list(self.through_pole),
            "C2_range": list(self.C2_range),
            "h_range": list(self.h_range),
            "cells": self.cells,
        }


#: Marks an orbit (a tuple of centre indices) that passes through the pole.
THROUGH_POLE = -1
#: The pole's energy among the cuts of a column's h axis (pole levels).
POLE_CUT = -2


def _orbits_at(
    U: FloatArray,
    centre: NDArray[np.bool_],
    h: float,
    theta: FloatArray | None = None,
    pole: tuple[float, float] | None = None,
) -> tuple[tuple[int, ...], ...]:
    """The periodic orbits of the level ``h`` from the critical points (in order of decreasing
    ``theta``, ``U`` there, which are centres): each orbit as the indices of the centres it
    encloses, followed by :data:`THROUGH_POLE` when it passes through ``pole`` = ``(theta_p,
    U(theta_p))`` (a pole level; ``theta`` the critical points' angles). Exact: ``U`` is monotone
    between critical points and ``+inf`` at both ends of the domain, so the intervals of
    ``{U < h}`` are separated by the saddles with ``U >= h``."""
    orbits: list[tuple[int, ...]] = []
    group: list[int] = []
    upper = math.inf  # theta of the saddle that bounds the current group from above

    def close(lower: float) -> None:
        if not group:
            return
        through = pole is not None and pole[1] < h and lower < pole[0] < upper
        orbits.append((*group, THROUGH_POLE) if through else tuple(group))

    for k in range(len(U)):
        if not centre[k] and U[k] >= h:
            close(float(theta[k]) if theta is not None else -math.inf)
            group = []
            upper = float(theta[k]) if theta is not None else math.inf
        elif centre[k] and U[k] < h:
            group.append(k)
    close(-math.inf)
    return tuple(orbits)


def _centres(orbit: Sequence[int]) -> list[int]:
    return [k for k in orbit if k != THROUGH_POLE]


def _pole(level: LevelSet) -> tuple[float, float] | None:
    """``(theta, U)`` of the pole an orbit of a pole level can pass, else ``None``."""
    t = level.pole_theta
    return None if t is None else (t, float(level.U(t)))


def region_orbits(level: LevelSet, h: float) -> list[tuple[int, bool]]:
    """What the level ``h`` of ``level`` holds: for each periodic orbit (each interval of
    ``{U < h}``, in order of increasing ``gamma3``, or of decreasing signed ``theta`` on a pole
    level) the number of centres (minima of ``U``) inside it and whether it passes through the
    pole; ``[]``: no motion (``h <= min U``)."""
    _base_level(level.body, level.M3, level.C1)  # refuses the level without spin
    theta, U, u2 = _critical(level)
    return [
        (len(_centres(o)), THROUGH_POLE in o) for o in _orbits_at(U, u2 > 0, h, theta, _pole(level))
    ]


def region_signature(level: LevelSet, h: float) -> tuple[int, ...]:
    """The number of centres inside each orbit of the level ``h`` (:func:`region_orbits`)."""
    return tuple(n for n, _ in region_orbits(level, h))


def describe_signature(signature: Sequence[int], through_pole: Sequence[bool] = ()) -> str:
    """Words for a :func:`region_signature`: ``"1 orbit around 1 centre"``, ``"2 orbits around
    1 + 1 centres"``, ``"no motion"``; with ``through_pole``, which orbits pass the pole."""
    if not signature:
        return "no motion"
    n = len(signature)
    centres = " + ".join(str(c) for c in signature)
    plural = "s" if n > 1 or signature[0] != 1 else ""
    words = f"{n} orbit{'s' if n > 1 else ''} around {centres} centre{plural}"
    passing = [k for k, p in enumerate(through_pole) if p]
    if passing and n == 1:
        words += ", through the pole"
    elif passing:
        which = " and ".join(f"orbit {k + 1}" for k in passing)
        words += f" ({which} through the pole)"
    return words
