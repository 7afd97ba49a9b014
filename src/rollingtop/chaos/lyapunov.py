"""Chaos indicators: the maximal Lyapunov exponent and MEGNO, for any contact model.

Both come from one integration of the motion together with its tangent (variational) dynamics
in compiled code (:mod:`rollingtop._compiled._tangent`: the tangent vector kept on the tangent space
of the constraint manifold and renormalised after every step):

- the **finite-time maximal Lyapunov exponent** ``lambda(t) = (1/t) sum ln |delta|`` over the
  renormalisations (Benettin et al. 1980, *Meccanica* 15, 9). For a quasi-periodic motion the
  tangent vector grows linearly, so ``lambda(t) ~ ln t / t -> 0``; for a chaotic one
  ``lambda(t) -> lambda > 0``;
- **MEGNO** (Cincotta & Simo 2000, *Astron. Astrophys. Suppl.* 147, 205)
  ``Y(t) = (2/t) int_0^t (delta' . delta / |delta|^2) s ds`` and its running mean
  ``<Y>(t) = (1/t) int_0^t Y(s) ds``: ``<Y> -> 2`` for quasi-periodic motion, ``0`` for a stable
  isochronous periodic one, and ``<Y> ~ lambda t / 2`` (``Y ~ lambda t``) for a chaotic one.

:func:`rollingtop.chaos.indicator_map` evaluates the final values over many initial states in
parallel (on all cores, or on a Dask cluster with ``client=``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from rollingtop._checks import check_memory
from rollingtop._compiled import compiling, for_code
from rollingtop._compiled._dop853 import BUDGET_EXHAUSTED, FINISHED, STATUS_NAMES
from rollingtop._compiled._tangent import N_AUG, REACHED_VERTICAL, STEPS
from rollingtop._errors import IntegrationError, ScenarioError
from rollingtop._jit import call
from rollingtop._layout import N_STATE, state_components
from rollingtop._output import NetCDFOutput
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.chaos.level import VERTICAL_MARGIN
from rollingtop.contact import ContactModel, get_model
from rollingtop.dynamics.integrals import evaluate
from rollingtop.dynamics.state import UNIT_TOLERANCE, constraint_residuals
from rollingtop.integrate.driver import _raise_for_status

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["ChaosIndicators", "chaos_indicators", "initial_tangent", "vertical_stop"]


def vertical_stop(model: ContactModel) -> float:
    """The ``s_stop`` of the tangent kernel for ``model``: nonzero (stop at a passage through the
    vertical) for a model whose motion the state there does not determine (the ``parallel``
    model: its flow has no derivative at the pole, the tangent vector would explode at every
    passage)."""
    return 0.0 if model.vertical.determined else 1.0


#: Seed of the default initial tangent vector (a fixed random direction: reproducible runs).
TANGENT_SEED = 20231205


def initial_tangent(seed: int = TANGENT_SEED) -> FloatArray:
    """A random direction of the state space, shape (18,), normal with this seed (projected onto
    the tangent space of the constraint manifold and normalised by the integration)."""
    d: FloatArray = np.random.default_rng(seed).normal(size=N_STATE)
    return d


def check_state(body: SphericalTop, model: ContactModel, state: ArrayLike) -> FloatArray:
    """``state`` as a float array of shape (18,), finite and on the model's constraints."""
    y = np.array(state, dtype=float)
    if y.shape != (N_STATE,) or not np.all(np.isfinite(y)):
        raise ScenarioError(f"state must be {N_STATE} finite numbers, got shape {y.shape}")
    res = constraint_residuals(body, model, y)
    if np.any(np.abs(res) > UNIT_TOLERANCE):
        raise ScenarioError(
            f"the state violates a constraint of model {model.name!r} (largest residual "
            f"{np.max(np.abs(res)):.3g}): build it with rollingtop.initial_state"
        )
    return y


def check_options(t_end: object, samples: object, rtol: float, atol: float | None) -> float:
    """Validate the shared options; returns ``atol`` (default ``rtol / 100``)."""
    if not (
        isinstance(t_end, int | float)
        and not isinstance(t_end, bool)
        and math.isfinite(t_end)
        and t_end > 0
    ):
        raise ScenarioError(f"t_end = {t_end!r} must be a positive number")
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 1:
        raise ScenarioError(f"samples = {samples!r} must be an integer >= 1")
    # the indicators (3) and the states (18) at every sample, and the dataset made of them
    check_memory(f"samples = {samples}", 2.0 * 8 * (3 + N_STATE) * float(samples))
    if not (isinstance(rtol, int | float) and 1e-15 <= rtol <= 0.1):
        raise ScenarioError(f"rtol = {rtol!r} must lie in [1e-15, 0.1]")
    atol = rtol / 100 if atol is None else atol
    if not (isinstance(atol, int | float) and atol > 0):
        raise ScenarioError(f"atol = {atol!r} must be > 0")
    return float(atol)


