"""The result of a simulation: samples, first integrals, reactions, export."""

from __future__ import annotations

import functools
import io
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rollingtop._compiled import for_code
from rollingtop._errors import RollingTopError
from rollingtop._figures import TRAJECTORY_KINDS, draw
from rollingtop._html import trajectory_html
from rollingtop._jit import call
from rollingtop._json import finite_or_none
from rollingtop._layout import ALPHA, BETA, GAMMA, MAX_ROWS, N_STATE, POSITION, V, W
from rollingtop._output import TRAJECTORY_UNITS, NetCDFOutput
from rollingtop._types import FloatArray
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, kernel_by_code
from rollingtop.dynamics.integrals import HELD_TOLERANCE, evaluate, natural_scales
from rollingtop.integrate.driver import StepReactions
from rollingtop.io import check_output_path, write_bytes_atomic

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes

__all__ = ["Trajectory", "OUTPUT_SUFFIXES"]

OUTPUT_SUFFIXES = (".nc", ".csv")


@dataclass
class Trajectory(NetCDFOutput):
    """Samples of one motion with everything measured along it.

    Attributes
    ----------
    body : SphericalTop
    model : ContactModel
    t : ndarray, shape (n,)
    y : ndarray, shape (n, 18)
        States ``(v, w, alpha, beta, gamma, X, Y, psi_nu)``, body-frame vectors (see
        :mod:`rollingtop._layout`).
    rtol, atol : float
        Tolerances the motion was integrated with.
    stats : dict of str to float
        ``steps, rejected_steps, rhs_evals, wall_time_s, compile_time_s``.
    step_reactions : StepReactions
        Contact reactions monitored at every accepted step (not only at samples):
        ``min_normal_force, t_min_normal_force, contact_lost_at, max_friction_ratio, ...``.
    event_t : ndarray, shape (k,)
        Times of the events asked of :func:`rollingtop.simulate` (empty otherwise).
    event_y : ndarray, shape (k, 18)
        States at those events.
    kernel_code : int, optional
        Compiled kernel the motion was integrated with (the model's code, or a pole variant of
        the meridian model); defaults to ``model.code``.
    """

    body: SphericalTop
    model: ContactModel
    t: FloatArray
    y: FloatArray
    rtol: float
    atol: float
    stats: dict[str, float] = field(default_factory=dict)
    step_reactions: StepReactions = field(default_factory=StepReactions)
    event_t: FloatArray = field(default_factory=lambda: np.empty(0))
    event_y: FloatArray = field(default_factory=lambda: np.empty((0, N_STATE)))
    kernel_code: int | None = None

    def __post_init__(self) -> None:
        if self.kernel_code is None:
            self.kernel_code = self.model.code

    @property
    def _code(self) -> int:
        """:attr:`kernel_code` (which ``__post_init__`` sets: ``model.code`` where not given)."""
        return self.model.code if self.kernel_code is None else self.kernel_code

    @property
    def pole_case(self) -> str | None:
        """``"south"``/``"north"`` when integrated as a meridian pole case (the kernel's variant),
        else ``None``."""
        return kernel_by_code(self._code).variant

    # ---- state components -------------------------------------------------------------------
    @property
    def v(self) -> FloatArray:
        """CoM velocity, body frame, shape (n, 3)."""
        return self.y[:, V]

    @property
    def omega(self) -> FloatArray:
        """Angular velocity, body frame, shape (n, 3)."""
        return self.y[:, W]

    @property
    def alpha(self) -> FloatArray:
        """Fixed ``x`` axis in the body frame, shape (n, 3)."""
        return self.y[:, ALPHA]

    @property
    def beta(self) -> FloatArray:
        """Fixed ``y`` axis in the body frame, shape (n, 3)."""
        return self.y[:, BETA]

    @property
    def gamma(self) -> FloatArray:
        """Upward vertical in the body frame, shape (n, 3)."""
        return self.y[:, GAMMA]

    @property
    def position(self) -> FloatArray:
        """Horizontal CoM position ``(X, Y)`` in the fixed frame, shape (n, 2)."""
        return self.y[:, POSITION]

    @property
    def contact_point(self) -> FloatArray:
        """Contact point on the plane, fixed frame, shape (n, 2).

        ``(X, Y) + ((r, alpha), (r, beta))`` with ``r = -R gamma - a``, i.e.
        ``(X - a3 alpha3, Y - a3 beta3)`` (``docs/model.md``, "Motion in absolute space").
        """
        return self.position - self.body.a3 * np.stack([self.y[:, 8], self.y[:, 11]], axis=-1)

    # ---- measured quantities ----------------------------------------------------------------
    @functools.cached_property
    def model_outputs(self) -> dict[str, FloatArray]:
        """The model's further per-sample quantities
        (:attr:`~rollingtop.contact.ContactModel.state_outputs`; ``shell-rotor``:
        ``shell_omega`` and ``bearing_torque``, shape (n, 3), body frame); empty for the
        others."""
        if self.model.state_outputs is None:
            return {}
        return self.model.state_outputs(self.body, self.y)

    @functools.cached_property
    def integrals(self) -> dict[str, FloatArray]:
        """First integrals of the model and body along the samples, each shape (n,)."""
        names = self.model.integrals_for(self.body)
        return evaluate(self.body, self.y, names, pole=self.pole_case, model=self.model)

    @functools.cached_property
    def _diagnostics(self) -> FloatArray:
        out = np.empty((self.y.shape[0], 4 + MAX_ROWS))
        dynamics = for_code(self._code).dynamics
        call(
            dynamics.diagnostics,
            self._code,
            self.model.params(self.body),
            np.ascontiguousarray(self.y),
            out,
        )
        return out

    @property
    def normal_force(self) -> FloatArray:
        """Normal reaction ``N = (F, gamma)`` at the samples, shape (n,); must stay positive."""
        return self._diagnostics[:, 0]

    @property
    def tangential_force(self) -> FloatArray:
        """Magnitude of the constraint's horizontal force at the samples, shape (n,)."""
        return self._diagnostics[:, 1]

    @property
    def friction_ratio(self) -> FloatArray:
        """Tangential over normal force, shape (n,): the friction coefficient the motion needs."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(
                self.normal_force > 0, self.tangential_force / self.normal_force, np.nan
            )

    @property
    def constraint_residuals(self) -> FloatArray:
        """Residual ``J_k u`` of each constraint row at the samples, shape (n, rows)."""
        return self._diagnostics[:, 4 : 4 + len(self.model.constraints)]

    @property
    def orthonormality_error(self) -> FloatArray:
        """``max |Q Q^T - 1|`` of the frame ``Q = [alpha; beta; gamma]``, shape (n,)."""
        return self._diagnostics[:, 3]

    @property
    def contact_lost_at(self) -> float | None:
        """First time the normal force was negative (steps or samples), else ``None``."""
        times = []
        step_lost = self.step_reactions.get("contact_lost_at")
        if step_lost is not None:
            times.append(step_lost)
        negative = np.flatnonzero(self.normal_force < 0)
        if negative.size:
            times.append(float(self.t[negative[0]]))
        return min(times) if times else None

    # ---- reports ----------------------------------------------------------------------------
    def summary(self) -> dict[str, Any]:
        """Summary as a JSON-ready dict (the output of ``rollingtop simulate --json``).

        Keys: ``model, t_end, final, integrals, constraints, reactions, stats`` (see README).
        Each integral's ``max_rel_drift`` is its largest drift over its natural size (the size
        it can take at the run's speed: :func:`~rollingtop.dynamics.integrals.natural_scales`).
        A run that held its integrals by projection adds ``projection``: ``held`` (every drift
        within ``tolerance``, :data:`~rollingtop.dynamics.integrals.HELD_TOLERANCE`), ``worst``
        (the integral of largest relative drift) and its ``max_rel_drift``.
        """
        last = self.y[-1]
        final = {
            "t": float(self.t[-1]),
            "v": last[V].tolist(),
            "omega": last[W].tolist(),
            "alpha": last[ALPHA].tolist(),
            "beta": last[BETA].tolist(),
            "gamma": last[GAMMA].tolist(),
            "position": last[POSITION].tolist(),
            "contact_point": self.contact_point[-1].tolist(),
        }
        for name, values in self.model_outputs.items():
            final[name] = values[-1].tolist()
        integrals = {}
        scales = natural_scales(
            self.body,
            self.y,
            self.integrals,
            self.pole_case,
            model=self.model,
        )
        for name, values in self.integrals.items():
            drift = float(np.max(np.abs(values - values[0])))
            integrals[name] = {
                "initial": float(values[0]),
                "final": float(values[-1]),
                "max_abs_drift": drift,
                # on the integral's natural size: the size it can take at the run's speed (None
                # where that size is 0, or beyond doubles: no relative drift can be measured)
                "max_rel_drift": (
                    drift / scales[name]
                    if 0 < scales[name] < np.inf and np.isfinite(drift)
                    else None
                ),
            }
        min_normal = min(
            float(np.min(self.normal_force)), self.step_reactions.get("min_normal_force", np.inf)
        )
        ratio = np.nanmax(self.friction_ratio) if np.any(self.normal_force > 0) else np.nan
        max_ratio = max(
            float(ratio) if np.isfinite(ratio) else 0.0,
            self.step_reactions.get("max_friction_ratio", 0.0),
        )
        held = {}
        if "projection_passes" in self.stats:  # a run that claims its integrals held
            # an integral that drifted where no relative drift can be measured is not vouched for
            unmeasured = [
                k
                for k, v in integrals.items()
                if v["max_rel_drift"] is None and v["max_abs_drift"] != 0.0  # NaN: drifted
            ]
            if unmeasured:
                verdict = {"held": False, "worst": unmeasured[0], "max_rel_drift": None}
            else:
                worst = max(integrals, key=lambda k: integrals[k]["max_rel_drift"] or 0.0)
                drift = integrals[worst]["max_rel_drift"] or 0.0
                verdict = {
                    "held": bool(drift <= HELD_TOLERANCE),
                    "worst": worst,
                    "max_rel_drift": drift,
                }
            held = {"projection": {**verdict, "tolerance": HELD_TOLERANCE}}
        return {
            "model": self.model.name,
            **(
                {"contact_parameters": self.model.parameter_values} if self.model.parameters else {}
            ),
            "t_end": float(self.t[-1]),
            "final": final,
            "integrals": integrals,
            "constraints": {
                "max_abs_residual": float(np.max(np.abs(self.constraint_residuals))),
                "orthonormality_max_error": float(np.max(self.orthonormality_error)),
            },
            "reactions": {
                "min_normal_force": finite_or_none(min_normal),
                "max_friction_ratio": finite_or_none(max_ratio),
                "contact_lost_at": self.contact_lost_at,
            },
            "stats": {
                "steps": int(self.stats["steps"]),
                "rejected_steps": int(self.stats["rejected_steps"]),
                "rhs_evals": int(self.stats["rhs_evals"]),
                "wall_time_s": float(self.stats["wall_time_s"]),
                "compile_time_s": float(self.stats.get("compile_time_s", 0.0)),
                **{
                    k: int(self.stats[k])
                    for k in ("projection_passes", "projection_deferred")
                    if k in self.stats
                },
            },
            **held,
        }

    # ---- notebooks ---------------------------------------------------------------------------
    def __repr__(self) -> str:
        return (
            f"<Trajectory: {self.model.name} model, t = {self.t[0]:g} .. {self.t[-1]:g}, "
            f"{len(self.t)} samples>"
        )

    def _repr_html_(self) -> str:
        """The notebook's view of :meth:`summary`: body, motion, each first integral's drift."""
        head = {
            "model": self.model.name,
            "description": self.model.description,
            "samples": len(self.t),
            "rtol": self.rtol,
            "atol": self.atol,
        }
        return trajectory_html(self.summary(), self.body.to_dict(), head)

    def plot(self, ax: Axes | None = None, *, kind: str = "path", **kw: Any) -> Axes:
        """Draw the motion on ``ax`` (default: a new figure's) and return ``ax``: ``kind`` is
        ``"path"`` (the paths on the plane of ``rollingtop path``; ``kw``: ``period_map``), or
        ``"gamma3"``, ``"drift"`` (the first integrals' relative drift), ``"reactions"``: the
        panels of ``rollingtop plot`` (:data:`rollingtop.plot.paths.PANELS`, named in
        :data:`rollingtop._figures.TRAJECTORY_KINDS`)."""
        if kind not in TRAJECTORY_KINDS:
            known = ", ".join(map(repr, TRAJECTORY_KINDS))
            raise RollingTopError(f"kind = {kind!r}: one of {known}")
        axes: Axes = draw(kind, ax, self, **kw)
        return axes

    # ---- export -----------------------------------------------------------------------------
    def _attrs(self) -> dict[str, str | float]:
        attrs: dict[str, str | float] = {f"body_{k}": v for k, v in self.body.to_dict().items()}
        # the model's own parameters (the parallel model's rule at the vertical)
        attrs.update({f"contact_{k}": v for k, v in self.model.parameter_values.items()})
        attrs.update(
            model=self.model.name,
            model_description=self.model.description,
            constraints="; ".join(self.model.constraints),
            rtol=self.rtol,
            atol=self.atol,
            summary_json=json.dumps(self.summary()),
            units_note=(
                "Quantities are in the scenario's own consistent units: L (length, the unit of R), "
                "M (mass, of m), T (time, set by g). Vectors v, omega, alpha, beta, gamma are "
                "body-frame components; position and contact_point are fixed-frame."
            ),
            references=(
                "A. A. Kilin, T. B. Ivanova, Russian Journal of Nonlinear Dynamics 19(1), 2023, "
                "3-17, doi:10.20537/nd221205"
            ),
            source="rollingtop",
        )
        return attrs

    def to_xarray(self) -> xr.Dataset:
        """The samples as an :class:`xarray.Dataset` with units and parameters as attributes."""
        import xarray as xr

        comp = ("1", "2", "3")
        data: dict[str, tuple[str | tuple[str, str], FloatArray]] = {
            "v": (("t", "component"), self.v),
            "omega": (("t", "component"), self.omega),
            "alpha": (("t", "component"), self.alpha),
            "beta": (("t", "component"), self.beta),
            "gamma": (("t", "component"), self.gamma),
            "position": (("t", "plane"), self.position),
            "contact_point": (("t", "plane"), self.contact_point),
            "normal_force": ("t", self.normal_force),
            "tangential_force": ("t", self.tangential_force),
            "constraint_residual": (("t", "constraint"), self.constraint_residuals),
            "orthonormality_error": ("t", self.orthonormality_error),
        }
        for name, values in self.integrals.items():
            data[name] = ("t", values)
        for name, values in self.model_outputs.items():
            data[name] = (("t", "component"), values)
        ds = xr.Dataset(
            data,
            coords={
                "t": self.t,
                "component": list(comp),
                "plane": ["X", "Y"],
                "constraint": list(self.model.constraints),
            },
            attrs=self._attrs(),
        )
        for name, units in TRAJECTORY_UNITS.items():
            if name in ds.variables:
                ds[name].attrs["units"] = units
        ds["t"].attrs["long_name"] = "time"
        return ds

    def _csv_table(self) -> tuple[list[str], FloatArray]:
        cols = ["t"]
        blocks = [self.t[:, None]]
        for name, arr, parts in (
            ("v", self.v, "123"),
            ("omega", self.omega, "123"),
            ("alpha", self.alpha, "123"),
            ("beta", self.beta, "123"),
            ("gamma", self.gamma, "123"),
            ("", self.position, ("X", "Y")),
            ("contact_", self.contact_point, ("x", "y")),
        ):
            cols += [f"{name}{c}" for c in parts]
            blocks.append(arr)
        cols += ["normal_force", "tangential_force", "max_constraint_residual"]
        blocks.append(
            np.stack(
                [
                    self.normal_force,
                    self.tangential_force,
                    np.max(np.abs(self.constraint_residuals), axis=1),
                ],
                axis=1,
            )
        )
        for name, values in self.integrals.items():
            cols.append(name)
            blocks.append(values[:, None])
        for name, values in self.model_outputs.items():  # shell-rotor: shell_omega1..3, ...
            cols += [f"{name}{c}" for c in "123"]
            blocks.append(values)
        return cols, np.hstack(blocks)

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write the samples as CSV (one header row; ``#`` comment lines carry the parameters)."""
        path = check_output_path(path, (".csv",))
        cols, table = self._csv_table()
        header = "\n".join(f"{k} = {v}" for k, v in self._attrs().items() if k != "summary_json")

        text = io.StringIO(newline="")
        for line in header.splitlines():
            text.write(f"# {line}\n")
        text.write(",".join(cols) + "\n")
        np.savetxt(text, table, delimiter=",", fmt="%.17g")
        return write_bytes_atomic(path, text.getvalue().encode("utf-8"))

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write to ``.nc`` (NetCDF) or ``.csv``, chosen by the suffix."""
        path = check_output_path(path, OUTPUT_SUFFIXES)
        return self.to_netcdf(path) if path.suffix.lower() == ".nc" else self.to_csv(path)
