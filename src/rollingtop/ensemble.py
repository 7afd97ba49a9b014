"""Ensembles of initial states (and optionally bodies): :func:`simulate_ensemble`."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._compiled import by_package
from rollingtop._compiled._dop853 import STATUS_NAMES
from rollingtop._errors import ScenarioError
from rollingtop._layout import N_STATE, state_components
from rollingtop._output import NetCDFOutput
from rollingtop._types import FloatArray, IntArray
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, get_model, kernel_by_code
from rollingtop.dynamics.integrals import evaluate
from rollingtop.ensemble_tables import (
    MAX_TABLE_BYTES,
    Columns,
    check_ensemble_memory,
    grid_table,
    read_table,
    states_from_table,
)
from rollingtop.integrate._threads import thread_count
from rollingtop.integrate.ensemble import compile_ensemble_code, integrate_batch
from rollingtop.scenario import (
    Scenario,
    short_repr,
)

if TYPE_CHECKING:
    import xarray as xr
    from distributed import Client

__all__ = [
    "MAX_TABLE_BYTES",
    "EnsembleResult",
    "check_ensemble_memory",
    "ensemble_from_scenario",
    "grid_table",
    "read_table",
    "simulate_ensemble",
    "states_from_table",
]

#: Per-trajectory status codes and their names (the compiled stepper's, :mod:`._dop853`).
STATUS = dict(STATUS_NAMES)


@dataclass
class EnsembleResult(NetCDFOutput):
    """Per-trajectory results of an ensemble.

    Attributes
    ----------
    model : ContactModel
    bodies : list of SphericalTop
        One per trajectory (the same object repeated for a single body).
    initial, final : ndarray, shape (N, 18)
    t_end : float
    status : ndarray of int, shape (N,)
        0 when the trajectory reached ``t_end`` (see :data:`STATUS`).
    steps, rejected_steps, rhs_evals : ndarray of int, shape (N,)
    min_normal_force, max_friction_ratio : ndarray, shape (N,)
        Monitored at every accepted step.
    integrals : dict of str to dict
        ``{name: {"initial": (N,), "final": (N,), "drift": (N,)}}`` for the integrals the model
        and bodies share; ``drift = final - initial``.
    samples : ndarray, shape (N, n, 18), or None
        Only when asked for (``samples=n``), with times ``t``.
    wall_time_s, compile_time_s : float
    threads : int
    """

    model: ContactModel
    bodies: list[SphericalTop]
    initial: FloatArray
    final: FloatArray
    t_end: float
    status: IntArray
    steps: IntArray
    rejected_steps: IntArray
    rhs_evals: IntArray
    min_normal_force: FloatArray
    max_friction_ratio: FloatArray
    integrals: dict[str, dict[str, FloatArray]]
    wall_time_s: float
    compile_time_s: float
    threads: int
    t: FloatArray | None = None
    samples: FloatArray | None = None
    columns: Columns = field(default_factory=dict)

    @property
    def n(self) -> int:
        n: int = self.initial.shape[0]
        return n

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary (the output of ``rollingtop ensemble --json``).

        ``max_abs_drift`` is the largest ``|final - initial|`` of each integral over the
        trajectories that finished; ``max_rel_drift`` the same divided by the largest
        ``|initial|`` over the ensemble.
        """
        worst: dict[str, float | None] = {}
        worst_abs: dict[str, float | None] = {}
        ok = self.status == 0
        for name, d in self.integrals.items():
            if not ok.any():
                worst[name] = worst_abs[name] = None
                continue
            # relative to the ensemble's largest |initial value| (an integral that starts at 0 in
            # some trajectory has no relative drift of its own); None if all start at 0
            size = float(np.max(np.abs(d["initial"][ok])))
            drift = float(np.max(np.abs(d["drift"][ok])))
            worst[name] = drift / size if size > 0 else None
            worst_abs[name] = float(np.max(np.abs(d["drift"][ok])))
        failed = int(np.sum(self.status != 0))
        return {
            "model": self.model.name,
            "n": self.n,
            "t_end": self.t_end,
            "threads": self.threads,
            "failed": failed,
            "status_counts": {
                STATUS.get(int(k), str(int(k))): int(v)
                for k, v in zip(*np.unique(self.status, return_counts=True), strict=True)
            },
            "wall_time_s": self.wall_time_s,
            "compile_time_s": self.compile_time_s,
            "trajectories_per_second": self.n / self.wall_time_s if self.wall_time_s else None,
            "steps_total": int(np.sum(self.steps)),
            "max_rel_drift": worst,
            "max_abs_drift": worst_abs,
            "min_normal_force": float(np.min(self.min_normal_force)),
            "contact_lost": int(np.sum(self.min_normal_force < 0)),
        }

    def to_xarray(self) -> xr.Dataset:
        """Per-trajectory results as an :class:`xarray.Dataset` (samples included if kept)."""
        import xarray as xr

        comp = state_components(self.model.slot_name)
        data: dict[str, tuple[str | tuple[str, ...], NDArray[Any]]] = {
            "initial_state": (("trajectory", "state"), self.initial),
            "final_state": (("trajectory", "state"), self.final),
            "status": ("trajectory", self.status.astype(np.int32)),
            "steps": ("trajectory", self.steps.astype(np.int64)),
            "rejected_steps": ("trajectory", self.rejected_steps.astype(np.int64)),
            "rhs_evals": ("trajectory", self.rhs_evals.astype(np.int64)),
            "min_normal_force": ("trajectory", self.min_normal_force),
            "max_friction_ratio": ("trajectory", self.max_friction_ratio),
        }
        for name, d in self.integrals.items():
            for key, values in d.items():
                data[f"{name}_{key}"] = ("trajectory", values)
        for name, column in self.columns.items():
            data[f"input_{name}"] = ("trajectory", np.asarray(column, dtype=float))
        coords: dict[str, NDArray[Any] | list[str]] = {
            "trajectory": np.arange(self.n),
            "state": comp,
        }
        if self.samples is not None and self.t is not None:  # kept together
            data["samples"] = (("trajectory", "t", "state"), self.samples)
            coords["t"] = self.t
        b = self.bodies[0]
        attrs: dict[str, str | float] = {f"body_{k}": v for k, v in b.to_dict().items()}
        attrs.update(
            model=self.model.name,
            t_end=self.t_end,
            summary_json=json.dumps(self.summary()),
            source="rollingtop ensemble",
            single_body=int(all(x == b for x in self.bodies)),
        )
        return xr.Dataset(data, coords=coords, attrs=attrs)


