"""Constants of the compiled section and chaos-indicator batches, shared by every model's
(:mod:`rollingtop._compiled._template.chaos`, compiled per contact model)."""

from __future__ import annotations

#: Fields of the per-trajectory statistics of the section batch
#: (:func:`rollingtop._compiled._template.chaos.section_batch`).
SECTION_STATS = ("status", "crossings", "steps", "t_last", "min_normal_force")
#: Newton corrections of a located crossing (each squares the event function's residual).
POLISH_ITERATIONS = 2
#: Time step of the central difference of the event function along the flow (exact for the
#: quadratic ``W_TAU``).
POLISH_DT = 1e-6
#: Status of a section trajectory stopped because it went ``max_gap_steps`` accepted steps
#: without a new crossing (a motion that settled, or one that never turns in ``gamma3``).
NO_CROSSING = 3
