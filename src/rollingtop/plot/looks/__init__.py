"""How the animation draws the body: the plain wireframe, or one of the devices of the paper's
Sec. 1 that realise its constraint (Figs. 1-3).

A look is ``look(ax, geometry, traj, view) -> draw``: it adds its artists to the 3D axes and
returns ``draw(frame)``, which moves them to the frame's placement
(:class:`~rollingtop.plot._frames.FrameGeometry`). What a device's moving parts do comes from
:mod:`rollingtop.devices` (numerics); the ``draw_*`` functions take it as arrays, so another
model of the same device (a shell with its own spin, say) can feed them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, TypeAlias

from rollingtop.plot.looks._plain import plain_look
from rollingtop.plot.looks._roller import draw_rollers, roller_look
from rollingtop.plot.looks._shell import draw_shell, shell_look
from rollingtop.plot.looks._skates import draw_skates, skates_look

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d import Axes3D

    from rollingtop.plot._frames import FrameGeometry
    from rollingtop.trajectory import Trajectory

__all__ = ["LOOKS", "Look", "draw_rollers", "draw_shell", "draw_skates"]

Look: TypeAlias = Callable[
    ["Axes3D", "FrameGeometry", "Trajectory", tuple[float, float]], Callable[[int], None]
]

#: The looks by name; every one but ``plain`` is a device (:data:`rollingtop.devices.DEVICES`).
LOOKS: dict[str, Look] = {
    "plain": plain_look,
    "roller": roller_look,
    "shell": shell_look,
    "skates": skates_look,
}