def simulate_ensemble(
    body: SphericalTop | Sequence[SphericalTop],
    model: str | ContactModel,
    states: FloatArray | Sequence[Sequence[float]],
    *,
    t_end: float,
    rtol: float = 1e-10,
    atol: float | None = None,
    samples: int | None = None,
    max_steps: int = 10**7,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    client: Client | None = None,
) -> EnsembleResult:
    """Integrate ``N`` initial states in parallel on all cores, or on a Dask cluster.

    Parameters
    ----------
    body : SphericalTop or sequence of N
        One body for all, or one per trajectory.
    model : str or ContactModel
    states : array_like, shape (N, 18)
        Constraint-consistent initial states (:func:`rollingtop.initial_state`, or
        :func:`states_from_table`).
    t_end : float
        Integration time (each trajectory starts at 0).
    rtol, atol : float
        Tolerances (``atol`` default ``rtol / 100``).
    samples : int, optional
        Keep this many equally spaced samples per trajectory (memory ``N * samples * 18``);
        default: keep only the final states.
    threads : int, optional
        Number of threads (default: all cores). More than numba may use
        (``numba.config.NUMBA_NUM_THREADS``, the cores by default) are reduced to that number;
        the result's ``threads`` says how many ran.
    progress : callable, optional
        ``progress(done, N)``.
    client : distributed.Client, optional
        Run on this Dask cluster instead: the states go to the workers in chunks
        (:data:`CLIENT_CHUNKS` per worker thread), each integrated by the compiled kernel on one
        thread (``threads`` is then ignored); the results are the same as in-process.
    """
    model = get_model(model)
    if samples is not None:
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 2:
            raise ScenarioError(f"samples = {short_repr(samples)} must be an integer >= 2")
        check_ensemble_memory(len(states), int(samples))
    states = np.array(states, dtype=float)
    if states.ndim != 2 or states.shape[1] != N_STATE:
        raise ScenarioError(f"states must have shape (N, {N_STATE}), got {states.shape}")
    N = states.shape[0]
    if N == 0:
        raise ScenarioError("the ensemble is empty")
    bodies = [body] * N if isinstance(body, SphericalTop) else list(body)
    if len(bodies) != N:
        raise ScenarioError(f"{len(bodies)} bodies for {N} states")
    if not (isinstance(t_end, int | float) and math.isfinite(t_end) and t_end > 0):
        raise ScenarioError(f"t_end = {t_end!r} must be a positive number")
    if not 1e-15 <= rtol <= 0.1:
        raise ScenarioError(f"rtol = {rtol:g} must lie in [1e-15, 0.1]")
    atol = rtol / 100 if atol is None else atol
    if not atol > 0:
        raise ScenarioError(f"atol = {atol:g} must be > 0")
    from rollingtop.dynamics.state import constraint_residuals

    for k, (b, y) in enumerate(zip(bodies, states, strict=True)):
        res = constraint_residuals(b, model, y)
        bad = np.flatnonzero(np.abs(res) > 1e-9)
        if bad.size or not np.all(np.isfinite(y)):
            which = model.constraints[bad[0]] if bad.size else "finite values"
            raise ScenarioError(
                f"state {k + 1} violates the constraint {which} of model {model.name!r} "
                "(build states with rollingtop.initial_state for the same body)"
            )
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, int | np.integer) or threads < 1:
            raise ScenarioError(f"threads = {short_repr(threads)} must be an integer >= 1")
        threads = thread_count(int(threads))  # what is really used
    # the model picks its kernel variant per state (meridian: the pole cases)
    codes = np.array(
        [model.kernel_code(b, y) for b, y in zip(bodies, states, strict=True)], dtype=np.int64
    )
    params = np.array([model.params(b) for b in bodies])
    t_eval = np.linspace(0.0, t_end, samples) if samples else np.array([0.0, float(t_end)])
    if client is not None:
        compile_s = 0.0
        out, final, stats, wall, used = _on_client(
            client, codes, params, states, t_eval, rtol, atol, max_steps, progress
        )
    else:
        # the packages of the codes it runs (the model's own, its variants'), and no other
        compile_s = sum(compile_ensemble_code(c) for c in _first_codes(codes))
        out, final, stats, wall = integrate_batch(
            codes,
            params,
            states,
            t_eval,
            rtol=rtol,
            atol=atol,
            max_steps=max_steps,
            threads=threads,
            progress=progress,
        )
        used = thread_count(threads)
    integrals = _ensemble_integrals(model, bodies, codes, states, final)
    return EnsembleResult(
        model=model,
        bodies=bodies,
        initial=states,
        final=final,
        t_end=float(t_end),
        status=stats[:, 0].astype(int),
        steps=stats[:, 1].astype(int),
        rejected_steps=stats[:, 2].astype(int),
        rhs_evals=stats[:, 3].astype(int),
        min_normal_force=stats[:, 4],
        max_friction_ratio=stats[:, 5],
        integrals=integrals,
        wall_time_s=wall,
        compile_time_s=compile_s,
        threads=used,
        t=t_eval if samples else None,
        samples=out if samples else None,
    )


