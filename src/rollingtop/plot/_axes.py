"""The axes a ``.plot()`` method draws on: the caller's, or a new figure's."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["axes_for"]


def axes_for(ax: Axes | None, figsize: tuple[float, float]) -> Axes:
    """``ax``, or the axes of a new pyplot figure of ``figsize`` inches (constrained layout):
    pyplot's, so that a notebook shows it under the cell and a script's ``plt.show()`` finds it,
    as ``xarray``'s and ``pandas``' ``.plot()`` do. The command line's figures are plain
    :class:`~matplotlib.figure.Figure` objects and never pass through here."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, new = plt.subplots(figsize=figsize, layout="constrained")
    return new
