"""Dense output of a DOP853 step: the model-independent evaluation of the interpolant.

The interpolant's coefficients are built from a step's stages by each model's compiled
:func:`rollingtop._compiled._template.dense.prepare_dense` (which evaluates the model's
right-hand side at three more stages), and the zeros on it are located there too.
"""

from __future__ import annotations

from rollingtop._jit import kernel
from rollingtop._types import FloatArray


@kernel
def dense_eval(Fd: FloatArray, y: FloatArray, x: float, out: FloatArray) -> None:
    """State at the fraction ``x`` of the step: ``y + sum`` of the interpolant's terms."""
    for i in range(y.shape[0]):
        acc = 0.0
        for r in range(6, -1, -1):
            acc += Fd[r, i]
            acc *= x if (6 - r) % 2 == 0 else 1.0 - x
        out[i] = y[i] + acc
