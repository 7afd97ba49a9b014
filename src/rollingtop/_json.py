"""JSON helpers: strict JSON has no NaN or infinity."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, SupportsFloat


def finite_or_none(x: SupportsFloat) -> float | None:
    """``x`` as a float, or ``None`` when it is NaN or infinite."""
    x = float(x)
    return x if math.isfinite(x) else None


def json_ready(mapping: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of ``mapping`` with non-finite floats replaced by ``None``."""
    return {k: finite_or_none(v) if isinstance(v, float) else v for k, v in mapping.items()}
