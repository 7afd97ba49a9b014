"""Basins of attraction on a level's Poincare section (issue 38, item 4), computed on Dask.

On a grid of the section plane ``(gamma3, w_n)`` of a level (:mod:`rollingtop.chaos.periodic`'s
grid, over the range of the section's own trajectories), each grid point is a start on the level
(:func:`rollingtop.chaos._section_map.on_level`: one of the at most two states of the level there,
``sheet`` 0 or 1). Each start runs ``crossings`` crossings of the section; its **label** is the
attracting orbit (:func:`rollingtop.chaos.periodic_orbits`) with the crossing nearest to its last
crossing, if within :data:`ATTRACTED`, ``-1`` where none (still wandering, or an attractor the
search did not find), ``-2`` where the trajectory stopped before its crossings (a steady motion, a
motion that turns no more), ``-3`` where the grid point is not on the level (that sheet has no state
there).

The starts are integrated in chunks on a Dask cluster, as the atlas's cells are
(:func:`rollingtop.atlas.atlas`: an embedded local cluster of worker processes by default, a
scheduler's address to go wide); each chunk runs the compiled section in parallel threads.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._checks import short_repr
from rollingtop._errors import ScenarioError
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos._section_map import SectionMap, grid_axes, on_level, section_coordinates
from rollingtop.chaos.level import held_integrals, level_values
from rollingtop.chaos.periodic import PeriodicOrbits, periodic_orbits
from rollingtop.contact import ContactModel, get_model

if TYPE_CHECKING:
    import xarray as xr
    from distributed import Client

__all__ = ["ATTRACTED", "LABELS", "basin_map"]

#: A start is attracted by an orbit when its last crossing is this close (max norm of the
#: section coordinates) to one of the orbit's crossings.
ATTRACTED = 1e-3
#: The labels that are not an attractor's index.
LABELS = {-1: "none", -2: "stopped", -3: "not on the level"}
#: Starts per Dask task.
CHUNK = 32
#: Worker processes of the local cluster per core, at most (as the atlas's).
MAX_WORKERS_PER_CORE = 4


def _settle(
    body: SphericalTop, model: ContactModel, X: FloatArray, crossings: int, rtol: float
) -> tuple[FloatArray, FloatArray]:
    """The last crossing's section coordinates of each start ``X`` (n, 4) after ``crossings``
    crossings (NaN where it stopped before) and the number found: a Dask task. ``model`` is the
    instance (pickled with its own parameters: by name a worker would run the registered
    rule)."""
    from rollingtop.chaos.section import poincare_section

    P = SectionMap(body, model, held_integrals(body, model, None), rtol)
    ds = poincare_section(
        body,
        model,
        P.states(X),
        crossings=crossings,
        rtol=rtol,
        atol=rtol * 1e-2,
        max_gap_steps=20_000,
        threads=1,  # one Dask worker process per core: its own threads would oversubscribe
    )
    found = ds["n_crossings"].values
    last = ds["crossing_state"].values[:, -1]
    return section_coordinates(model, last), found.astype(float)


def basin_map(
    body: SphericalTop,
    model: str | ContactModel,
    state: ArrayLike,
    *,
    found: PeriodicOrbits | None = None,
    grid: int = 24,
    crossings: int = 200,
    sheet: int = 0,
    trajectories: int = 16,
    settle: int = 300,
    rtol: float = 1e-10,
    client: Client | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> xr.Dataset:
    """Which attracting orbit each start of a grid on the level's section reaches.

    Parameters
    ----------
    body, model, state :
        The level: ``state``'s energy and the model's other integrals (a level of two
        integrals, the ``parallel`` model's).
    found : PeriodicOrbits, optional
        The level's orbits (default: :func:`rollingtop.chaos.periodic_orbits` of ``state`` with
        ``trajectories`` and ``settle``: the attracting orbits are those the section's
        trajectories settle onto, so no grid of seeds).
    grid : int
        Grid points per axis of the section plane.
    crossings : int
        Crossings each start runs before it is labelled.
    sheet : int
        Which state of the level at a grid point, in order of the free velocity component ``u``
        (:func:`rollingtop.chaos._section_map.on_level`): 0 or 1.
    rtol : float
        Tolerance of the integrations.
    client, workers, scheduler :
        The Dask cluster, as for :func:`rollingtop.atlas.atlas`.
    progress : callable, optional
        ``progress(done_starts, total_starts)``.

    Returns
    -------
    xarray.Dataset
        ``label`` (``gamma3``, ``w_n``): an attractor's index in ``attractors`` or a code of
        :data:`LABELS`; ``last_gamma3``, ``last_w_n`` (each start's last crossing). Attributes:
        ``model``, the level's integrals, ``attractors`` (JSON: each attracting orbit's
        ``returns``, ``period`` and crossings), ``crossings``, ``sheet``.
    """
    import xarray as xr

    from rollingtop.atlas._run import _client

    model = get_model(model)
    for name, value, lo, hi in (("grid", grid, 2, 400), ("crossings", crossings, 1, 10**6)):
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ScenarioError(f"{name} = {short_repr(value)} must be an integer in [{lo}, {hi}]")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise ScenarioError(f"workers = {short_repr(workers)} must be an integer >= 1")
    cores = os.cpu_count() or 1
    if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
        raise ScenarioError(
            f"workers = {workers} is more than {MAX_WORKERS_PER_CORE} per core ({cores} cores) "
            "for the local cluster; use a scheduler to go wide"
        )
    if isinstance(sheet, bool) or not isinstance(sheet, int) or sheet not in (0, 1):
        raise ScenarioError(f"sheet = {short_repr(sheet)} must be 0 or 1")
    y0 = np.asarray(state, dtype=float)
    names = held_integrals(body, model, None)
    if len(names) != 2 or "energy" not in names:
        raise ScenarioError(
            f"basins need a level of the energy and one more integral (the {model.name} model "
            f"holds {', '.join(names)} for this body)"
        )
    if found is None:
        found = periodic_orbits(body, model, y0, trajectories=trajectories, settle=settle, grid=0)
    target = level_values(body, model, y0, names)
    P = SectionMap(body, model, names, rtol)
    axes = grid_axes(found.iterates, grid)
    if axes is None:
        raise ScenarioError("the level's section has no crossings to take the grid's range from")
    g3s, wns = axes
    label = np.full((grid, grid), -3, dtype=np.int64)
    cells, X = [], []
    for i, g3 in enumerate(g3s):
        for j, w_n in enumerate(wns):
            roots = on_level(P, target, float(g3), float(w_n))
            if len(roots) > sheet:
                cells.append((i, j))
                X.append(roots[sheet])
    last = np.full((grid, grid, 4), np.nan)
    attractors = [o for o in found if o.type == "attracting"]
    if X:
        Xa = np.array(X)
        chunks = [Xa[k : k + CHUNK] for k in range(0, len(Xa), CHUNK)]
        results: dict[int, tuple[FloatArray, FloatArray]] = {}
        with _client(client, workers, scheduler, 10.0) as c:
            futures = {
                c.submit(_settle, body, model, part, crossings, rtol, pure=False): k
                for k, part in enumerate(chunks)
            }
            from distributed import as_completed

            done = 0
            try:
                for fut in as_completed(futures):
                    k = futures[fut]
                    try:
                        results[k] = fut.result()
                    except Exception as exc:  # a lost worker, an error on a worker
                        why = str(exc).splitlines()[0] if str(exc) else ""
                        raise ScenarioError(
                            f"a Dask task failed ({type(exc).__name__}: {why})"
                        ) from None
                    done += len(chunks[k])
                    if progress is not None:
                        progress(done, len(Xa))
            except BaseException:
                c.cancel(list(futures))  # nothing left queued on a cluster that stays
                raise
        ends = np.concatenate([results[k][0] for k in range(len(chunks))])
        counts = np.concatenate([results[k][1] for k in range(len(chunks))])
        for (i, j), end, n in zip(cells, ends, counts, strict=True):
            last[i, j] = end
            label[i, j] = _label(end, int(n), crossings, attractors)
    data = {
        "label": (("gamma3", "w_n"), label),
        "last_gamma3": (("gamma3", "w_n"), last[..., 0]),
        "last_w_n": (("gamma3", "w_n"), last[..., 1]),
    }
    attrs: dict[str, Any] = {f"level_{k}": v for k, v in found.level.items()}
    attrs.update(
        model=model.name,
        crossings=crossings,
        sheet=sheet,
        rtol=rtol,
        labels=json.dumps({str(k): v for k, v in LABELS.items()}),
        attractors=json.dumps(
            [
                {"returns": o.returns, "period": o.period, "points": o.points[:, :2].tolist()}
                for o in attractors
            ]
        ),
        source="rollingtop basins",
    )
    return xr.Dataset(data, coords={"gamma3": g3s, "w_n": wns}, attrs=attrs)


def _label(end: FloatArray, n: int, crossings: int, attractors: list[Any]) -> int:
    if n < crossings or not np.all(np.isfinite(end)):
        return -2
    if not attractors:
        return -1
    gaps = [float(np.min(np.max(np.abs(o.points - end), axis=-1))) for o in attractors]
    k = int(np.argmin(gaps))  # the nearest: two attractors may lie closer than ATTRACTED
    return k if gaps[k] < ATTRACTED else -1
