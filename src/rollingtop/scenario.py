"""Scenario files (TOML): parsing and validation.

A scenario names a body, a contact model, initial conditions and integration options::

    [body]        R, m, g, a3, I1, I3, optional I2
    [contact]     model = "meridian" | "smooth" | "rough"        (default "meridian")
    [initial]     gamma, omega, optional alpha, position, and the model's free velocity
                  components (meridian: v_tau; smooth: v_horizontal = [vx, vy]) or a full v
    [integration] t_end, rtol, atol, samples, max_steps            (defaults: DEFAULTS)
    [level]       M3, C1, C2 and optionally h, gamma3, branch, phi, psi: a level set of the
                  meridian model's integrals (paper Sec. 3). With h and no [initial], the
                  initial state is built on that level (``reduction.state_from_level``)

Unknown tables and keys are errors, so that a typo never silently falls back to a default.
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from rollingtop._errors import RollingTopError, ScenarioError
from rollingtop.body import SphericalTop
from rollingtop.contact import ContactModel, get_model
from rollingtop.dynamics.state import initial_state

__all__ = [
    "DEFAULTS",
    "InitialConditions",
    "IntegrationOptions",
    "LevelSpec",
    "Scenario",
    "load_scenario",
]

#: Integration defaults. ``atol`` defaults to ``rtol / 100`` when not given.
DEFAULTS = {"t_end": 10.0, "rtol": 1e-10, "atol": None, "samples": 1001, "max_steps": 10**8}
DEFAULT_MODEL = "meridian"

_BODY_KEYS = ("R", "m", "g", "a3", "I1", "I3", "I2")
_INITIAL_KEYS = ("gamma", "omega", "alpha", "position", "v")
_LEVEL_KEYS = ("M3", "C1", "C2", "h", "gamma3", "branch", "phi", "psi")


def _number(where: str, key: str, value: Any, *, integer: bool = False) -> float | int:
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "an integer" if integer else "a number"
        raise ScenarioError(f"{where}.{key} = {value!r} must be {kind}")
    if integer:
        if isinstance(value, float):
            if not value.is_integer():
                raise ScenarioError(f"{where}.{key} = {value!r} must be an integer")
            value = int(value)
        return value
    if not math.isfinite(value):
        raise ScenarioError(f"{where}.{key} = {value!r} must be finite")
    return float(value)


@dataclass(frozen=True)
class IntegrationOptions:
    """Validated integration options.

    Attributes
    ----------
    t_end : float
        End time (> 0); the motion starts at t = 0.
    rtol : float
        Relative tolerance of the error control, ``1e-15 <= rtol <= 0.1``.
    atol : float or None
        Absolute tolerance, ``> 0``; ``None`` means ``rtol / 100`` (:attr:`resolved_atol`).
    samples : int
        Number of equally spaced samples in ``[0, t_end]``, >= 2.
    max_steps : int
        Bound on accepted steps.
    """

    t_end: float = DEFAULTS["t_end"]
    rtol: float = DEFAULTS["rtol"]
    atol: float | None = None
    samples: int = DEFAULTS["samples"]
    max_steps: int = DEFAULTS["max_steps"]

    def __post_init__(self) -> None:
        w = "integration"
        t_end = _number(w, "t_end", self.t_end)
        rtol = _number(w, "rtol", self.rtol)
        atol = rtol / 100 if self.atol is None else _number(w, "atol", self.atol)
        samples = _number(w, "samples", self.samples, integer=True)
        max_steps = _number(w, "max_steps", self.max_steps, integer=True)
        if t_end <= 0:
            raise ScenarioError(f"integration.t_end = {t_end:g} must be > 0")
        if not 1e-15 <= rtol <= 0.1:
            raise ScenarioError(f"integration.rtol = {rtol:g} must lie in [1e-15, 0.1]")
        if atol <= 0:
            raise ScenarioError(f"integration.atol = {atol:g} must be > 0")
        if samples < 2:
            raise ScenarioError(f"integration.samples = {samples} must be >= 2")
        if max_steps < 1:
            raise ScenarioError(f"integration.max_steps = {max_steps} must be >= 1")
        for k, val in (
            ("t_end", t_end),
            ("rtol", rtol),
            ("samples", samples),
            ("max_steps", max_steps),
        ):
            object.__setattr__(self, k, val)
        if self.atol is not None:
            object.__setattr__(self, "atol", atol)

    @property
    def resolved_atol(self) -> float:
        """``atol`` as given, else ``rtol / 100``."""
        return self.rtol / 100 if self.atol is None else self.atol

    @property
    def t_eval(self) -> np.ndarray:
        """Sample times ``linspace(0, t_end, samples)``, shape (samples,)."""
        return np.linspace(0.0, self.t_end, self.samples)


@dataclass(frozen=True)
class InitialConditions:
    """Initial conditions as given by the user (see :func:`rollingtop.initial_state`)."""

    gamma: tuple
    omega: tuple
    alpha: tuple | None = None
    position: tuple = (0.0, 0.0)
    v: tuple | None = None
    free: dict = field(default_factory=dict)

    @classmethod
    def from_state(cls, y) -> InitialConditions:
        """The initial conditions that rebuild the state ``y`` (full velocity given)."""
        y = np.asarray(y, dtype=float)
        return cls(gamma=tuple(y[12:15]), omega=tuple(y[3:6]), alpha=tuple(y[6:9]),
                   position=tuple(y[15:17]), v=tuple(y[0:3]))  # fmt: skip

    def state(self, body: SphericalTop, model: ContactModel) -> np.ndarray:
        """The constraint-consistent state vector, shape (18,)."""
        return initial_state(
            body,
            model,
            gamma=self.gamma,
            omega=self.omega,
            alpha=self.alpha,
            position=self.position,
            v=self.v,
            free=self.free,
        )


@dataclass(frozen=True)
class LevelSpec:
    """A level set of the meridian model's integrals, as given in a ``[level]`` table.

    ``M3, C1, C2`` (Lagrange, area, F6) fix the level set; ``h`` (reduced energy
    ``E - I3 w3^2/2 - m g R``) an orbit on it. ``gamma3`` (default: the first orbit's lowest
    turning point, or its other one when the lowest lies beyond a pole passage),
    ``branch`` (sign of ``w_tau``, default +1), ``phi`` and ``psi`` (Euler angles, default 0)
    place the initial state when the scenario has no ``[initial]`` table.
    """

    M3: float
    C1: float
    C2: float
    h: float | None = None
    gamma3: float | None = None
    branch: int = 1
    phi: float = 0.0
    psi: float = 0.0

    def __post_init__(self) -> None:
        for key in ("M3", "C1", "C2", "h", "gamma3", "phi", "psi"):
            value = getattr(self, key)
            if value is not None:
                object.__setattr__(self, key, _number("level", key, value))
        if self.branch not in (1, -1) or isinstance(self.branch, bool):
            raise ScenarioError(f"level.branch = {self.branch!r} must be +1 or -1")


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: body, contact model, initial conditions, integration options and
    optionally a level set of the integrals.

    Construction checks the initial conditions against the model (so a scenario that loads can
    be simulated); :attr:`y0` is the constraint-consistent initial state, built from
    ``initial``, else from ``level`` (with ``h``), else ``None`` (such a scenario serves the
    reduction commands only).
    """

    body: SphericalTop
    model: ContactModel
    initial: InitialConditions | None
    integration: IntegrationOptions = field(default_factory=IntegrationOptions)
    source: str | None = None
    level: LevelSpec | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "model", get_model(self.model))
        if self.initial is not None:
            y0 = self.initial.state(self.body, self.model)
        elif self.level is not None and self.level.h is not None:
            y0 = self._state_on_level()
        else:
            y0 = None
        object.__setattr__(self, "y0", y0)

    def _require_meridian(self, what: str) -> None:
        if self.model.name != "meridian":
            raise ScenarioError(
                f"{what} needs the meridian model (the reduction is the paper's), "
                f"not {self.model.name!r}"
            )

    def _state_on_level(self):
        from rollingtop.reduction import orbits, state_from_level

        self._require_meridian("an initial state built from [level]")
        level = self.level_set()
        spec = self.level
        gamma3 = spec.gamma3
        if gamma3 is None:  # a turning point of the first orbit, on the branch 0 < theta < pi
            orbit = orbits(level, spec.h)[0]
            theta = orbit.theta_max if 0 < orbit.theta_max < math.pi else orbit.theta_min
            gamma3 = math.cos(theta)
        return state_from_level(level, spec.h, gamma3, branch=spec.branch, phi=spec.phi,
                                psi=spec.psi)  # fmt: skip

    def require_state(self):
        """The initial state, or a :class:`ScenarioError` saying how to give one."""
        if self.y0 is None:
            raise ScenarioError(
                "the scenario has no initial state: give an [initial] table, or h in [level]"
            )
        return self.y0

    def level_set(self):
        """The :class:`~rollingtop.reduction.LevelSet` of ``[level]``, else of the initial state."""
        from rollingtop.reduction import LevelSet, reduced_integrals

        self._require_meridian("the reduction to one degree of freedom")
        if self.level is not None:
            return LevelSet(self.body, self.level.M3, self.level.C1, self.level.C2)
        ints = reduced_integrals(self.body, self.require_state())
        return LevelSet(self.body, float(ints["M3"]), float(ints["C1"]), float(ints["C2"]))

    def level_h(self) -> float:
        """The reduced energy ``h`` of ``[level]``, else of the initial state."""
        from rollingtop.reduction import reduced_integrals

        if self.level is not None and self.level.h is not None:
            return self.level.h
        if self.level is not None and self.initial is None:
            raise ScenarioError("no h: give h in [level] (or --h)")
        return float(reduced_integrals(self.body, self.require_state())["h"])

    def with_overrides(self, **overrides) -> Scenario:
        """A copy with integration options (``t_end, rtol, atol, samples, max_steps``) or the
        contact ``model`` replaced. ``None`` values are ignored."""
        overrides = {k: v for k, v in overrides.items() if v is not None}
        allowed = set(DEFAULTS) | {"model"}
        unknown = sorted(set(overrides) - allowed)
        if unknown:
            raise ScenarioError(
                f"unknown override {', '.join(unknown)} (allowed: {', '.join(sorted(allowed))})"
            )
        model = overrides.pop("model", self.model)
        integration = replace(self.integration, **overrides) if overrides else self.integration
        return Scenario(self.body, get_model(model), self.initial, integration, self.source,
                        self.level)  # fmt: skip

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> Scenario:
        """Build from the parsed TOML structure (see the module docstring)."""
        allowed_tables = ("body", "contact", "initial", "integration", "level")
        for key, value in data.items():
            if key not in allowed_tables:
                raise ScenarioError(f"unknown table [{key}] (allowed: {', '.join(allowed_tables)})")
            if not isinstance(value, dict):
                raise ScenarioError(f"[{key}] must be a table")
        if "body" not in data:
            raise ScenarioError("missing table [body]")
        if "initial" not in data and "level" not in data:
            raise ScenarioError("missing table [initial] (or [level])")

        body_t = data["body"]
        _reject_unknown("body", body_t, _BODY_KEYS)
        missing = [k for k in _BODY_KEYS[:-1] if k not in body_t]
        if missing:
            raise ScenarioError(f"[body] is missing {', '.join(missing)}")
        body = SphericalTop(**{k: body_t[k] for k in _BODY_KEYS if k in body_t})

        contact_t = data.get("contact", {})
        _reject_unknown("contact", contact_t, ("model",))
        model = get_model(contact_t.get("model", DEFAULT_MODEL))

        level = None
        if "level" in data:
            level_t = data["level"]
            _reject_unknown("level", level_t, _LEVEL_KEYS)
            missing = [k for k in ("M3", "C1", "C2") if k not in level_t]
            if missing:
                raise ScenarioError(f"[level] is missing {', '.join(missing)}")
            level = LevelSpec(**level_t)
        integ_t = data.get("integration", {})
        _reject_unknown("integration", integ_t, tuple(DEFAULTS))
        integration = IntegrationOptions(**integ_t)
        if "initial" not in data:
            return cls(body, model, None, integration, source, level)

        init_t = dict(data["initial"])
        free_keys = tuple(model.free_velocity)
        for key in init_t:
            if key not in _INITIAL_KEYS + free_keys:
                raise ScenarioError(
                    f"unknown key initial.{key} for model {model.name!r} (allowed: "
                    f"{', '.join(_INITIAL_KEYS + free_keys)})"
                )
        for required in ("gamma", "omega"):
            if required not in init_t:
                raise ScenarioError(f"[initial] is missing {required}")
        initial = InitialConditions(
            gamma=init_t["gamma"],
            omega=init_t["omega"],
            alpha=init_t.get("alpha"),
            position=init_t.get("position", (0.0, 0.0)),
            v=init_t.get("v"),
            free={k: init_t[k] for k in free_keys if k in init_t},
        )
        return cls(body, model, initial, integration, source, level)


def _reject_unknown(table: str, values: dict, allowed: tuple[str, ...]) -> None:
    for key in values:
        if key not in allowed:
            raise ScenarioError(f"unknown key {table}.{key} (allowed: {', '.join(allowed)})")


def load_scenario(path: str | os.PathLike) -> Scenario:
    """Read and validate a TOML scenario file.

    Raises
    ------
    ScenarioError
        Unreadable file, invalid TOML, unknown table or key, missing or ill-typed value.
    RollingTopError
        Any other inadmissible content (body, model, initial conditions), with the file named.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario {str(path)!r}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"cannot read scenario {str(path)!r}: not UTF-8 text") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: invalid TOML: {exc}") from None
    try:
        return Scenario.from_dict(data, source=str(path))
    except RollingTopError as exc:
        raise type(exc)(f"{path}: {exc}") from None
