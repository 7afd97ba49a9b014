"""Array and tuple types of the annotations, defined once.

numba ignores annotations, so the compiled kernels (:mod:`rollingtop._jit`) are annotated like
any Python function: the arrays they take are float64 (states, parameters, work arrays) or int64
(counters, codes), scalars are ``float``, ``int`` or ``bool``.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

FloatArray: TypeAlias = NDArray[np.float64]
IntArray: TypeAlias = NDArray[np.int64]
ComplexArray: TypeAlias = NDArray[np.complex128]
#: Work arrays ``(J, bias, dirs, A, lam)`` of the kernels, shapes ``(4, 6), (4,), (4, 3), (4, 4),
#: (4,)`` (:func:`rollingtop._compiled._kernel.new_workspace`).
Workspace: TypeAlias = tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]
#: Three scalars: the components of a vector.
Float3: TypeAlias = tuple[float, float, float]
#: Six scalars: a vector and its rate, or the six components of a generalised force.
Float6: TypeAlias = tuple[float, float, float, float, float, float]