@dataclass
class ChaosIndicators(NetCDFOutput):
    """Time series of the chaos indicators along one motion.

    Attributes
    ----------
    body : SphericalTop
    model : ContactModel
    initial : ndarray, shape (18,)
    t : ndarray, shape (n,)
        Sample times (positive, increasing; the last is ``t_end``).
    lyapunov : ndarray, shape (n,)
        Finite-time maximal Lyapunov exponent ``lambda(t)``.
    megno, megno_mean : ndarray, shape (n,)
        MEGNO ``Y(t)`` and its running mean ``<Y>(t)``.
    states : ndarray, shape (n, 18)
        The motion at the sample times.
    steps, rejected_steps, rhs_evals : int
        Of the augmented integration (``rhs_evals`` counts the model's right-hand side).
    wall_time_s : float
        Of the integration alone.
    compile_time_s : float
        Compiling (or loading from numba's cache) the kernels first, 0 once done in the process.
    """

    body: SphericalTop
    model: ContactModel
    initial: FloatArray
    t: FloatArray
    lyapunov: FloatArray
    megno: FloatArray
    megno_mean: FloatArray
    states: FloatArray
    steps: int
    rejected_steps: int
    rhs_evals: int
    wall_time_s: float
    compile_time_s: float = 0.0

    def integral_drift(self) -> dict[str, float]:
        """Largest ``|I(t) - I(0)|`` over the samples of each integral of the model."""
        names = self.model.integrals_for(self.body)
        pole = self.model.kernel(self.body, self.initial).variant
        start = evaluate(self.body, self.initial, names, pole=pole, model=self.model)
        along = evaluate(self.body, self.states, names, pole=pole, model=self.model)
        return {n: float(np.max(np.abs(along[n] - start[n]))) for n in names}

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary (``rollingtop chaos --json``): ``lyapunov`` is ``lambda(t_end)``,
        ``megno`` the time-averaged ``<Y>(t_end)``, ``megno_instantaneous`` ``Y(t_end)``."""
        return {
            "model": self.model.name,
            "t_end": float(self.t[-1]),
            "lyapunov": float(self.lyapunov[-1]),
            "megno": float(self.megno_mean[-1]),
            "megno_instantaneous": float(self.megno[-1]),
            "steps": self.steps,
            "rejected_steps": self.rejected_steps,
            "rhs_evals": self.rhs_evals,
            "wall_time_s": self.wall_time_s,
            "compile_time_s": self.compile_time_s,
            "integral_drift": self.integral_drift(),
        }

    def to_xarray(self) -> xr.Dataset:
        """The time series as an :class:`xarray.Dataset` (dimension ``t``)."""
        import xarray as xr

        data = {
            "lyapunov": ("t", self.lyapunov),
            "megno": ("t", self.megno),
            "megno_mean": ("t", self.megno_mean),
            "states": (("t", "state"), self.states),
            "initial_state": ("state", self.initial),
        }
        attrs: dict[str, Any] = {f"body_{k}": v for k, v in self.body.to_dict().items()}
        attrs.update(
            model=self.model.name,
            source="rollingtop chaos",
            summary_json=json.dumps(self.summary()),
        )
        return xr.Dataset(
            data, coords={"t": self.t, "state": state_components(self.model.slot_name)}, attrs=attrs
        )


_indicators_compiled: set[str] = set()


#: Accepted steps of the tangent integration per compiled call: between calls Python runs, and
#: with it the signal handlers (a SIGTERM ends a long run within about a second).
CHUNK_STEPS = 4000


def _run_chunks(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    d0: FloatArray,
    t: FloatArray,
    rtol: float,
    atol: float,
    max_steps: int,
    out: FloatArray,
    states: FloatArray,
    stats: FloatArray,
    stop: float,
) -> tuple[FloatArray, FloatArray]:
    """The compiled ``run_indicators`` of kernel ``code``, in calls of at most
    :data:`CHUNK_STEPS` accepted steps (the same steps as one call); returns the final augmented
    state ``z`` (shape ``(N_AUG,)``: the state, the unit tangent vector, ...) and ``ctrl``
    (its ``LOG_SUM``: the tangent vector's growth, ``ln |delta(t)| - ln |delta(0)|``)."""
    kernels = for_code(code).tangent
    z, fz = np.zeros(N_AUG), np.zeros(N_AUG)
    ctrl = np.array([0.0, 0.0, rtol, atol, 0.0])
    counts = np.zeros(3, dtype=np.int64)
    call(kernels.start_indicators, code, p, y0, d0, float(t[-1]), z, fz, ctrl)
    k = 0
    while True:
        limit = min(max_steps, int(counts[STEPS]) + CHUNK_STEPS)
        k = call(
            kernels.indicators_chunk,
            code,
            p,
            z,
            fz,
            ctrl,
            counts,
            t,
            k,
            limit,
            out,
            states,
            stats,
            stop,
        )
        if stats[0] != BUDGET_EXHAUSTED or counts[STEPS] >= max_steps:
            return z, ctrl


def _compile_indicators(
    code: int,
    p: FloatArray,
    y0: FloatArray,
    d0: FloatArray,
    rtol: float,
    atol: float,
    stop: float,
) -> float:
    """Compile (or load) the tangent kernel apart from a timed run, by a run of one tiny step;
    seconds spent, 0 after the first call in a process (its types never change)."""
    kernels = for_code(code)
    if kernels.PACKAGE in _indicators_compiled:
        return 0.0
    import time

    start = time.perf_counter()
    with compiling(kernels, "chaos"):
        _run_chunks(
            code,
            p,
            y0.copy(),
            d0.copy(),
            np.array([1e-9]),
            float(rtol),
            atol,
            1,
            np.full((1, 3), np.nan),
            np.full((1, N_STATE), np.nan),
            np.zeros(4),
            stop,
        )
    _indicators_compiled.add(kernels.PACKAGE)
    return time.perf_counter() - start


def chaos_indicators(
    body: SphericalTop,
    model: str | ContactModel,
    state: ArrayLike,
    *,
    t_end: float,
    samples: int = 1000,
    rtol: float = 1e-10,
    atol: float | None = None,
    tangent: ArrayLike | None = None,
    max_steps: int = 10**8,
) -> ChaosIndicators:
    """The maximal Lyapunov exponent and MEGNO along the motion from ``state``.

    Parameters
    ----------
    body : SphericalTop
    model : str or ContactModel
        Any registered model (through its compiled kernel).
    state : array_like, shape (18,)
        Constraint-consistent initial state.
    t_end : float
        Length of the integration.
    samples : int
        Equally spaced sample times in ``(0, t_end]`` (the integration's steps end on them).
    rtol, atol : float
        Tolerances (``atol`` default ``rtol / 100``); the tangent vector's error is held to
        ``max(rtol, 1e-8)`` of its norm (:data:`rollingtop._compiled._tangent.TANGENT_TOL`).
    tangent : array_like, shape (18,), optional
        Initial tangent vector (projected onto the tangent space; default
        :func:`initial_tangent`).
    max_steps : int
        Bound on accepted steps.

    Raises
    ------
    IntegrationError
        When the integration cannot reach ``t_end`` (one line saying why).
    """
    model = get_model(model)
    atol = check_options(t_end, samples, rtol, atol)
    y0 = check_state(body, model, state)
    d0 = initial_tangent() if tangent is None else np.array(tangent, dtype=float)
    if d0.shape != (N_STATE,) or not np.all(np.isfinite(d0)) or not np.any(d0[:15]):
        raise ScenarioError(f"tangent must be {N_STATE} finite numbers, not all zero")
    code = model.kernel_code(body, y0)
    t = np.linspace(0.0, float(t_end), int(samples) + 1)[1:]
    out = np.full((t.size, 3), np.nan)
    states = np.full((t.size, N_STATE), np.nan)
    stats = np.zeros(4)
    import time

    stop = vertical_stop(model)
    tilt = math.hypot(y0[12], y0[13])
    if stop != 0.0 and tilt < VERTICAL_MARGIN:
        raise IntegrationError(
            f"the motion starts at the vertical (sqrt(gamma1^2 + gamma2^2) = {tilt:.3g} < "
            f"{VERTICAL_MARGIN:g}), where the {model.name} model's continuation is not determined "
            "by the state: the tangent dynamics (Lyapunov exponent, MEGNO) is undefined there; "
            "start with the axis tilted"
        )
    compiled = _compile_indicators(code, model.params(body), y0, d0, rtol, atol, stop)
    start = time.perf_counter()
    _run_chunks(
        code,
        model.params(body),
        y0,
        d0,
        t,
        float(rtol),
        atol,
        int(max_steps),
        out,
        states,
        stats,
        stop,
    )
    wall = time.perf_counter() - start
    status = int(stats[0])
    if status != FINISHED:
        done = np.flatnonzero(np.isfinite(out[:, 0]))
        t_stop = float(t[done[-1]]) if done.size else 0.0
        if status == 1:
            raise IntegrationError(f"max_steps = {max_steps} reached near t = {t_stop:.6g}")
        if status == REACHED_VERTICAL:
            raise IntegrationError(
                f"the motion reaches the vertical after t = {t_stop:.6g}, where the "
                f"{model.name} model's continuation is not determined by the state: the tangent "
                "dynamics (Lyapunov exponent, MEGNO) is undefined beyond it; choose a shorter "
                "t_end or a motion that stays away from the vertical"
            )
        _raise_for_status(
            status,
            np.array([t_stop, 0.0, t_end, rtol, atol, 0.0]),
            np.array([0, 1, 0, 0, 0], dtype=np.int64),
        )
        raise IntegrationError(f"{STATUS_NAMES.get(status, status)} near t = {t_stop:.6g}")
    return ChaosIndicators(
        body=body,
        model=model,
        initial=y0,
        t=t,
        lyapunov=out[:, 0],
        megno=out[:, 1],
        megno_mean=out[:, 2],
        states=states,
        steps=int(stats[1]),
        rejected_steps=int(stats[2]),
        rhs_evals=int(stats[3]),
        wall_time_s=wall,
        compile_time_s=compiled,
    )
