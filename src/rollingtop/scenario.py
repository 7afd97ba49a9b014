"""Scenario files (TOML): parsing and validation, nothing else.

A scenario names a body, a contact model, initial conditions and integration options::

    [body]        R, m, g, a3, I1, I3, optional I2
    [contact]     model = the name of a registered contact model (rollingtop.contact.MODELS;
                  default DEFAULT_MODEL), and the model's own parameters
                  (ContactModel.parameters: parallel's pole_disk, relax, pass_relax;
                  oblique's angle and the same three)
    [shell]       mass, inertia: the spherical shell around the body, for a model with its
                  own inertia (ContactModel.own_inertia: shell-rotor, where it is required;
                  other models refuse it)
    [initial]     gamma, omega, optional alpha, position, and the model's free velocity
                  components (ContactModel.free_velocity) or a full v
    [integration] t_end, rtol, atol, samples, max_steps            (defaults: DEFAULTS)
    [level]       the integrals of the model's reduction (ContactModel.reduction: M3, C1, C2
                  for the meridian model, M3, C1, p_horizontal for the smooth one; C2 and
                  p_horizontal may be left out) and optionally h, gamma3,
                  branch, phi, psi (rollingtop.reduction.models; paper Sec. 3). With h and no
                  [initial], the initial state is built on that level
                  (rollingtop.reduction.start.start_on_level)

:func:`load_scenario` reads a file into a :class:`Scenario` of typed objects: the
:class:`~rollingtop.SphericalTop`, the :class:`~rollingtop.contact.ContactModel`, the
:class:`~rollingtop.dynamics.start.InitialConditions` and their state, the
:class:`~rollingtop.integrate.options.IntegrationOptions`. The numerics live where their words
do (:mod:`rollingtop.dynamics`, :mod:`rollingtop.reduction`); this module only calls them.

Unknown tables and keys are errors, so that a typo never silently falls back to a default.
Scenario files are read only when they are regular files of at most :data:`MAX_SCENARIO_BYTES`
(1 MiB) of UTF-8 text without a byte-order mark (a BOM is refused, saying so). Quoted values are
cut to 80 characters in messages. ``samples`` is bounded so that a run's samples fit in
:func:`memory_limit` (8 GiB, or half the physical memory if less), ``max_steps`` by ``2**62``.
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from rollingtop._checks import (
    MEMORY_CAP_BYTES,
    check_memory,
    memory_limit,
    number,
    short_name,
    short_repr,
    vector,
)
from rollingtop._errors import ContactModelError, RollingTopError, ScenarioError
from rollingtop.body import SphericalTop
from rollingtop.contact import DEFAULT_MODEL, MODELS, ContactModel, get_model
from rollingtop.dynamics.start import InitialConditions
from rollingtop.integrate.options import (
    BYTES_PER_SAMPLE,
    DEFAULTS,
    MAX_STEPS_LIMIT,
    IntegrationOptions,
)
from rollingtop.io import read_input_text
from rollingtop.scenario_level import LevelSpec, level_from_table

if TYPE_CHECKING:  # the reduction (and scipy.optimize) is imported where a level is needed
    from rollingtop.reduction.level import Level

    pass

__all__ = [
    "BYTES_PER_SAMPLE",
    "DEFAULTS",
    "MAX_SCENARIO_BYTES",
    "MAX_STEPS_LIMIT",
    "MEMORY_CAP_BYTES",
    "DEFAULT_MODEL",
    "InitialConditions",
    "IntegrationOptions",
    "LevelSpec",
    "Scenario",
    "check_memory",
    "check_model_name",
    "load_scenario",
    "memory_limit",
    "short_name",
    "short_repr",
]

#: The contact model of a scenario without a ``[contact]`` table (the paper's).

_BODY_KEYS = ("R", "m", "g", "a3", "I1", "I3", "I2")
_INITIAL_KEYS = ("gamma", "omega", "alpha", "position", "v")
_VECTOR_LENGTHS = {"gamma": 3, "omega": 3, "alpha": 3, "position": 2, "v": 3}

#: Largest scenario file read (bytes).
MAX_SCENARIO_BYTES = 1 << 20


def check_model_name(where: str, name: object) -> str:
    """``name`` if it names a contact model, else a ``ContactModelError`` quoting it
    (shortened) and listing the registered models."""
    if not isinstance(name, str) or name not in MODELS:
        raise ContactModelError(
            f"{where}: unknown contact model {short_repr(name)} (known: {', '.join(MODELS)})"
        )
    return name


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: body, contact model, initial conditions, integration options and
    optionally a level set of the integrals.

    Construction checks the initial conditions against the model (so a scenario that loads can
    be simulated); :attr:`y0` is the constraint-consistent initial state, built from
    ``initial`` (:meth:`InitialConditions.state`), else from ``level`` with ``h``
    (:func:`~rollingtop.reduction.start.start_on_level`), else ``None`` (such a scenario serves
    the reduction commands only). ``model`` may be given by name.
    """

    body: SphericalTop
    model: ContactModel
    initial: InitialConditions | None
    integration: IntegrationOptions = field(default_factory=IntegrationOptions)
    source: str | None = None
    level: LevelSpec | None = None
    y0: NDArray[np.float64] | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "model", get_model(self.model))
        try:
            object.__setattr__(self, "body", self.model.body_for(self.body))
        except ValueError as err:
            raise ScenarioError(str(err)) from None
        y0 = None
        spec = self.level
        if self.initial is not None:
            y0 = self.initial.state(self.body, self.model)
        elif spec is not None and spec.h is not None:
            self._require_reduction("an initial state built from [level]")
            from rollingtop.reduction.start import start_on_level

            y0 = start_on_level(
                spec.level_set(self.body, self.model),
                spec.h,
                gamma3=spec.gamma3,
                branch=spec.branch,
                phi=spec.phi,
                psi=spec.psi,
            )
        object.__setattr__(self, "y0", y0)

    def _require_reduction(self, what: str) -> None:
        """A :class:`ScenarioError` for ``what`` unless the model has a reduction
        (:func:`rollingtop.reduction.models.reduction_of`)."""
        if not self.model.reduction:
            from rollingtop.reduction.models import reduction_of

            reduction_of(self.model)  # its ScenarioError says what the model has instead

    def _require_full_reduction(self, what: str) -> None:
        """A :class:`ScenarioError` for ``what`` unless the whole of the paper's reduction
        applies (:attr:`rollingtop.reduction.Reduction.closed_form_diagram`: the bifurcation
        diagrams, rotation numbers,
        atlas)."""
        from rollingtop.reduction.models import closed_form_diagram

        if not closed_form_diagram(self.model):
            self._require_reduction(what)  # no reduction at all: what serves such a model
            names = " or ".join(m for m in MODELS if closed_form_diagram(m))
            reduced = ", ".join(m.name for m in MODELS.values() if m.reduction)
            raise ScenarioError(
                f"{what} needs the {names} model so far, not {self.model.name!r} (every model "
                f"with a reduction, {reduced}, has equilibria, orbits, portrait, bifurcation "
                "and compare-classification)"
            )

    def require_state(self) -> NDArray[np.float64]:
        """The initial state, or a :class:`ScenarioError` saying how to give one."""
        if self.y0 is None:
            raise ScenarioError(
                "the scenario has no initial state: give an [initial] table, or h in [level]"
            )
        return self.y0

    def level_set(self) -> Level:
        """The :class:`~rollingtop.reduction.LevelSet` of ``[level]``, else of the initial state
        (:meth:`rollingtop.reduction.models.Reduction.level_of_state`), under the model's
        reduction."""
        self._require_reduction("the reduction to one degree of freedom")
        if self.level is not None:
            return self.level.level_set(self.body, self.model)
        from rollingtop.reduction.models import reduction_of

        return reduction_of(self.model).level_of_state(self.body, self.require_state())

    def level_integrals(self, what: str = "this command") -> tuple[float, float, float | None]:
        """``(M3, C1, C2)`` of ``[level]`` (``C2`` may be absent: ``None``), else of the initial
        state: the paper's level, for the commands that need its whole reduction
        (:meth:`_require_full_reduction`)."""
        self._require_full_reduction(what)
        if self.level is not None:
            M3, C1 = self.level.M3, self.level.C1
            assert M3 is not None and C1 is not None  # the meridian model's [level] has them
            return M3, C1, self.level.C2
        values = self.level_set().values()
        return values["M3"], values["C1"], values["C2"]

    def level_h(self) -> float:
        """The reduced energy ``h`` of ``[level]``, else of the initial state
        (:meth:`rollingtop.reduction.models.Reduction.reduced_energy`)."""
        if self.level is not None and self.level.h is not None:
            return self.level.h
        if self.level is not None and self.initial is None:
            raise ScenarioError("no h: give h in [level] (or --h)")
        self._require_reduction("the reduced energy")
        from rollingtop.reduction.models import reduction_of

        return reduction_of(self.model).reduced_energy(self.body, self.require_state())

    def level_summary(self) -> dict[str, Any] | None:
        """The level of the scenario's motion and the energy it implies, where the model has
        the reduction, the body is dynamically symmetric and there is a motion; else ``None``.

        Returns
        -------
        dict or None
            ``None`` also where the model's reduction refuses the level (the shell-rotor pair's
            levels through both poles with spin): the run needs no reduction. Otherwise ``M3,
            C1, C2, h``
            (:meth:`level_integrals`, :meth:`level_h`), ``energy = h +
            spin_energy + mgR`` (:func:`~rollingtop.reduction.start.level_energy`), ``source``
            (``"[level]"`` where it gives ``h``, else ``"initial state"``).
        """
        if not (self.model.reduction and self.body.symmetric) or self.y0 is None:
            return None
        from rollingtop.reduction.level import LevelSetError

        try:  # a level the reduction refuses (spin through both poles): not shown; the run stands
            level = self.level_set()
            values = level.values()
            h = self.level_h()
        except LevelSetError:
            return None
        given = self.level is not None and self.level.h is not None
        body = self.body
        M3 = values.get("M3")
        return {
            **values,
            "C2": values.get("C2"),
            "h": h,
            "energy": level.full_energy(h),
            "energy_formula": level.energy_formula,
            "spin_energy": None if M3 is None else M3 * M3 / (2.0 * body.I3),
            "mgR": body.m * body.g * body.R,
            "source": "[level]" if given else "initial state",
        }

    def with_overrides(self, **overrides: Any) -> Scenario:
        """A copy with integration options (``t_end, rtol, atol, samples, max_steps``) or the
        contact ``model`` (a name or a :class:`ContactModel`) replaced. ``None`` values are
        ignored."""
        given = {k: v for k, v in overrides.items() if v is not None}
        allowed = set(DEFAULTS) | {"model"}
        unknown = sorted(set(given) - allowed)
        if unknown:
            raise ScenarioError(
                f"unknown override {', '.join(unknown)} (allowed: {', '.join(sorted(allowed))})"
            )
        model = given.pop("model", self.model)
        if not isinstance(model, ContactModel):
            model = get_model(check_model_name("model", model))
            if model.name == self.model.name:  # the scenario's own, with its [contact] values
                model = self.model
        integration = replace(self.integration, **given) if given else self.integration
        return Scenario(self.body, model, self.initial, integration, self.source, self.level)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str | None = None) -> Scenario:
        """Build from the parsed TOML structure (see the module docstring): check every
        table and key, then build the typed objects."""
        allowed_tables = ("body", "contact", "shell", "initial", "integration", "level")
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
        body = SphericalTop(**{k: number("body", k, body_t[k]) for k in _BODY_KEYS if k in body_t})

        contact_t = data.get("contact", {})
        model = get_model(check_model_name("contact.model", contact_t.get("model", DEFAULT_MODEL)))
        own = tuple(r.name for r in model.parameters)
        _reject_unknown("contact", contact_t, ("model", *own))
        if any(k in contact_t for k in own):
            model = model.with_parameters(**{k: contact_t[k] for k in own if k in contact_t})
        body = _with_shell(body, model, data.get("shell"))

        level: LevelSpec | None = None
        if "level" in data:
            level = level_from_table(data["level"], model)
        integ_t = data.get("integration", {})
        _reject_unknown("integration", integ_t, tuple(DEFAULTS))
        integration = IntegrationOptions(**integ_t)
        if "initial" not in data:
            return cls(body, model, None, integration, source, level)

        init_t: dict[str, Any] = dict(data["initial"])
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
                init_t[key] = number("initial", key, value)
            else:
                assert length is not None  # every allowed key has a length
                init_t[key] = vector("initial", key, value, length)
        initial = InitialConditions(
            gamma=init_t["gamma"],
            omega=init_t["omega"],
            alpha=init_t.get("alpha"),
            position=init_t.get("position", (0.0, 0.0)),
            v=init_t.get("v"),
            free={k: init_t[k] for k in free_keys if k in init_t},
        )
        return cls(body, model, initial, integration, source, level)


