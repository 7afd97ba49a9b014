"""Atomic figure output."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from rollingtop.io import atomic_write, check_output_path

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


def save_figure(fig: Figure, path: str | os.PathLike[str], *, dpi: int = 200) -> Path:
    """Save ``fig`` to ``path`` (PNG, SVG or PDF by suffix) atomically."""
    path = check_output_path(path, FIGURE_SUFFIXES)
    fmt = path.suffix.lower().lstrip(".")
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=dpi))
