"""Root bracketing for the reduction, with SciPy's optimiser imported on first use.

``scipy.optimize`` takes about a third of a second to import; every command that touches the
reduction -- ``simulate`` prints the level of the paper's model beside the energy -- would pay it
at start-up although most never look for a root.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["brentq"]


def brentq(f: Callable[..., float], a: float, b: float, **options: Any) -> Any:
    """:func:`scipy.optimize.brentq` (same arguments and result), imported on first call."""
    from scipy.optimize import brentq as scipy_brentq

    return scipy_brentq(f, a, b, **options)
