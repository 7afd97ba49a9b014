"""The arrays the compiled loop needs to hold integrals by projection
(:func:`rollingtop.integrate.integrate`'s ``project_integrals``)."""

from __future__ import annotations

import numpy as np

from rollingtop._errors import IntegrationError
from rollingtop._jit import call
from rollingtop._types import FloatArray, IntArray

__all__ = ["held_arrays", "none_held"]


def held_arrays(
    code: int, p: FloatArray, y0: FloatArray, held: IntArray | None
) -> tuple[IntArray, FloatArray, FloatArray]:
    """The arrays of the projection onto the integrals ``held`` (codes of
    :mod:`rollingtop._compiled._integrals`; ``None``: no projection): their codes, their values
    at ``y0`` (the compiled evaluation the projection compares with) and its work array."""
    if held is None or len(held) == 0:
        return none_held()
    from rollingtop._compiled import _integrals
    from rollingtop._compiled._template.invariants import WORK_SHAPE

    icodes = np.ascontiguousarray(held, dtype=np.int64)
    targets = np.array([call(_integrals.integral_value, int(c), p, y0) for c in icodes])
    if not np.all(np.isfinite(targets)):
        raise IntegrationError("the integrals to hold are not finite at the initial state")
    return icodes, targets, np.zeros(WORK_SHAPE)


def none_held() -> tuple[IntArray, FloatArray, FloatArray]:
    """:func:`held_arrays` for no projection: no codes, no values, a placeholder work array
    (the compiled loop's argument types whether or not integrals are held)."""
    return np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros((1, 8))
