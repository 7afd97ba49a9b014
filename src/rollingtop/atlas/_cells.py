"""The classification of the atlas's cells (:mod:`rollingtop.atlas`): pure functions, each
call one Dask task."""

from __future__ import annotations

import functools
from collections.abc import Mapping

import numpy as np

from rollingtop._errors import BodyError, RollingTopError
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.reduction.models import ATLAS_MODELS as _ATLAS_MODELS
from rollingtop.reduction.models import closed_form_diagram

BODY_KEYS = ("R", "m", "g", "a3", "I1", "I3")
LEVEL_KEYS = ("M3", "C1", "C2")
#: The models an atlas classifies (:data:`rollingtop.reduction.models.ATLAS_MODELS`, from the
#: registry): a ``model`` axis holds indices into this tuple (its coordinate in the Dataset: the
#: names).
ATLAS_MODELS = _ATLAS_MODELS
#: The initial state a cell's level is read from under each model (a ``model`` axis, or a model
#: other than the meridian one): the attitude and the angular velocity.
STATE_KEYS = ("gamma1", "gamma2", "gamma3", "omega1", "omega2", "omega3")
#: Centres whose rotation number is kept per cell.
MAX_CENTRES = 3

# ---- the classification of cells (pure functions: Dask tasks) ---------------------------------

FIELDS = ("status", "n_steady", "n_centres", "n_saddles", "n_folds")


@functools.lru_cache(maxsize=4096)
def _fold_count(*key: float) -> int:
    """Folds of the diagram of ``(body, M3, C1)`` (independent of ``C2``): cached in each worker
    process across its tasks, since neighbouring cells share them."""
    from rollingtop.reduction.bifurcation import folds

    body = SphericalTop(**dict(zip(BODY_KEYS, key[:6], strict=True)))
    return len(folds(body, key[6], key[7]))


def classify_cells(
    fixed: Mapping[str, float], names: tuple[str, ...], values: FloatArray
) -> dict[str, np.ndarray]:
    """Classify the cells ``values`` (shape (k, len(names))): one Dask task.

    Returns
    -------
    dict of str to ndarray
        ``status, n_steady, n_centres, n_saddles, n_folds``, shape (k,), int (-1 where the cell
        is not classified, see :data:`STATUS`); ``rotation_centre`` and ``centre_gamma3``,
        shape (k, :data:`MAX_CENTRES`), NaN-padded, the centres in order of ``gamma3``.
    """
    from rollingtop.reduction._critical_curves import _critical
    from rollingtop.reduction.level import LevelSet, LevelSetError
    from rollingtop.reduction.rotation import centre_rotation_number
    from rollingtop.reduction.steady import steady_motion

    k = values.shape[0]
    out = {name: np.full(k, -1, dtype=np.int16) for name in FIELDS}
    out["rotation_centre"] = np.full((k, MAX_CENTRES), np.nan)
    out["centre_gamma3"] = np.full((k, MAX_CENTRES), np.nan)
    for n in range(k):
        p = dict(fixed)
        p.update(zip(names, (float(x) for x in values[n]), strict=True))
        try:
            body = SphericalTop(**{key: p[key] for key in BODY_KEYS})
        except BodyError:
            out["status"][n] = 1
            continue
        if "gamma1" in p:  # each model's level of the initial state; a body beyond doubles
            with np.errstate(all="ignore"):  # (I1 = 1e300) is its cell's status, not warnings
                _classify_state(body, p, out, n)
            continue
        try:
            level = LevelSet(body, p["M3"], p["C1"], p["C2"])
        except LevelSetError:
            out["status"][n] = 3
            continue
        if level.pole is not None:
            out["status"][n] = 2
            continue
        try:  # a level the analysis cannot classify (degenerate, beyond doubles): its cell only
            with np.errstate(all="ignore"):
                th, _, u2 = _critical(level)
                g3 = np.cos(th)
                out["status"][n] = 0
                out["n_steady"][n] = len(g3)
                out["n_centres"][n] = int(np.sum(u2 > 0))
                out["n_saddles"][n] = int(np.sum(u2 < 0))
                out["n_folds"][n] = _fold_count(*(p[key] for key in (*BODY_KEYS, "M3", "C1")))
                centres = [t for t, c in zip(th, u2 > 0, strict=True) if c][:MAX_CENTRES]
                for c, t in enumerate(centres):
                    m = steady_motion(level, float(t))
                    out["centre_gamma3"][n, c] = m.gamma3
                    out["rotation_centre"][n, c] = centre_rotation_number(m)
        except (RollingTopError, ArithmeticError, ValueError):
            _unclassified(out, n, 3)
    return out


def _unclassified(out: dict[str, np.ndarray], n: int, status: int) -> None:
    """Cell ``n`` not classified, with its ``status``: its other fields back to -1 and NaN."""
    for name in FIELDS:
        out[name][n] = -1
    out["status"][n] = status
    out["rotation_centre"][n] = np.nan
    out["centre_gamma3"][n] = np.nan


# ---- running it on Dask, resumably --------------------------------------------------------------


def _classify_state(
    body: SphericalTop, p: Mapping[str, float], out: dict[str, np.ndarray], n: int
) -> None:
    """Cell ``n`` of a spec with an initial state: the level of the state ``p[STATE_KEYS]``
    under the model ``ATLAS_MODELS[p["model"]]`` (as ``rollingtop compare-classification``
    builds it: the centre of mass's velocity from the model's constraints, ``omega``'s part
    along a constraint on the angular velocity dropped), classified by the model's own
    reduction. ``n_folds`` is the meridian model's alone (-1 for the others)."""
    from rollingtop.dynamics.state import initial_state
    from rollingtop.reduction.classify import admissible_omega
    from rollingtop.reduction.level import LevelSetError, PoleLevelError
    from rollingtop.reduction.models import reduction_of
    from rollingtop.reduction.rotation import centre_rotation_number
    from rollingtop.reduction.steady import steady_motions

    name = ATLAS_MODELS[int(p["model"])]
    gamma = np.array([p[key] for key in STATE_KEYS[:3]])
    omega, _ = admissible_omega(name, gamma, [p[key] for key in STATE_KEYS[3:]])
    try:
        y = initial_state(body, name, gamma=gamma, omega=omega)
        level = reduction_of(name).level_of_state(body, y)
    except PoleLevelError:
        out["status"][n] = 2
        return
    except LevelSetError:
        out["status"][n] = 3
        return
    except RollingTopError:
        out["status"][n] = 4
        return
    if level.pole is not None:
        out["status"][n] = 2
        return
    try:  # a level the analysis cannot classify (a flat U, beyond doubles): its cell only
        with np.errstate(all="ignore"):
            motions = steady_motions(level)
            out["status"][n] = 0
            out["n_steady"][n] = len(motions)
            out["n_centres"][n] = sum(m.type == "center" for m in motions)
            out["n_saddles"][n] = sum(m.type == "saddle" for m in motions)

            if closed_form_diagram(name):  # the paper's whole reduction: its fold curves
                out["n_folds"][n] = _fold_count(
                    *(float(getattr(body, key)) for key in BODY_KEYS),
                    level.values()["M3"],
                    level.values()["C1"],
                )
            centres = [m for m in motions if m.type == "center"][:MAX_CENTRES]
            for c, m in enumerate(centres):
                out["centre_gamma3"][n, c] = m.gamma3
                out["rotation_centre"][n, c] = centre_rotation_number(m)
    except (RollingTopError, ArithmeticError, ValueError):
        _unclassified(out, n, 3)
