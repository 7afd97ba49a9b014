"""The explore page for a model without a reduction: its Poincare section, with the relative
periodic orbits that its trajectories settle onto marked (:func:`rollingtop.chaos.periodic_orbits`).

The plane is the section coordinates' ``(gamma3, w_n)`` in the geometric basis of the axis's
horizontal projection (:func:`rollingtop.chaos._section_map.section_coordinates`, the plane of
``rollingtop periodic``'s figure), where the model has one; else the section's own."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rollingtop._types import FloatArray
from rollingtop.explore.view import ExploreState

__all__ = [
    "ORBIT_RETURNS",
    "SECTION_CROSSINGS",
    "SECTION_TRAJECTORIES",
    "SectionView",
    "section_view",
]

#: Trajectories and crossings of the page's section (small: it is redrawn on every change).
SECTION_TRAJECTORIES, SECTION_CROSSINGS = 8, 150
#: The orbits marked: fixed points of the section's map after 1 to this many crossings.
ORBIT_RETURNS = 4


@dataclass(frozen=True)
class SectionView:
    """The Poincare section ``w_tau = 0`` of the reference state's level under a model without a
    reduction (:func:`section_view`): its points ``(gamma3, w_n)`` (shape ``(k, 2)``) and the
    full state at each (shape ``(k, 18)``), from which a click starts a trajectory on the same
    energy level; and the periodic orbits its trajectories settle onto, each ``(returns, type,
    points)`` with ``points`` of shape ``(returns, 2)``."""

    readout: str
    points: FloatArray
    states: FloatArray
    orbits: tuple[tuple[int, str, FloatArray], ...] = ()


def section_view(state: ExploreState) -> SectionView:
    """:func:`rollingtop.chaos.section.poincare_section` of the reference state under
    ``state``'s model and body (:meth:`ExploreState.reference_state`):
    :data:`SECTION_TRAJECTORIES` trajectories on its level, seed 0, :data:`SECTION_CROSSINGS`
    crossings each, at most 200 time units."""
    from rollingtop.chaos.section import poincare_section

    y = state.reference_state()
    ds = poincare_section(
        state.body,
        state.contact_model,
        y,
        crossings=SECTION_CROSSINGS,
        trajectories=SECTION_TRAJECTORIES,
        t_max=200.0,
    )
    ys = ds["crossing_state"].values.reshape(-1, ds.sizes["state"])
    orbits = _orbits(state, y)
    if orbits is None:  # no section coordinates for this model: the section's own plane
        g3, wn = ds["gamma3"].values.ravel(), ds["w_n"].values.ravel()
    else:
        from rollingtop.chaos._section_map import section_coordinates

        x = section_coordinates(state.contact_model, ys)
        g3, wn = x[:, 0], x[:, 1]
    ok = np.isfinite(g3) & np.isfinite(wn)
    held = ds.attrs["held"].replace(",", ", ")
    angle = "".join(f", {k} = {v:.6g}" for k, v in state.contact)
    readout = (
        f"{state.model} model{angle}: no reduction; Poincare section of the level of the "
        f"scenario's state (held: {held}) | {int(ok.sum())} crossings"
    )
    if orbits:
        named = ", ".join(f"{k} {'return' if k == 1 else 'returns'} {t}" for k, t, _ in orbits)
        readout += f" | periodic orbits: {named}"
    return SectionView(readout, np.column_stack([g3[ok], wn[ok]]), ys[ok], tuple(orbits or ()))


def _orbits(state: ExploreState, y: FloatArray) -> list[tuple[int, str, FloatArray]] | None:
    """The periodic orbits that the section's trajectories settle onto: as many trajectories and
    crossings as the page's section, though without its time limit (so not the very runs
    shown), and no grid of seeds; ``None`` for a model the search does not take. Computed
    with the view (about 3 s more on 2 cores for ``examples/parallel.toml``)."""
    from rollingtop._errors import RollingTopError
    from rollingtop.chaos.periodic import periodic_orbits

    try:
        found = periodic_orbits(
            state.body,
            state.contact_model,
            y,
            returns=ORBIT_RETURNS,
            trajectories=SECTION_TRAJECTORIES,
            settle=SECTION_CROSSINGS,
            grid=0,
        )
    except RollingTopError:
        return None
    return [(o.returns, o.type, o.points[:, :2]) for o in found]