def _first_codes(codes: IntArray) -> list[int]:
    """One kernel code of each compiled package among ``codes``."""
    return [int(codes[idx[0]]) for _, idx in by_package(codes)]


#: Chunks of states per worker thread when :func:`simulate_ensemble` runs on a Dask client.
CLIENT_CHUNKS = 4


def _integrate_chunk(
    codes: IntArray,
    params: FloatArray,
    states: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
) -> tuple[FloatArray, FloatArray, FloatArray, float]:
    """One Dask task of :func:`simulate_ensemble`: a chunk on one thread of a worker."""
    return integrate_batch(
        codes, params, states, t_eval, rtol=rtol, atol=atol, max_steps=max_steps, threads=1
    )


def _on_client(
    client: Client,
    codes: IntArray,
    params: FloatArray,
    states: FloatArray,
    t_eval: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    progress: Callable[[int, int], None] | None,
) -> tuple[FloatArray, FloatArray, FloatArray, float, int]:
    from distributed import as_completed

    slots = max(1, sum(client.nthreads().values()))
    N = len(states)
    bounds = np.linspace(0, N, min(N, CLIENT_CHUNKS * slots) + 1).astype(int)
    futures = {
        client.submit(
            _integrate_chunk,
            codes[a:b],
            params[a:b],
            states[a:b],
            t_eval,
            rtol,
            atol,
            max_steps,
            pure=False,
        ): k
        for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:], strict=True))
    }
    parts: dict[int, tuple[FloatArray, FloatArray, FloatArray, float]] = {}
    done = 0
    for fut in as_completed(futures):
        k = futures[fut]
        parts[k] = fut.result()
        done += len(parts[k][1])
        if progress is not None:
            progress(done, N)
    order = sorted(parts)
    out = np.concatenate([parts[k][0] for k in order])
    final = np.concatenate([parts[k][1] for k in order])
    stats = np.concatenate([parts[k][2] for k in order])
    return out, final, stats, max(parts[k][3] for k in order), slots