def _with_shell(body: SphericalTop, model: ContactModel, shell: object) -> SphericalTop:
    """``body`` with the ``[shell]`` table's mass and inertia; required exactly by the models
    with their own inertia."""
    if shell is None:
        if model.own_inertia:
            raise ScenarioError(f"model {model.name!r} needs a table [shell] (mass, inertia)")
        return body
    if not model.own_inertia:
        own = [name for name, m in MODELS.items() if m.own_inertia]
        raise ScenarioError(
            f"[shell] is for model {' or '.join(map(repr, own))}, not {model.name!r}"
        )
    assert isinstance(shell, Mapping)
    _reject_unknown("shell", shell, ("mass", "inertia"))
    missing = [k for k in ("mass", "inertia") if k not in shell]
    if missing:
        raise ScenarioError(f"[shell] is missing {', '.join(missing)}")
    return replace(
        body,
        shell_mass=number("shell", "mass", shell["mass"]),
        shell_inertia=number("shell", "inertia", shell["inertia"]),
    )


def _reject_unknown(table: str, values: Mapping[str, object], allowed: tuple[str, ...]) -> None:
    for key in values:
        if key not in allowed:
            raise ScenarioError(
                f"unknown key {table}.{short_name(key)} (allowed: {', '.join(allowed)})"
            )


def load_scenario(path: str | os.PathLike[str], *, level_h: float | None = None) -> Scenario:
    """Read and validate a TOML scenario file.

    ``level_h`` replaces the ``[level]`` table's ``h`` before the scenario is validated (the
    command line's ``--h``: a file whose own ``h`` has no motion is still read at the ``h``
    asked for), and drops its ``gamma3``, a point of the orbit at the file's ``h`` (the start is
    then the orbit's first turning point at ``level_h``); a file without a ``[level]`` table is
    read as it is.

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
    if level_h is not None and isinstance(data.get("level"), dict):
        kept = {k: v for k, v in data["level"].items() if k != "gamma3"}
        data["level"] = {**kept, "h": level_h}
    try:
        return Scenario.from_dict(data, source=str(path))
    except RollingTopError as exc:
        raise type(exc)(f"{path}: {exc}") from None
