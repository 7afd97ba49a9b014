"""Poincare sections on a level set of the integrals, for any contact model.

**The section** is the hyperplane ``w_tau = 0`` crossed upward (``w_tau`` from negative to
positive), where ``tau = e3 x gamma / s`` (``docs/model.md``, "Reduced variables"). Since
``gamma3' = s w_tau`` (paper eq. 3.3, a kinematic identity that holds for every model), these are
the minima of ``gamma3``: the lowest inclinations of the axis, reached once per nutation. The
event function is the stepper's ``W_TAU`` (``s w_tau = (w, e3 x gamma)``,
:mod:`rollingtop._compiled._events`), located on the 7th-order dense output of each step by
bisection (:func:`rollingtop._compiled._template.dense.event_root`, 60 halvings) and the state
there projected onto the constraints.

**The plane** of the points is ``(gamma3, w_n)``, ``w_n = (w, n)``, ``n = -(gamma1, gamma2, 0)
/ s``: the inclination at the minimum and the angular velocity about the horizontal axis
``n`` (the axis's azimuth rate is ``psi' = -w_n / s``). For the paper's model and a
dynamically symmetric body the reduced system on a level ``(M3, C1, C2)`` has one degree of
freedom (paper Sec. 3): ``gamma3(t)`` is periodic, so every crossing of a trajectory is the same
point, ``(gamma3_min, w_n(gamma3_min))`` with ``w_n`` of eq. 3.8: the invariant curves of the
section degenerate to points, one per orbit. Without such a reduction (a non-symmetric body,
the smooth or rough plane's generic cases, the non-integrable models) the points of one
trajectory fill curves (quasi-periodic motion, KAM tori) or areas (chaos). At a given
``(gamma3, w_n)`` the section may hold several states of the level (the remaining coordinates,
such as ``w3`` or the azimuth of ``gamma`` in the body, take the values the held integrals
allow): the plane is a projection, so points of different sheets may overlap.

**Initial states** share the level of the given state (:func:`rollingtop.chaos.level_states`),
or are given; they are integrated in parallel on all cores, each until it has the asked number
of crossings.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._checks import short_repr
from rollingtop._compiled import by_package, compiling
from rollingtop._compiled._dop853 import FINISHED, STATUS_NAMES
from rollingtop._compiled._section import NO_CROSSING, SECTION_STATS
from rollingtop._errors import InitialStateError, ScenarioError
from rollingtop._layout import GAMMA, N_STATE, W, state_components
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos.level import held_integrals, level_states, level_values
from rollingtop.contact import ContactModel, get_model
from rollingtop.dynamics.integrals import reduced_components
from rollingtop.dynamics.state import UNIT_TOLERANCE, constraint_residuals
from rollingtop.integrate._threads import run_rows

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["STATE_COMPONENTS", "poincare_section", "section_summary", "stopped_early"]

#: Names of the state components (the ``state`` coordinate of the datasets).
STATE_COMPONENTS = state_components()
#: Accepted steps a section trajectory may take without crossing before it stops: at the
#: default tolerance a turn of gamma3 takes tens to hundreds of steps, so this is hundreds of
#: its periods.
MAX_GAP_STEPS = 100_000
#: The stepper's status names and the section's own.
SECTION_STATUS = {**STATUS_NAMES, NO_CROSSING: "no crossing within max_gap_steps steps"}
#: Largest number of crossings stored (trajectories times crossings).
MAX_POINTS = 20_000_000
#: Default number of trajectories when a single state is given.
DEFAULT_TRAJECTORIES = 16


def _check_count(name: str, value: object, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < lo:
        raise ScenarioError(f"{name} = {value!r} must be an integer >= {lo}")
    return int(value)


def _initial_states(
    body: SphericalTop,
    model: ContactModel,
    states: ArrayLike,
    trajectories: int | None,
    hold: Sequence[str] | None,
    seed: int | None,
) -> FloatArray:
    Y = np.array(states, dtype=float)
    if Y.shape == (N_STATE,):
        n = DEFAULT_TRAJECTORIES if trajectories is None else trajectories
        return level_states(
            body, model, Y, _check_count("trajectories", n, 1), hold=hold, seed=seed
        )
    if Y.ndim != 2 or Y.shape[1] != N_STATE or Y.shape[0] == 0:
        raise InitialStateError(f"states must have shape (18,) or (K, 18), got {Y.shape}")
    if trajectories is not None and trajectories != Y.shape[0]:
        raise InitialStateError(f"trajectories = {trajectories!r} but {Y.shape[0]} states given")
    for k, y in enumerate(Y):
        res = constraint_residuals(body, model, y)
        if not np.all(np.isfinite(y)) or np.any(np.abs(res) > UNIT_TOLERANCE):
            raise InitialStateError(
                f"state {k} is not finite or violates a constraint of model {model.name!r} "
                "(build states with rollingtop.initial_state or rollingtop.chaos.level_states)"
            )
    return Y


def poincare_section(
    body: SphericalTop,
    model: str | ContactModel,
    states: ArrayLike,
    *,
    crossings: int = 1000,
    trajectories: int | None = None,
    hold: Sequence[str] | None = None,
    seed: int | None = 0,
    rtol: float = 1e-10,
    atol: float | None = None,
    t_max: float = math.inf,
    max_steps: int = 10**7,
    max_gap_steps: int = MAX_GAP_STEPS,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> xr.Dataset:
    """Crossings of the section ``w_tau = 0`` (upward) by trajectories on one level set.

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
        Any registered model (through its compiled kernel).
    states : array_like, shape (18,) or (K, 18)
        One state, whose level is sampled (:func:`rollingtop.chaos.level_states`: the state
        itself and ``trajectories - 1`` more), or the initial states themselves.
    crossings : int
        Crossings wanted per trajectory.
    trajectories : int, optional
        Trajectories sampled on the level (default 16; with K states given: K).
    hold : sequence of str, optional
        The integrals held on the level (default: all of the model's for the body).
    seed : int or None
        Seed of the sampling.
    rtol, atol : float
        Tolerances of the integration (``atol`` default ``rtol / 100``).
    t_max : float
        A trajectory stops at this time even with fewer crossings.
    max_steps : int
        ... or after this many accepted steps.
    max_gap_steps : int
        ... or after this many accepted steps without a new crossing (default
        :data:`MAX_GAP_STEPS`: a motion that settled onto a steady one, or that never turns in
        ``gamma3``, stops instead of running to ``max_steps``; its status says
        ``"no crossing within max_gap_steps steps"``).
    threads : int, optional
        Threads (default: numba's, all cores).
    progress : callable, optional
        ``progress(found, K * crossings)``: the crossings found so far by all trajectories,
        called every ``WAIT_SLICE`` (0.05 s) while they run and once at the end.

    Returns
    -------
    xarray.Dataset
        Dimensions ``trajectory`` (K), ``crossing`` (N) and ``state`` (18). Variables
        ``gamma3``, ``w_n``, ``w_tau`` (at the located crossing: zero to ~1e-12), ``t``
        (K, N; NaN beyond a trajectory's crossings), ``crossing_state`` (K, N, 18),
        ``initial_state`` (K, 18), per trajectory ``n_crossings``, ``status`` (0: done, else
        the stepper's code, attribute ``status_names``), ``steps``, ``t_last`` and
        ``min_normal_force`` (over the accepted steps' ends: negative where the body would
        leave the plane), and per held integral ``level_<name>`` (its value at each
        initial state). Attributes: the body, ``model``, ``held``, ``section``, ``plane``.
        NetCDF-writable (:func:`rollingtop.io.netcdf_bytes`).
    """
    import xarray as xr

    model = get_model(model)
    crossings = _check_count("crossings", crossings, 1)
    _check_count("max_steps", max_steps, 1)
    _check_count("max_gap_steps", max_gap_steps, 1)
    if trajectories is not None:
        trajectories = _check_count("trajectories", trajectories, 1)
    if not 1e-15 <= rtol <= 0.1:
        raise ScenarioError(f"rtol = {rtol!r} must lie in [1e-15, 0.1]")
    atol = rtol / 100 if atol is None else atol
    if not (isinstance(atol, int | float) and atol > 0):
        raise ScenarioError(f"atol = {atol!r} must be > 0")
    if not (isinstance(t_max, int | float) and t_max > 0):
        raise ScenarioError(f"t_max = {t_max!r} must be > 0")
    if seed is not None and (
        isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0
    ):
        raise ScenarioError(f"seed = {short_repr(seed)} must be an integer >= 0")
    if trajectories is not None and trajectories * crossings > MAX_POINTS:  # before sampling
        raise ScenarioError(
            f"{trajectories} trajectories x {crossings} crossings exceeds {MAX_POINTS}"
        )
    names = held_integrals(body, model, hold)
    Y0 = _initial_states(body, model, states, trajectories, hold, seed)
    K = Y0.shape[0]
    if K * crossings > MAX_POINTS:
        raise ScenarioError(f"{K} trajectories x {crossings} crossings exceeds {MAX_POINTS}")
    codes = np.array([model.kernel_code(body, y) for y in Y0], dtype=np.int64)
    ev_t = np.full((K, crossings), np.nan)
    ev_y = np.full((K, crossings, N_STATE), np.nan)
    stats = np.zeros((K, len(SECTION_STATS)))
    wall, used = 0.0, 1
    # package by package: the model's own kernel, its variants (pole levels) in theirs
    for kernels, idx in by_package(codes):
        part = ev_t[idx], ev_y[idx], stats[idx]  # copies the kernel fills
        done = int(np.count_nonzero(~np.isnan(ev_t)))
        poll = None
        if progress is not None:
            # the kernel writes each crossing's time into ev_t (NaN until then) as it finds it
            def poll(_: int, found: FloatArray = part[0], before: int = done) -> None:
                progress(before + int(np.count_nonzero(~np.isnan(found))), ev_t.size)

        with compiling(kernels, "chaos"):
            seconds, used = run_rows(
                kernels.chaos.section_batch,
                (
                    codes[idx],
                    model.params(body),
                    Y0[idx],
                    float(t_max),
                    float(rtol),
                    float(atol),
                    int(max_steps),
                    int(max_gap_steps),
                    *part,
                ),
                (0, 2, 8, 9, 10),
                idx.size,
                threads=threads,
                poll=poll,
            )
        wall += seconds
        ev_t[idx], ev_y[idx], stats[idx] = part
    found = stats[:, 1].astype(int)
    if progress is not None:
        progress(int(found.sum()), ev_t.size)
    mask = np.arange(crossings)[None, :] >= found[:, None]
    ev_t[mask] = np.nan
    ev_y[mask] = np.nan
    red = reduced_components(ev_y, model=model)
    levels = np.array([level_values(body, model, y, names) for y in Y0])
    data: dict[str, tuple[Any, NDArray[Any]]] = {
        "gamma3": (("trajectory", "crossing"), red["gamma3"]),
        "w_n": (("trajectory", "crossing"), red["w_n"]),
        "w_tau": (("trajectory", "crossing"), red["w_tau"]),
        "t": (("trajectory", "crossing"), ev_t),
        "crossing_state": (("trajectory", "crossing", "state"), ev_y),
        "initial_state": (("trajectory", "state"), Y0),
        "n_crossings": ("trajectory", found.astype(np.int64)),
        "status": ("trajectory", stats[:, 0].astype(np.int32)),
        "steps": ("trajectory", stats[:, 2].astype(np.int64)),
        "t_last": ("trajectory", stats[:, 3]),
        "min_normal_force": ("trajectory", stats[:, 4]),
    }
    for k, name in enumerate(names):
        data[f"level_{name}"] = ("trajectory", levels[:, k])
    attrs: dict[str, Any] = {f"body_{k}": v for k, v in body.to_dict().items()}
    attrs.update(
        model=model.name,
        held=",".join(names),
        crossings=crossings,
        rtol=float(rtol),
        atol=float(atol),
        wall_time_s=wall,
        threads=used,
        source="rollingtop section",
        section="w_tau = 0, w_tau increasing (minima of gamma3)",
        plane="gamma3, w_n",
        status_names=json.dumps({str(k): v for k, v in SECTION_STATUS.items()}),
    )
    coords = {
        "trajectory": np.arange(K),
        "crossing": np.arange(crossings),
        "state": state_components(model.slot_name),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def stopped_early(ds: xr.Dataset) -> list[dict[str, Any]]:
    """The trajectories of a section that stopped before the asked number of crossings.

    Parameters
    ----------
    ds : xarray.Dataset
        A section (:func:`poincare_section`).

    Returns
    -------
    list of dict
        One per such trajectory, in order: ``trajectory`` (its index), ``crossings`` (found),
        ``t_last``, ``status`` (the stepper's code) and ``reason``: the stepper's status name
        (``"max_steps reached"``, ...), or ``"t_max reached"`` where the stepper finished at
        ``t_max``; ``gamma`` and ``omega``, the body-frame initial values.
    """
    names = json.loads(ds.attrs["status_names"])
    found = ds["n_crossings"].values
    out = []
    for k in np.flatnonzero(found < ds.attrs["crossings"]):
        status = int(ds["status"].values[k])
        y0 = ds["initial_state"].values[k]
        reason = "t_max reached" if status == FINISHED else names.get(str(status), str(status))
        out.append(
            {
                "trajectory": int(k),
                "crossings": int(found[k]),
                "t_last": float(ds["t_last"].values[k]),
                "status": status,
                "reason": reason,
                "gamma": [float(x) for x in y0[GAMMA]],
                "omega": [float(x) for x in y0[W]],
            }
        )
    return out


def section_summary(ds: xr.Dataset) -> dict[str, Any]:
    """JSON-ready summary of a section (``rollingtop section --json``): ``incomplete`` counts
    the trajectories that stopped early, ``stopped_early`` names them (:func:`stopped_early`)."""
    w_tau = np.abs(ds["w_tau"].values)
    ok = np.isfinite(w_tau)
    levels = {
        str(name)[6:]: [float(ds[name].min()), float(ds[name].max())]
        for name in ds.data_vars
        if str(name).startswith("level_")
    }
    return {
        "model": ds.attrs["model"],
        "trajectories": int(ds.sizes["trajectory"]),
        "crossings_per_trajectory": int(ds.attrs["crossings"]),
        "crossings_found": int(ds["n_crossings"].sum()),
        "incomplete": int(np.sum(ds["n_crossings"].values < ds.attrs["crossings"])),
        "stopped_early": stopped_early(ds),
        "max_abs_w_tau": float(w_tau[ok].max()) if ok.any() else None,
        "min_normal_force": float(ds["min_normal_force"].min()),
        "contact_lost": int(np.sum(ds["min_normal_force"].values < 0)),
        "held": ds.attrs["held"].split(","),
        "level_range": levels,
        "gamma3_range": [float(np.nanmin(ds["gamma3"])), float(np.nanmax(ds["gamma3"]))]
        if ok.any()
        else None,
        "wall_time_s": float(ds.attrs["wall_time_s"]),
    }
