"""The pace guard of the validated driver (:func:`rollingtop.integrate.integrate`): a run whose
steps are far too short for its length ends in one line instead of running to ``max_steps``."""

from __future__ import annotations

import math

from rollingtop._errors import IntegrationError

__all__ = ["check_pace"]

#: A run stops early when, after at least :data:`PACE_AFTER` steps, its pace so far would need
#: more than :data:`PACE_FACTOR` times ``max_steps`` to reach ``t_end`` (issue 27: a shell of
#: 1e50 took steps of 1e-17; ``max_steps`` alone bounded it by minutes, not seconds).
PACE_AFTER = 40_000
PACE_FACTOR = 100


def check_pace(t0: float, t: float, t_end: float, steps: int, max_steps: int) -> None:
    """:class:`IntegrationError` (one line) when the pace of ``steps`` steps from ``t0`` to
    ``t`` would need more than :data:`PACE_FACTOR` times ``max_steps`` to reach ``t_end``."""
    if steps < PACE_AFTER:
        return
    done = t - t0
    needed = math.inf if not done > 0.0 else (t_end - t0) / done * steps
    if needed > PACE_FACTOR * max_steps:
        raise IntegrationError(
            f"at this pace (t = {t:.3g} after {steps} steps) t_end = {t_end:g} needs about "
            f"{needed:.2g} steps, more than {PACE_FACTOR} times max_steps = {max_steps}: the "
            "motion's time scale is too short for its length (rescale the scenario, shorten "
            "t_end or raise max_steps)"
        )
