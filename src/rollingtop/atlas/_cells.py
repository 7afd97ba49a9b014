"""The classification of the atlas's cells (:mod:`rollingtop.atlas`): pure functions, each
call one Dask task."""

from __future__ import annotations

import functools
from collections.abc import Mapping

import numpy as np

from rollingtop._errors import BodyError
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop

BODY_KEYS = ("R", "m", "g", "a3", "I1", "I3")
LEVEL_KEYS = ("M3", "C1", "C2")
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
        try:
            level = LevelSet(body, p["M3"], p["C1"], p["C2"])
        except LevelSetError:
            out["status"][n] = 3
            continue
        if level.pole is not None:
            out["status"][n] = 2
            continue
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
    return out


# ---- running it on Dask, resumably --------------------------------------------------------------
