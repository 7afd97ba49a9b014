"""Maps of the chaos indicators over many initial states: in parallel on all cores, or on a
Dask cluster (``client=``, as :func:`rollingtop.simulate_ensemble` and the atlas use it)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._compiled import by_package, compiling
from rollingtop._compiled._tangent import STATUS_NAMES
from rollingtop._errors import ScenarioError
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray, IntArray
from rollingtop.body import SphericalTop
from rollingtop.chaos.lyapunov import check_options, check_state, initial_tangent, vertical_stop
from rollingtop.contact import ContactModel, get_model
from rollingtop.integrate._threads import run_rows

if TYPE_CHECKING:
    import xarray as xr
    from distributed import Client

__all__ = ["indicator_map"]

#: Chunks of states per worker thread on a Dask cluster.
CLIENT_CHUNKS = 4


def _chunk(
    codes: IntArray,
    params: FloatArray,
    states: FloatArray,
    tangents: FloatArray,
    t: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    s_stop: float,
    threads: int | None,
) -> tuple[FloatArray, FloatArray]:
    """One batch (a Dask task, or the whole map in-process): outputs ``(out, stats)``."""
    out = np.full((len(states), t.size, 3), np.nan)
    stats = np.zeros((len(states), 4))
    # package by package: the model's own kernel, its variants (pole levels) in theirs
    for kernels, idx in by_package(codes):
        part = out[idx], stats[idx]  # copies the kernel fills
        with compiling(kernels, "chaos"):
            run_rows(
                kernels.chaos.indicator_batch,
                (
                    codes[idx],
                    params,
                    states[idx],
                    tangents[idx],
                    t,
                    rtol,
                    atol,
                    max_steps,
                    *part,
                    s_stop,
                ),
                (0, 2, 3, 8, 9),
                idx.size,
                threads=threads,
            )
        out[idx], stats[idx] = part
    return out, stats


def _on_client(client: Client, args: tuple[Any, ...]) -> tuple[FloatArray, FloatArray]:
    codes, params, states, tangents, *rest = args
    slots = max(1, sum(client.nthreads().values()))
    N = len(states)
    bounds = np.linspace(0, N, min(N, CLIENT_CHUNKS * slots) + 1).astype(int)
    futures = [
        client.submit(_chunk, codes[a:b], params, states[a:b], tangents[a:b], *rest, 1, pure=False)
        for a, b in zip(bounds[:-1], bounds[1:], strict=True)
    ]
    parts = client.gather(futures)
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def indicator_map(
    body: SphericalTop,
    model: str | ContactModel,
    states: ArrayLike,
    *,
    t_end: float,
    samples: int = 1,
    rtol: float = 1e-10,
    atol: float | None = None,
    max_steps: int = 10**8,
    threads: int | None = None,
    client: Client | None = None,
) -> xr.Dataset:
    """The chaos indicators (:func:`rollingtop.chaos.chaos_indicators`) of many initial states.

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
    states : array_like, shape (N, 18)
        Constraint-consistent initial states (e.g. :func:`rollingtop.initial_state` over a grid
        of initial conditions, or :func:`rollingtop.chaos.level_states`).
    t_end : float
    samples : int
        Sample times per state (default 1: the final values only).
    rtol, atol, max_steps
        As for :func:`~rollingtop.chaos.chaos_indicators`.
    threads : int, optional
        Threads in-process (default: all cores).
    client : distributed.Client, optional
        Run on this Dask cluster instead, in chunks of states (one thread each).

    Returns
    -------
    xarray.Dataset
        ``lyapunov``, ``megno`` (the running mean ``<Y>``) and ``megno_instantaneous``
        (``Y``) of shape (N, samples) over dimensions ``point`` and ``t``, ``status`` (N,)
        (0: reached ``t_end``; else the stepper's code, NaN indicators after the failure),
        ``steps`` (N,), ``initial_state`` (N, 18).
    """
    import xarray as xr

    model = get_model(model)
    atol = check_options(t_end, samples, rtol, atol)
    Y = np.array(states, dtype=float)
    if Y.ndim != 2 or Y.shape[1] != N_STATE or Y.shape[0] == 0:
        raise ScenarioError(f"states must have shape (N, {N_STATE}), got {Y.shape}")
    Y = np.array([check_state(body, model, y) for y in Y])
    codes = np.array([model.kernel_code(body, y) for y in Y], dtype=np.int64)
    tangents = np.repeat(initial_tangent()[None, :], len(Y), axis=0)
    t = np.linspace(0.0, float(t_end), int(samples) + 1)[1:]
    args = (
        codes,
        model.params(body),
        Y,
        tangents,
        t,
        float(rtol),
        atol,
        int(max_steps),
        vertical_stop(model),
    )
    if client is not None:
        out, stats = _on_client(client, args)
    else:
        out, stats = _chunk(*args, threads)
    data = {
        "lyapunov": (("point", "t"), out[:, :, 0]),
        "megno": (("point", "t"), out[:, :, 2]),
        "megno_instantaneous": (("point", "t"), out[:, :, 1]),
        "status": ("point", stats[:, 0].astype(np.int32)),
        "steps": ("point", stats[:, 1].astype(np.int64)),
        "initial_state": (("point", "state"), Y),
    }
    attrs: dict[str, Any] = {f"body_{k}": v for k, v in body.to_dict().items()}
    attrs.update(
        model=model.name,
        rtol=float(rtol),
        atol=atol,
        status_names=str({int(k): v for k, v in STATUS_NAMES.items()}),
    )
    return xr.Dataset(data, coords={"point": np.arange(len(Y)), "t": t}, attrs=attrs)
