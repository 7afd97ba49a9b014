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
Scenario files are read only when they are regular files of at most :data:`MAX_SCENARIO_BYTES`
(1 MiB) of UTF-8 text without a byte-order mark (a BOM is refused, saying so). Quoted values are
cut to 80 characters in messages. ``samples`` is bounded so that a run's samples fit in
:func:`memory_limit` (8 GiB, or half the physical memory if less), ``max_steps`` by ``2**62``.
"""

from __future__ import annotations

import math
import os
import re
import sys
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from rollingtop._errors import ContactModelError, RollingTopError, ScenarioError
from rollingtop.body import SphericalTop
from rollingtop.contact import MODELS, ContactModel, get_model
from rollingtop.dynamics.state import initial_state
from rollingtop.io import format_bytes, read_input_text

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
_VECTOR_LENGTHS = {"gamma": 3, "omega": 3, "alpha": 3, "position": 2, "v": 3}
_LEVEL_KEYS = ("M3", "C1", "C2", "h", "gamma3", "branch", "phi", "psi")

#: Largest scenario file read (bytes).
MAX_SCENARIO_BYTES = 1 << 20
#: Largest ``max_steps`` (the integrator's own "no limit").
MAX_STEPS_LIMIT = 2**62
#: Rough memory of one output sample of a single run (state, diagnostics, integrals, the
#: dataset and its serialised file), used to refuse ``samples`` that cannot fit.
BYTES_PER_SAMPLE = 1024
#: Cap on the memory a run may plan for, before the physical-memory bound.
MEMORY_CAP_BYTES = 8 << 30

_QUOTE_CHARS = 80


def short_repr(value: Any, limit: int = _QUOTE_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters (with an ellipsis), for error messages."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 4 * limit:
        try:
            return f"<integer of {len(str(abs(value)))} digits>"
        except ValueError:  # longer than Python converts to text
            return f"<integer of about {int(value.bit_length() * 0.30103)} digits>"
    if isinstance(value, str) and len(value) > limit:
        return repr(value[: limit - 3] + "…")
    if isinstance(value, list | tuple | dict) and len(value) > limit:
        return f"<{type(value).__name__} of {len(value)} items>"
    try:
        text = repr(value)
    except (RecursionError, ValueError):
        return f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 1] + "…"


def short_name(key: str, limit: int = _QUOTE_CHARS) -> str:
    """A TOML key for a message: bare keys as they are, others quoted; cut to ``limit``."""
    key = str(key)
    if not re.fullmatch(r"[A-Za-z0-9_-]+", key):
        return short_repr(key, limit)
    return key if len(key) <= limit else key[: limit - 1] + "…"


def memory_limit() -> int:
    """Bytes a run may plan to allocate: :data:`MEMORY_CAP_BYTES` (8 GiB), or half the physical
    memory when that is less."""
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return MEMORY_CAP_BYTES
    return min(MEMORY_CAP_BYTES, physical // 2) if physical > 0 else MEMORY_CAP_BYTES


def check_memory(what: str, needed: float) -> None:
    """Refuse (``ScenarioError``) when ``needed`` bytes exceed :func:`memory_limit`."""
    limit = memory_limit()
    if needed > limit:
        raise ScenarioError(
            f"{what} needs about {format_bytes(needed)} of memory, more than the "
            f"{format_bytes(limit)} a run may use (the lesser of 8 GiB and half the physical "
            "memory)"
        )


def _number(where: str, key: str, value: Any, *, integer: bool = False) -> float | int:
    if isinstance(value, bool) or not isinstance(value, int | float):
        kind = "an integer" if integer else "a number"
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be {kind}")
    if integer:
        if isinstance(value, float):
            if not value.is_integer():
                raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be an integer")
            value = int(value)
        return value
    try:
        x = float(value)
    except OverflowError:
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} is too large") from None
    if not math.isfinite(x):
        raise ScenarioError(f"{where}.{key} = {short_repr(value)} must be finite")
    return x


def _vector(where: str, key: str, value: Any, length: int) -> tuple[float, ...]:
    """A list of ``length`` finite real numbers (no strings, booleans or tables in it)."""
    if not isinstance(value, list | tuple) or len(value) != length:
        raise ScenarioError(
            f"{where}.{key} = {short_repr(value)} must be a list of {length} numbers"
        )
    return tuple(_number(where, f"{key}[{i}]", x) for i, x in enumerate(value))


def check_model_name(where: str, name: Any) -> str:
    """``name`` if it names a contact model, else a ``ScenarioError`` quoting it (shortened)."""
    if not isinstance(name, str) or name not in MODELS:
        raise ContactModelError(
            f"{where}: unknown contact model {short_repr(name)} (known: {', '.join(MODELS)})"
        )
    return name


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
            raise ScenarioError(f"integration.samples = {short_repr(samples)} must be >= 2")
        check_memory(f"integration.samples = {short_repr(samples)}", samples * BYTES_PER_SAMPLE)
        if not 1 <= max_steps <= MAX_STEPS_LIMIT:
            raise ScenarioError(
                f"integration.max_steps = {short_repr(max_steps)} must lie in [1, 2**62]"
            )
        step = t_end / (samples - 1)
        if step < sys.float_info.min or step <= 4 * math.ulp(t_end):
            raise ScenarioError(
                f"integration.t_end = {t_end:g} is too small for {samples} samples (their "
                "spacing is not representable)"
            )
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
        if isinstance(self.branch, bool) or not isinstance(self.branch, int | float):
            raise ScenarioError(f"level.branch = {short_repr(self.branch)} must be +1 or -1")
        if self.branch not in (1, -1):
            raise ScenarioError(f"level.branch = {short_repr(self.branch)} must be +1 or -1")
        object.__setattr__(self, "branch", int(self.branch))


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
        y = self.require_state()
        ints = reduced_integrals(self.body, y)
        scale = float(np.linalg.norm(self.body.inertia * y[3:6]))  # round-off scale of M3, C1
        return LevelSet(self.body, float(ints["M3"]), float(ints["C1"]), float(ints["C2"]),
                        scale=scale)  # fmt: skip

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
        if not isinstance(model, ContactModel):
            model = check_model_name("model", model)
        integration = replace(self.integration, **overrides) if overrides else self.integration
        return Scenario(self.body, get_model(model), self.initial, integration, self.source,
                        self.level)  # fmt: skip

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> Scenario:
        """Build from the parsed TOML structure (see the module docstring)."""
        allowed_tables = ("body", "contact", "initial", "integration", "level")
        for key, value in data.items():
            if key not in allowed_tables:
                raise ScenarioError(
                    f"unknown table [{short_name(key)}] (allowed: {', '.join(allowed_tables)})"
                )
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
        body = SphericalTop(**{k: _number("body", k, body_t[k]) for k in _BODY_KEYS
                               if k in body_t})  # fmt: skip

        contact_t = data.get("contact", {})
        _reject_unknown("contact", contact_t, ("model",))
        model = get_model(check_model_name("contact.model", contact_t.get("model", DEFAULT_MODEL)))

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
                    f"unknown key initial.{short_name(key)} for model {model.name!r} "
                    f"(allowed: {', '.join(_INITIAL_KEYS + free_keys)})"
                )
        for required in ("gamma", "omega"):
            if required not in init_t:
                raise ScenarioError(f"[initial] is missing {required}")
        for key, value in init_t.items():
            length = _VECTOR_LENGTHS.get(key, model.free_velocity.get(key))
            if length == 1:
                init_t[key] = _number("initial", key, value)
            else:
                init_t[key] = _vector("initial", key, value, length)
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
            raise ScenarioError(
                f"unknown key {table}.{short_name(key)} (allowed: {', '.join(allowed)})"
            )


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
    text = read_input_text(path, "scenario", MAX_SCENARIO_BYTES, ScenarioError)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: invalid TOML: {exc}") from None
    except RecursionError:
        raise ScenarioError(f"{path}: invalid TOML: arrays or tables nested too deeply") from None
    except ValueError:  # an integer beyond Python's limit on converting digits (4300)
        raise ScenarioError(f"{path}: invalid TOML: an integer with too many digits") from None
    try:
        return Scenario.from_dict(data, source=str(path))
    except RollingTopError as exc:
        raise type(exc)(f"{path}: {exc}") from None
