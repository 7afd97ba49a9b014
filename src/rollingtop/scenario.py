"""Scenario files (TOML): parsing and validation.

A scenario names a body, a contact model, initial conditions and integration options::

    [body]        R, m, g, a3, I1, I3, optional I2
    [contact]     model = "meridian" | "smooth" | "rough"        (default "meridian")
    [initial]     gamma, omega, optional alpha, position, and the model's free velocity
                  components (meridian: v_tau; smooth: v_horizontal = [vx, vy]) or a full v
    [integration] t_end, rtol, atol, samples, max_steps            (defaults: DEFAULTS)

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

__all__ = ["Scenario", "InitialConditions", "IntegrationOptions", "load_scenario", "DEFAULTS"]

#: Integration defaults. ``atol`` defaults to ``rtol / 100`` when not given.
DEFAULTS = {"t_end": 10.0, "rtol": 1e-10, "atol": None, "samples": 1001, "max_steps": 10**8}
DEFAULT_MODEL = "meridian"

_BODY_KEYS = ("R", "m", "g", "a3", "I1", "I3", "I2")
_INITIAL_KEYS = ("gamma", "omega", "alpha", "position", "v")


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

    def state(self, body: SphericalTop, model: ContactModel) -> np.ndarray:
        """The constraint-consistent state vector, shape (17,)."""
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
class Scenario:
    """A validated scenario: body, contact model, initial conditions, integration options.

    Construction checks the initial conditions against the model (so a scenario that loads can
    be simulated); :attr:`y0` is the constraint-consistent initial state.
    """

    body: SphericalTop
    model: ContactModel
    initial: InitialConditions
    integration: IntegrationOptions = field(default_factory=IntegrationOptions)
    source: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "model", get_model(self.model))
        object.__setattr__(self, "y0", self.initial.state(self.body, self.model))

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
        return Scenario(self.body, get_model(model), self.initial, integration, self.source)

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> Scenario:
        """Build from the parsed TOML structure (see the module docstring)."""
        allowed_tables = ("body", "contact", "initial", "integration")
        for key, value in data.items():
            if key not in allowed_tables:
                raise ScenarioError(f"unknown table [{key}] (allowed: {', '.join(allowed_tables)})")
            if not isinstance(value, dict):
                raise ScenarioError(f"[{key}] must be a table")
        for required in ("body", "initial"):
            if required not in data:
                raise ScenarioError(f"missing table [{required}]")

        body_t = data["body"]
        _reject_unknown("body", body_t, _BODY_KEYS)
        missing = [k for k in _BODY_KEYS[:-1] if k not in body_t]
        if missing:
            raise ScenarioError(f"[body] is missing {', '.join(missing)}")
        body = SphericalTop(**{k: body_t[k] for k in _BODY_KEYS if k in body_t})

        contact_t = data.get("contact", {})
        _reject_unknown("contact", contact_t, ("model",))
        model = get_model(contact_t.get("model", DEFAULT_MODEL))

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
        integ_t = data.get("integration", {})
        _reject_unknown("integration", integ_t, tuple(DEFAULTS))
        integration = IntegrationOptions(**integ_t)
        return cls(body, model, initial, integration, source)


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
