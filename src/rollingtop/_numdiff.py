"""Jacobians by central differences, for the linearisations of steady motions
(:mod:`rollingtop.stability`, :func:`rollingtop.reduction.steady.linearised_eigenvalues`).

The right-hand sides differenced here are compiled kernels or closed forms that are not analytic
in complex arguments (square roots of ``1 - gamma3^2``, numba), so the complex step does not
apply; the central difference with a relative step of ``1e-6`` leaves an error of about ``1e-10``
of the Jacobian's size, far below the thresholds the callers apply.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rollingtop._types import FloatArray

__all__ = ["DIFF_STEP", "central_jacobian"]

#: Relative step: ``h_i = DIFF_STEP * max(1, |x_i|)``.
DIFF_STEP = 1e-6


def central_jacobian(
    fun: Callable[[FloatArray], FloatArray], x: FloatArray, steps: FloatArray | None = None
) -> FloatArray:
    """``d fun / d x`` at ``x`` by central differences, shape ``(len(fun(x)), len(x))``.

    ``steps`` replaces the default steps ``DIFF_STEP * max(1, |x_i|)`` (a caller near the edge
    of ``fun``'s domain shrinks them).
    """
    if steps is None:
        steps = DIFF_STEP * np.maximum(1.0, np.abs(x))
    columns = []
    for i, h in enumerate(steps):
        e = np.zeros(len(x))
        e[i] = h
        columns.append((fun(x + e) - fun(x - e)) / (2.0 * h))
    out: FloatArray = np.stack(columns, axis=1)
    return out
