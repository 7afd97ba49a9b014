"""The atlas's chaos cells (issue 39, item 3): for a model without a reduction (the ``oblique``
family over its angle, ``parallel``), each cell's chaos indicators, phase-volume rate and
periodic orbits on the level of the spec's initial state. Pure functions, each call one Dask
task, as :mod:`._cells`' classification.

Per cell, under the cell's body and angle:

- ``n_seeds`` states on the level of the initial state (:func:`rollingtop.chaos.level_states`:
  the state itself first) and, for each, MEGNO and the largest Lyapunov exponent over
  ``t_end`` (:func:`rollingtop.chaos.chaos_indicators`). A motion that reaches the vertical
  has no tangent dynamics beyond it (the constraint's direction is not determined there) and
  is counted in ``n_vertical`` instead; so is one whose steps run out (the regularised passage
  is stiff: ``MAX_STEPS`` bounds each run); any other failure in ``n_failed``. ``megno`` is the
  median over the seeds that finished, ``lyapunov`` their largest exponent (NaN when none
  finished);
- ``volume_rate``: the time average of the divergence along the initial state's motion
  (:func:`rollingtop.chaos.phase_volume`), the rate of phase-volume drift (zero on average for
  a model with an invariant measure); NaN where that motion reaches the vertical before
  ``t_end`` (the rate there would be the regularised passage's);
- ``n_periodic``, ``n_attracting``: the relative periodic orbits that the section's
  trajectories settle onto (:func:`rollingtop.chaos.periodic_orbits`, up to
  ``PERIODIC_RETURNS`` crossings, no grid of seeds), and how many of them attract.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from rollingtop._errors import BodyError, IntegrationError, RollingTopError
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop

__all__ = [
    "CHAOS_FIELDS",
    "CHAOS_MODELS",
    "CHAOS_DOCS",
    "DEFAULT_SEEDS",
    "DEFAULT_T_END",
    "chaos_cells",
]

#: The models a chaos atlas runs (its ``fixed["model"]`` indexes this tuple).
CHAOS_MODELS = ("oblique", "parallel")
#: A cell's variables: name -> dtype kind (``i`` int16, ``f`` float64).
CHAOS_FIELDS = {
    "status": "i",
    "megno": "f",
    "lyapunov": "f",
    "n_finished": "i",
    "n_vertical": "i",
    "n_failed": "i",
    "volume_rate": "f",
    "n_periodic": "i",
    "n_attracting": "i",
}
CHAOS_DOCS = {
    "status": "0 computed, 1 inadmissible body, 4 state refused by the model",
    "megno": "median MEGNO over the seeds that finished t_end (2: regular; growing: chaotic)",
    "lyapunov": "largest finite-time Lyapunov exponent over the seeds that finished",
    "n_finished": "seeds whose tangent dynamics ran to t_end",
    "n_vertical": "seeds whose motion reached the vertical (or ran out of steps near it)",
    "n_failed": "seeds whose integration failed otherwise (step size, a non-finite state)",
    "volume_rate": "time average of the divergence along the initial state's motion, where "
    "that motion stays away from the vertical up to t_end (else NaN)",
    "n_periodic": "periodic orbits the section's trajectories settle onto",
    "n_attracting": "attracting periodic orbits among them",
}
#: Defaults of the spec's ``[chaos]`` table.
DEFAULT_T_END = 100.0
DEFAULT_SEEDS = 3
#: Bound on accepted steps of each run (a motion creeping along the regularised vertical).
MAX_STEPS = 200_000
#: Crossings per period sought, and the search's trajectories and settling crossings.
PERIODIC_RETURNS = 3
PERIODIC_TRAJECTORIES = 8
PERIODIC_SETTLE = 150


def free_key(name: str) -> str:
    """The model's one free velocity component (its ``[initial]`` key: ``v_slip``, ``v_nu``),
    whose value a chaos atlas keeps in ``fixed["free"]``."""
    from rollingtop.contact import get_model

    (key,) = get_model(name).free_velocity
    return str(key)


def has_angle(name: str) -> bool:
    """Whether the model has the parameter ``angle`` (the oblique family)."""
    from rollingtop.contact import get_model

    return any(r.name == "angle" for r in get_model(name).parameters)


def _near_vertical(message: str) -> bool:
    """Whether an integration stopped at the vertical (``chaos_indicators``' stop) or ran out
    of steps (a motion crawling through the regularised passage, the one place these models
    do), from its one-line message."""
    return "reaches the vertical" in message or "max_steps" in message


def cell_model(p: Mapping[str, float]) -> object:
    """The cell's contact model: ``CHAOS_MODELS[p["model"]]`` with the cell's ``angle``."""
    from rollingtop.contact import get_model

    model = get_model(CHAOS_MODELS[int(p["model"])])
    if "angle" in p and has_angle(model.name):
        model = model.with_parameters(angle=float(p["angle"]))
    return model


def chaos_cells(
    fixed: Mapping[str, float], names: tuple[str, ...], values: FloatArray
) -> dict[str, np.ndarray]:
    """The chaos outputs of the cells ``values`` (shape (k, len(names))): one Dask task.

    Returns
    -------
    dict of str to ndarray
        :data:`CHAOS_FIELDS`, each shape (k,): int16 (-1 where not computed) or float64 (NaN).
    """
    from rollingtop.atlas._cells import BODY_KEYS, STATE_KEYS
    from rollingtop.dynamics.state import initial_state

    k = values.shape[0]
    out = {
        name: np.full(k, -1, dtype=np.int16) if kind == "i" else np.full(k, np.nan)
        for name, kind in CHAOS_FIELDS.items()
    }
    for n in range(k):
        p = dict(fixed)
        p.update(zip(names, (float(x) for x in values[n]), strict=True))
        try:
            body = SphericalTop(**{key: p[key] for key in BODY_KEYS})
        except BodyError:
            out["status"][n] = 1
            continue
        model = cell_model(p)
        try:
            y0 = initial_state(
                body,
                model,  # type: ignore[arg-type]
                gamma=[p[key] for key in STATE_KEYS[:3]],
                omega=[p[key] for key in STATE_KEYS[3:]],
                free={free_key(model.name): p["free"]},  # type: ignore[attr-defined]
            )
        except RollingTopError:
            out["status"][n] = 4
            continue
        with np.errstate(all="ignore"):
            _cell(body, model, y0, p, out, n)
    return out


def _cell(
    body: SphericalTop,
    model: object,
    y0: FloatArray,
    p: Mapping[str, float],
    out: dict[str, np.ndarray],
    n: int,
) -> None:
    from rollingtop.chaos.divergence import phase_volume
    from rollingtop.chaos.level import level_states
    from rollingtop.chaos.lyapunov import chaos_indicators
    from rollingtop.chaos.periodic import periodic_orbits

    t_end, n_seeds = float(p["t_end"]), int(p["seeds"])
    out["status"][n] = 0
    try:
        seeds = level_states(body, model, y0, n_seeds, seed=0)  # type: ignore[arg-type]
    except (RollingTopError, IntegrationError):
        seeds = np.asarray([y0])
    megno, lyap, vertical, failed = [], [], 0, 0
    followed = False  # whether the initial state's own motion (seeds[0]) ran to t_end
    for k, y in enumerate(seeds):
        try:
            s = chaos_indicators(
                body,
                model,  # type: ignore[arg-type]
                y,
                t_end=t_end,
                samples=100,
                max_steps=MAX_STEPS,
            ).summary()
        except IntegrationError as exc:
            if _near_vertical(str(exc)):
                vertical += 1
            else:
                failed += 1
            continue
        followed = followed or k == 0
        megno.append(float(s["megno"]))
        lyap.append(float(s["lyapunov"]))
    out["n_finished"][n] = len(megno)
    out["n_vertical"][n] = vertical
    out["n_failed"][n] = failed
    if megno:
        out["megno"][n] = float(np.median(megno))
        out["lyapunov"][n] = float(np.max(lyap))
    # the rate through the vertical would be the regularised passage's, not the motion's
    try:
        if not followed:
            raise IntegrationError("the initial state's motion reaches the vertical")
        pv = phase_volume(
            body,
            model,  # type: ignore[arg-type]
            y0,
            t_end=t_end,
            samples=2001,
            max_steps=MAX_STEPS,
        )
        out["volume_rate"][n] = float(pv.mean[-1])
    except (RollingTopError, IntegrationError):  # out of steps near the vertical: NaN
        pass
    try:
        found = periodic_orbits(
            body,
            model,  # type: ignore[arg-type]
            y0,
            returns=PERIODIC_RETURNS,
            trajectories=PERIODIC_TRAJECTORIES,
            settle=PERIODIC_SETTLE,
            grid=0,
        )
    except (RollingTopError, IntegrationError):
        return
    out["n_periodic"][n] = len(found)
    out["n_attracting"][n] = sum(o.type == "attracting" for o in found)
