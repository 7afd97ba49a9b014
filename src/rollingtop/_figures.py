"""The figures of the objects that draw themselves, named rather than imported.

A level set, its steady motions and orbits, a bifurcation diagram and a trajectory have a
``.plot(ax)`` (notebook objects); what draws them is :mod:`rollingtop.plot`, which imports the
numerics to read those objects. So that the numerics never import the plotting layer (nor
matplotlib), not even inside a function, each ``.plot()`` names its drawer here, as
``"module:function"``, and :func:`draw` imports it by that name when called (the way pandas
loads its plotting backend, ``pandas.plotting._core._get_plot_backend``). The import graph of the
package then has no cycle (``tests/test_layout.py`` walks it) and the layers contract of
``pyproject.toml`` needs no exemption.
"""

from __future__ import annotations

import importlib
from typing import Any

from rollingtop._errors import RollingTopError

__all__ = ["DRAWERS", "TRAJECTORY_KINDS", "draw"]

#: What draws each kind of figure: ``"module:function"``, called as ``function(ax, *args, **kw)``.
DRAWERS: dict[str, str] = {
    "portrait": "rollingtop.plot.portrait:draw_portrait",
    "potential": "rollingtop.plot.portrait:draw_potential",
    "bifurcation": "rollingtop.plot.bifurcation:draw_bifurcation",
    "path": "rollingtop.plot.paths:draw_path",
    "gamma3": "rollingtop.plot.paths:draw_gamma3",
    "drift": "rollingtop.plot.paths:draw_drift",
    "reactions": "rollingtop.plot.paths:draw_reactions",
    "periodic": "rollingtop.plot.periodic:draw_periodic",
    "branch": "rollingtop.plot.continuation:draw_branch",
}

#: The kinds :meth:`rollingtop.Trajectory.plot` draws (the panels of ``rollingtop plot``).
TRAJECTORY_KINDS: tuple[str, ...] = ("path", "gamma3", "drift", "reactions")


def draw(kind: str, ax: Any, *args: Any, **kw: Any) -> Any:
    """Draw a figure of ``kind`` (:data:`DRAWERS`) on ``ax`` (``None``: a new figure's) and
    return the axes.

    Raises
    ------
    RollingTopError
        For a kind not in :data:`DRAWERS`.
    """
    try:
        module, function = DRAWERS[kind].split(":")
    except KeyError:
        raise RollingTopError(
            f"no figure of kind {kind!r} (known: {', '.join(map(repr, DRAWERS))})"
        ) from None
    return getattr(importlib.import_module(module), function)(ax, *args, **kw)