def _ensemble_integrals(
    model: ContactModel,
    bodies: list[SphericalTop],
    codes: IntArray,
    initial: FloatArray,
    final: FloatArray,
) -> dict[str, dict[str, FloatArray]]:
    # the integrals every body has (with the model's particular ones, e.g. parallel's slip)
    unique = list({id(b): b for b in bodies}.values())
    shared = set(model.integrals_for(unique[0]))
    for b in unique[1:]:
        shared &= set(model.integrals_for(b))
    names = [n for n in model.integrals_for(unique[0]) if n in shared]
    result: dict[str, dict[str, FloatArray]] = {
        n: {"initial": np.empty(len(bodies)), "final": np.empty(len(bodies))} for n in names
    }
    groups: dict[tuple[int, int], tuple[SphericalTop, int, list[int]]] = {}
    for k, (b, c) in enumerate(zip(bodies, codes, strict=True)):
        groups.setdefault((id(b), int(c)), (b, int(c), []))[2].append(k)
    for b, c, members in groups.values():
        idx = np.array(members)
        for key, Y in (("initial", initial[idx]), ("final", final[idx])):
            kernel = kernel_by_code(c)
            values_of = evaluate(b, Y, names, pole=kernel.variant, model=kernel.model)
            for name, values in values_of.items():
                result[name][key][idx] = values
    for d in result.values():
        d["drift"] = d["final"] - d["initial"]
    return result


def ensemble_from_scenario(scenario: Scenario, columns: Columns, **kwargs: Any) -> EnsembleResult:
    """Run the scenario's body and model over the initial states of ``columns``; ``kwargs`` go to
    :func:`simulate_ensemble` (the scenario's ``t_end``, ``rtol``, ``atol`` and ``max_steps`` by
    default)."""
    opts = scenario.integration
    check_ensemble_memory(len(next(iter(columns.values()), ())), kwargs.get("samples"))
    kwargs.setdefault("t_end", opts.t_end)
    kwargs.setdefault("rtol", opts.rtol)
    kwargs.setdefault("atol", opts.resolved_atol if kwargs["rtol"] == opts.rtol else None)
    kwargs.setdefault("max_steps", opts.max_steps)
    states = states_from_table(scenario, columns)
    result = simulate_ensemble(scenario.body, scenario.model, states, **kwargs)
    return replace(result, columns=dict(columns))
