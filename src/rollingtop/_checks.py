"""Checks of user-given values (scenario tables, options): one short line per refusal.

Quoted values are cut to :data:`QUOTE_CHARS` (80) characters, so that a hostile value (a huge
integer, a long string) never makes a long message. A run plans its memory against
:func:`memory_limit` (8 GiB, or half the physical memory if less).
"""

from __future__ import annotations

import math
import os
import re

from rollingtop._errors import QUOTE_CHARS, ScenarioError, short_repr
from rollingtop.io import format_bytes

__all__ = [
    "MEMORY_CAP_BYTES",
    "QUOTE_CHARS",
    "check_memory",
    "memory_limit",
    "number",
    "short_name",
    "short_repr",
    "vector",
]

#: Cap on the memory a run may plan for, before the physical-memory bound.
MEMORY_CAP_BYTES = 8 << 30


def short_name(key: str, limit: int = QUOTE_CHARS) -> str:
    """A TOML key for a message: bare keys as they are, others quoted; cut to ``limit``."""
    key = str(key)
    if not re.fullmatch(r"[A-Za-z0-9_-]+", key):
        return short_repr(key, limit)
    return key if len(key) <= limit else key[: limit - 1] + "…"


def memory_limit() -> int:
    """Bytes a run may plan to allocate: :data:`MEMORY_CAP_BYTES` (8 GiB), or half the physical
    memory when that is less."""
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return MEMORY_CAP_BYTES
    return min(MEMORY_CAP_BYTES, physical // 2) if physical > 0 else MEMORY_CAP_BYTES


def check_memory(what: str, needed: float) -> None:
    """Refuse (``ScenarioError``) when ``needed`` bytes exceed :func:`memory_limit`."""
    limit = memory_limit()
    if needed > limit:
        raise ScenarioError(
            f"{what} needs about {format_bytes(needed)} of memory, more than the "
            f"{format_bytes(limit)} a run may use (the lesser of 8 GiB and half the physical "
            "memory)"
        )


def number(where: str, key: str, value: object, *, integer: bool = False) -> float | int:
    """``value`` as a finite float (``integer``: as an int, integral floats accepted), else a
    ``ScenarioError`` naming ``where.key`` and quoting the value (shortened)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "an integer" if integer else "a number"
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be {kind}")
    if integer:
        if isinstance(value, float):
            if not value.is_integer():
                raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be an integer")
            return int(value)
        return value
    try:
        x = float(value)
    except OverflowError:
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} is too large") from None
    if not math.isfinite(x):
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be finite")
    return x


def vector(where: str, key: str, value: object, length: int) -> tuple[float, ...]:
    """A list of ``length`` finite real numbers (no strings, booleans or tables in it)."""
    if not isinstance(value, list | tuple) or len(value) != length:
        raise ScenarioError(
            f"{where}.{key} = {short_repr(value)} must be a list of {length} numbers"
        )
    return tuple(float(number(where, f"{key}[{i}]", x)) for i, x in enumerate(value))
