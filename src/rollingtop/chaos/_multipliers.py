"""The multipliers of a section map on a level, and the type they give an orbit
(:mod:`rollingtop.chaos.periodic`, :mod:`rollingtop.chaos.continuation`)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rollingtop._types import FloatArray

__all__ = ["RANK_TOL", "UNIT_CIRCLE", "classify", "level_bases"]

#: A multiplier this close to modulus 1 counts as on the unit circle (``neutral`` / ``elliptic``),
#: at least.
UNIT_CIRCLE = 1e-5
#: Singular values of the integrals' gradients below this fraction of the largest count as 0.
RANK_TOL = 1e-8


def level_bases(G: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Orthonormal bases ``(T, Q)`` of the level's tangent plane (the null space of the
    integrals' gradients ``G``, shape (m, n)) and of ``G``'s rows: shapes (n, n - rank) and
    (n, rank). ``T`` is empty where the level meets the section in isolated points (an
    integrable level); ``Q`` where no integral is held."""
    n = G.shape[1]
    if not G.shape[0]:
        return np.eye(n), np.zeros((n, 0))
    _, sv, vt = np.linalg.svd(G)
    rank = int(np.sum(sv > RANK_TOL * sv[0])) if sv.size and sv[0] > 0 else 0
    return vt[rank:].T, vt[:rank].T


def classify(mu: NDArray[np.complex128], margin: float = UNIT_CIRCLE) -> str:
    """The type of multipliers ``mu``, a modulus within ``margin`` of 1 counting as on the unit
    circle (the differences' error: :data:`UNIT_CIRCLE`, or more where the multipliers' spread
    or the trivial ones' distance from 1 says so): ``attracting`` (all inside the circle),
    ``repelling`` (all outside), ``saddle`` (some of each), ``elliptic`` (all on it, complex),
    else ``neutral`` (one on it: the linearisation does not decide)."""
    if not mu.size:  # no multiplier on the level (an integrable level): nothing moves away
        return "neutral"
    r = np.abs(mu)
    inside, outside = r < 1.0 - margin, r > 1.0 + margin
    if np.all(inside):
        return "attracting"
    if np.all(outside):
        return "repelling"
    if np.any(inside) and np.any(outside):
        return "saddle"
    if np.all(~inside & ~outside) and np.any(np.abs(mu.imag) > margin):
        return "elliptic"
    return "neutral"  # a multiplier on the unit circle within the margin, the rest not beyond
