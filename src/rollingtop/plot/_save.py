"""Atomic figure output."""

from __future__ import annotations

from pathlib import Path

from rollingtop.io import atomic_write, check_output_path

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


def save_figure(fig, path, *, dpi: int = 200) -> Path:
    """Save ``fig`` to ``path`` (PNG, SVG or PDF by suffix) atomically."""
    path = check_output_path(path, FIGURE_SUFFIXES)
    fmt = path.suffix.lower().lstrip(".")
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=dpi))
