"""One orbit of a level set (:class:`Orbit`), the orbits of one energy (:class:`Orbits`), its
turning points and the tolerances that decide its kind: shared by :mod:`.orbits` (every level)
and :mod:`.no_spin` (the no-spin level, to which :func:`~rollingtop.reduction.orbits.orbits`
hands it), and re-exported by :mod:`.orbits`."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from rollingtop._figures import draw
from rollingtop._html import html_view
from rollingtop._json import json_ready
from rollingtop.reduction._roots import brentq
from rollingtop.reduction.level import Level

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["SEPARATRIX_TOLERANCE", "STEADY_TOLERANCE", "Orbit", "Orbits", "turning_point"]

#: ``|h - U(saddle)|`` below this (relative to the scale of ``U``) is on the separatrix.
SEPARATRIX_TOLERANCE = 1e-10
#: ``h - U_min`` below this (relative) is the steady motion itself.
STEADY_TOLERANCE = 1e-13


@dataclass(frozen=True)
class Orbit:
    """One connected component of the level set ``(M3, C1, C2, h)``.

    Attributes
    ----------
    gamma3_min, gamma3_max : float
        Range of ``gamma3`` on the orbit (a pole passage reaches ``+-1``).
    theta_min, theta_max : float
        Turning points in the signed nutation angle (``gamma3 = cos theta``).
    period : float
        Period of ``gamma3(t)`` (``inf`` on a separatrix).
    period_error : float
        Estimated absolute error of ``period``.
    kind : {"periodic", "steady", "separatrix"}
    pole_passage : bool
        The orbit passes through the pole (pole cases only).
    w_tau_max : float
        Largest ``|w_tau|`` on the orbit.
    note : str
        Plain-language remark (near separatrix, pole passage, ...), or empty.
    pole_distance : float
        Distance in ``theta`` of the orbit's nearer end from its pole, to full relative
        precision (``theta_max = pi - pole_distance`` near the north pole rounds it): the width
        of the gap next to the pole on a level near a pole level; NaN in a pole case.
    """

    gamma3_min: float
    gamma3_max: float
    theta_min: float
    theta_max: float
    period: float
    period_error: float
    kind: str
    pole_passage: bool
    w_tau_max: float
    note: str = ""
    pole_distance: float = math.nan

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite values become ``None``)."""
        return json_ready(asdict(self))

    @property
    def start_theta(self) -> float:
        """The canonical turning point to start the orbit from: ``theta_max`` (the lowest
        ``gamma3``) when it lies on the branch ``0 < theta < pi``, else ``theta_min`` (the other
        side of a pole passage); ``w_tau = 0`` there."""
        return self.theta_max if 0 < self.theta_max < math.pi else self.theta_min

    @property
    def rolls_over(self) -> bool:
        """``theta`` runs round the whole circle (no spin, above the upright pole's energy):
        the orbit has no turning points and ``theta_min``, ``theta_max`` are a full turn apart."""
        return self.theta_max - self.theta_min >= 2 * math.pi * (1 - 1e-12)


class Orbits(list[Orbit]):
    """The orbits of a level set at one reduced energy (:func:`~rollingtop.reduction.orbits`): a
    list, which also knows its :attr:`level` and :attr:`h`, shows itself as a table in a
    notebook and draws itself (:meth:`plot`).

    Attributes
    ----------
    level : LevelSet
    h : float
        The reduced energy.
    """

    def __init__(self, found: Iterable[Orbit], level: Level, h: float) -> None:
        super().__init__(found)
        self.level = level
        self.h = h

    def _repr_html_(self) -> str:
        """The notebook's view: the level, ``h`` and the full energy, a row per orbit (turning
        points, period, kind; ``rollingtop orbits``' table)."""
        return html_view(self)

    def plot(self, ax: Axes | None = None, **kw: Any) -> Axes:
        """Draw the orbits in ``(gamma3, w_tau)`` with the level's steady motions on ``ax``
        (default: a new figure's) and return ``ax``: ``rollingtop portrait --h-levels h``'s
        upper panel (:func:`rollingtop.plot.portrait.draw_portrait`, which takes ``kw``:
        ``show_contact``, ``legend``)."""
        axes: Axes = draw("portrait", ax, self.level, [self.h], **kw)
        return axes


def turning_point(level: Level, h: float, a: float, b: float) -> float:
    """The root of ``h = U(theta)`` in ``[a, b]`` (``U - h`` of opposite signs at the ends)."""
    # xtol tiny: the root is found to a relative 4 ulps also next to a pole (theta ~ 1e-12)
    root: float = brentq(lambda t: h - level.U(t), a, b, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    return root
