"""The explore page for a model without a reduction: its Poincare section."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rollingtop._types import FloatArray
from rollingtop.explore.view import ExploreState

__all__ = ["SECTION_CROSSINGS", "SECTION_TRAJECTORIES", "SectionView", "section_view"]

#: Trajectories and crossings of the page's section (small: it is redrawn on every change).
SECTION_TRAJECTORIES, SECTION_CROSSINGS = 8, 150


@dataclass(frozen=True)
class SectionView:
    """The Poincare section ``w_tau = 0`` of the reference state's level under a model without a
    reduction (:func:`section_view`): its points ``(gamma3, w_n)`` (shape ``(k, 2)``) and the
    full state at each (shape ``(k, 18)``), from which a click starts a trajectory on the same
    energy level."""

    readout: str
    points: FloatArray
    states: FloatArray


def section_view(state: ExploreState) -> SectionView:
    """:func:`rollingtop.chaos.section.poincare_section` of the reference state under
    ``state``'s model and body (:meth:`ExploreState.reference_state`):
    :data:`SECTION_TRAJECTORIES` trajectories on its level, seed 0, :data:`SECTION_CROSSINGS`
    crossings each, at most 200 time units."""
    from rollingtop.chaos.section import poincare_section

    y = state.reference_state()
    ds = poincare_section(
        state.body,
        state.model,
        y,
        crossings=SECTION_CROSSINGS,
        trajectories=SECTION_TRAJECTORIES,
        t_max=200.0,
    )
    g3 = ds["gamma3"].values.ravel()
    wn = ds["w_n"].values.ravel()
    ys = ds["crossing_state"].values.reshape(-1, ds.sizes["state"])
    ok = np.isfinite(g3) & np.isfinite(wn)
    held = ds.attrs["held"].replace(",", ", ")
    readout = (
        f"{state.model} model: no reduction; Poincare section of the level of the "
        f"scenario's state (held: {held}) | {int(ok.sum())} crossings"
    )
    return SectionView(readout, np.column_stack([g3[ok], wn[ok]]), ys[ok])
