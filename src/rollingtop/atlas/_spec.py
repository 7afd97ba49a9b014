"""The atlas's spec (:mod:`rollingtop.atlas`): its axes and fixed values read from a scenario
file with an ``[axes]`` table and validated, the constants of a run, and the atlas's error."""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rollingtop._checks import short_repr
from rollingtop._errors import BodyError, RollingTopError, ScenarioError
from rollingtop._types import FloatArray
from rollingtop.atlas._cells import ATLAS_MODELS, BODY_KEYS, LEVEL_KEYS, STATE_KEYS
from rollingtop.contact import MODELS
from rollingtop.io import read_input_text

__all__ = ["AtlasError", "AtlasSpec", "atlas_spec_from_dict", "load_atlas_spec"]

AXIS_KEYS = (*BODY_KEYS, *LEVEL_KEYS, "model", "angle")
#: Largest number of cells of one atlas.
MAX_CELLS = 10_000_000
#: Cells per Dask task (a chunk, and a file of the partial folder).
DEFAULT_CHUNK = 200
#: Seconds a ``--scheduler`` has to answer as a Dask scheduler, by default and at most.
SCHEDULER_TIMEOUT = 10.0
MAX_SCHEDULER_TIMEOUT = 3600.0
#: Bumped when the classification changes: partial results of another version are not reused.
ATLAS_VERSION = 2
#: Status of a cell.
STATUS = {
    0: "classified",
    1: "inadmissible body",
    2: "pole level (C1 = +-M3)",
    3: "level too large, or one the analysis cannot classify (beyond doubles, degenerate)",
    4: "state refused by the model",
}
#: Most worker processes per core of the embedded local cluster.
MAX_WORKERS_PER_CORE = 4
MAX_SPEC_BYTES = 1_000_000


class AtlasError(RollingTopError):
    """A bad atlas spec, output, or cluster."""


@dataclass(frozen=True)
class AtlasSpec:
    """A validated atlas spec.

    Attributes
    ----------
    fixed : dict of str to float
        Every key of :data:`AXIS_KEYS` with its fixed value (the first axis value for keys on
        an axis).
    axes : dict of str to ndarray
        The axes, in order (the Dataset's dimensions).
    """

    fixed: dict[str, float]
    axes: dict[str, FloatArray]
    #: ``reduction`` (the cells' levels classified, :mod:`._cells`) or ``chaos`` (the cells'
    #: chaos indicators and periodic orbits, :mod:`._chaos`).
    kind: str = "reduction"

    @property
    def models(self) -> tuple[str, ...]:
        """The models classified: a ``model`` axis's names, or the one model of the spec."""
        if self.kind == "chaos":
            from rollingtop.atlas._chaos import CHAOS_MODELS

            return (CHAOS_MODELS[int(self.fixed["model"])],)
        indices = self.axes["model"] if "model" in self.axes else [self.fixed.get("model", 0.0)]
        return tuple(ATLAS_MODELS[int(i)] for i in indices)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    def digest(self, chunk: int) -> str:
        """What a partial result must match to be reused."""
        axes = {k: v.tolist() for k, v in self.axes.items()}
        text = json.dumps(
            {"version": ATLAS_VERSION, "fixed": self.fixed, "chunk": chunk, "axes": axes}
            # a chaos atlas's kind too (a reduction atlas's digest as before: its partial
            # folders stay reusable)
            | ({"kind": self.kind} if self.kind != "reduction" else {}),
            sort_keys=True,
        )
        return hashlib.sha256(text.encode()).hexdigest()

    def cells(self) -> FloatArray:
        """Every cell's axis values, shape (size, n_axes), in C order of the axes."""
        grids = np.meshgrid(*self.axes.values(), indexing="ij")
        return np.stack([g.ravel() for g in grids], axis=1)


def _axis(key: str, value: object) -> FloatArray:
    try:
        return _axis_values(key, value)
    except ScenarioError as exc:  # a value that is not a finite number (rollingtop._checks)
        raise AtlasError(str(exc)) from None


def _axis_values(key: str, value: object) -> FloatArray:
    from rollingtop._checks import number

    where = f"axes.{key}"
    if isinstance(value, list):
        if not value:
            raise AtlasError(f"{where} is empty")
        out = np.array([number("axes", key, v) for v in value], dtype=float)
    elif isinstance(value, dict):
        unknown = set(value) - {"start", "stop", "num"}
        if unknown or {"start", "stop", "num"} - set(value):
            raise AtlasError(
                f"{where} must be a list or {{start, stop, num}}, got {short_repr(value)}"
            )
        num = int(number("axes", f"{key}.num", value["num"], integer=True))
        if num < 1:
            raise AtlasError(f"{where}.num = {num} must be >= 1")
        if num > MAX_CELLS:
            raise AtlasError(f"{where}.num = {num} is more than {MAX_CELLS} values")
        start = number("axes", f"{key}.start", value["start"])
        stop = number("axes", f"{key}.stop", value["stop"])
        out = np.linspace(start, stop, num)
    else:
        raise AtlasError(
            f"{where} must be a list of numbers or {{start, stop, num}}, got {short_repr(value)}"
        )
    if not np.all(np.isfinite(out)):
        raise AtlasError(f"{where} has non-finite values")
    return out


def atlas_spec_from_dict(data: Mapping[str, Any]) -> AtlasSpec:
    """Validate a parsed spec (module docstring)."""
    from rollingtop.scenario import Scenario

    data = dict(data)
    axes_t = data.pop("axes", None)
    if not isinstance(axes_t, dict) or not axes_t:
        raise AtlasError("missing or empty table [axes] (keys: " + ", ".join(AXIS_KEYS) + ")")
    for key in axes_t:
        if key not in AXIS_KEYS:
            raise AtlasError(f"unknown axis {short_repr(key)} (allowed: {', '.join(AXIS_KEYS)})")
    axes = {
        key: _model_axis(value) if key == "model" else _axis(key, value)
        for key, value in axes_t.items()
    }
    size = int(np.prod([len(v) for v in axes.values()], dtype=float))
    if size > MAX_CELLS:
        raise AtlasError(f"the atlas has {size} cells, more than {MAX_CELLS}")
    contact = data.get("contact", {})
    model = contact.get("model", "meridian") if isinstance(contact, dict) else "meridian"
    if not isinstance(model, str):
        raise AtlasError(f"contact.model = {short_repr(model)} must be a model name")
    from rollingtop.atlas._chaos import CHAOS_MODELS, has_angle
    from rollingtop.reduction.models import closed_form_diagram

    if "angle" in axes and not (model in MODELS and has_angle(model)):
        raise AtlasError(
            f"axes.angle is the oblique model's constraint angle: [contact] model = "
            f"{model!r} has none"
        )
    if "angle" in axes and "model" in axes:
        raise AtlasError(
            "axes.angle and axes.model: an angle axis is a chaos atlas of the oblique model "
            "alone (leave out the model axis)"
        )
    if model in CHAOS_MODELS and "model" not in axes:
        return _chaos_spec(data, axes, model)
    if "model" in axes or not (model in MODELS and closed_form_diagram(model)):
        return _state_spec(data, axes, model)
    # the fixed values: the scenario's, with each axis at its first value
    level_t = dict(data.get("level", {})) if isinstance(data.get("level", {}), dict) else {}
    for key in LEVEL_KEYS:
        if key in axes:
            level_t[key] = float(axes[key][0])
    missing = [k for k in LEVEL_KEYS if k not in level_t]
    if missing:
        raise AtlasError(f"[level] or [axes] must give {', '.join(missing)}")
    level_t = {k: v for k, v in level_t.items() if k in LEVEL_KEYS}
    given = dict(data.get("body", {})) if isinstance(data.get("body", {}), dict) else {}
    body_t = dict(given)
    for key in BODY_KEYS:
        if key in axes:
            body_t[key] = float(axes[key][0])
    data["body"], data["level"] = body_t, level_t
    data.pop("initial", None)
    try:
        sc = Scenario.from_dict(data)
    except BodyError:
        # an axis whose first value is no admissible body: the [body] table's own body is the
        # one checked, each cell is checked alone (status 1) whatever the order of its axis
        if not any(key in axes for key in BODY_KEYS):
            raise
        sc = Scenario.from_dict({**data, "body": given})
    from rollingtop.reduction.models import closed_form_diagram

    if not closed_form_diagram(sc.model):
        raise AtlasError(
            f"the atlas classifies the reduction of the meridian model, not model {sc.model.name!r}"
        )
    if not sc.body.symmetric:
        raise AtlasError(
            f"the atlas needs a dynamically symmetric body (I1 = I2), got "
            f"I1 = {sc.body.I1:g}, I2 = {sc.body.I2:g}"
        )
    fixed = {k: float(getattr(sc.body, k)) for k in BODY_KEYS}
    fixed.update({k: float(body_t[k]) for k in BODY_KEYS if k in axes})
    fixed.update({k: float(level_t[k]) for k in LEVEL_KEYS})
    return AtlasSpec(fixed, axes)


def _model_axis(value: object) -> FloatArray:
    """A ``model`` axis: a list of model names with a reduction, as indices into
    :data:`~rollingtop.atlas._cells.ATLAS_MODELS`."""
    if not isinstance(value, list) or not value:
        raise AtlasError(
            f"axes.model must be a non-empty list of model names, got {short_repr(value)}"
        )
    out = []
    for name in value:
        if name not in ATLAS_MODELS:
            raise AtlasError(
                f"axes.model: {short_repr(name)} is not a model the atlas "
                f"classifies ({', '.join(ATLAS_MODELS)}: those with a reduction, "
                "for a body without a shell)"
            )
        if ATLAS_MODELS.index(name) in out:
            raise AtlasError(f"axes.model names {name!r} twice")
        out.append(ATLAS_MODELS.index(name))
    return np.array(out, dtype=float)


def _body_cells(body_t: dict[str, Any], axes: Mapping[str, FloatArray]) -> Iterator[dict[str, Any]]:
    """The ``[body]`` table with each cell's values of the body axes, in the cells' order."""
    keys = [key for key in BODY_KEYS if key in axes]
    for values in itertools.product(*(axes[key] for key in keys)):
        yield {**body_t, **{key: float(v) for key, v in zip(keys, values, strict=True)}}


def _first_admissible(
    data: dict[str, Any], axes: Mapping[str, FloatArray]
) -> tuple[Any, dict[str, Any]]:
    """The scenario of the first cell whose body is admissible, and that cell's ``[body]``:
    the state is checked against it; a cell whose body is inadmissible is that cell's status
    (1), not a refusal of the whole atlas. Every cell inadmissible: what is wrong with the
    first, or one line."""
    from rollingtop.scenario import Scenario

    body_t = dict(data.get("body", {})) if isinstance(data.get("body", {}), dict) else {}
    for cell in _body_cells(body_t, axes):
        try:
            return Scenario.from_dict({**data, "body": cell}), cell
        except BodyError:
            continue
    Scenario.from_dict({**data, "body": next(_body_cells(body_t, axes))})
    raise AtlasError("no cell of the atlas has an admissible body")


def _state_spec(data: dict[str, Any], axes: dict[str, FloatArray], model: object) -> AtlasSpec:
    """The spec of an atlas whose cells' levels are the ``[initial]`` state's under each model
    (a ``model`` axis, or a model other than the meridian one): body keys and ``model`` as
    axes, the state fixed."""
    from rollingtop.reduction.models import reduction_of

    on_level = [key for key in axes if key in LEVEL_KEYS]
    if on_level:
        raise AtlasError(
            f"axes {', '.join(on_level)}: with a model axis or a model other than "
            "the meridian one, each cell's level is the [initial] state's under "
            "its model; [axes] takes body keys and model"
        )
    if not isinstance(data.get("initial"), dict):
        raise AtlasError(
            "an atlas with a model axis or a model other than the meridian one "
            "needs an [initial] table (gamma, omega): each model's level is that "
            "state's"
        )
    data.pop("level", None)
    sc, body_t = _first_admissible(data, axes)
    if "model" not in axes:
        try:
            reduction_of(sc.model)
        except ScenarioError as exc:
            raise AtlasError(f"the atlas classifies a reduction: {exc}") from None
        if sc.model.name not in ATLAS_MODELS:  # the shell-rotor pair: no shell keys on the axes
            raise AtlasError(
                f"the atlas classifies {', '.join(ATLAS_MODELS)} (a body without a "
                f"shell), not the {sc.model.name} model"
            )
    if not sc.body.symmetric:
        raise AtlasError(
            f"the atlas needs a dynamically symmetric body (I1 = I2), got "
            f"I1 = {sc.body.I1:g}, I2 = {sc.body.I2:g}"
        )
    if sc.body.has_shell:
        raise AtlasError(
            "the atlas classifies bodies without a shell: the shell's mass and "
            "inertia are not among its axes"
        )
    y0 = sc.require_state()
    fixed = {k: float(getattr(sc.body, k)) for k in BODY_KEYS}
    fixed.update({k: float(body_t[k]) for k in BODY_KEYS if k in axes})
    fixed.update(zip(STATE_KEYS, (float(x) for x in (*y0[12:15], *y0[3:6])), strict=True))
    fixed["model"] = float(ATLAS_MODELS.index(model)) if model in ATLAS_MODELS else 0.0
    return AtlasSpec(fixed, axes)


#: Bounds of the ``[chaos]`` table's ``t_end`` and ``seeds``.
MAX_CHAOS_T_END = 1.0e4
MAX_CHAOS_SEEDS = 32


def _chaos_options(table: object) -> tuple[float, int]:
    """The ``[chaos]`` table's ``t_end`` and ``seeds`` (defaults of :mod:`._chaos`)."""
    from rollingtop._checks import number
    from rollingtop.atlas._chaos import DEFAULT_SEEDS, DEFAULT_T_END

    if table is None:
        return DEFAULT_T_END, DEFAULT_SEEDS
    if not isinstance(table, dict):
        raise AtlasError(f"[chaos] must be a table (t_end, seeds), got {short_repr(table)}")
    unknown = set(table) - {"t_end", "seeds"}
    if unknown:
        raise AtlasError(f"[chaos] has unknown keys {', '.join(sorted(unknown))} (t_end, seeds)")
    try:
        t_end = number("chaos", "t_end", table.get("t_end", DEFAULT_T_END))
        seeds = int(number("chaos", "seeds", table.get("seeds", DEFAULT_SEEDS), integer=True))
    except ScenarioError as exc:
        raise AtlasError(str(exc)) from None
    if not 0.0 < t_end <= MAX_CHAOS_T_END:
        raise AtlasError(f"chaos.t_end = {t_end:g} must be in (0, {MAX_CHAOS_T_END:g}]")
    if not 1 <= seeds <= MAX_CHAOS_SEEDS:
        raise AtlasError(f"chaos.seeds = {seeds} must be in [1, {MAX_CHAOS_SEEDS}]")
    return t_end, seeds


def _chaos_spec(data: dict[str, Any], axes: dict[str, FloatArray], model: str) -> AtlasSpec:
    """The spec of a chaos atlas (:mod:`._chaos`): a model without a reduction (``oblique``,
    ``parallel``), the ``[initial]`` state fixed, body keys and ``angle`` (oblique) as axes."""
    from rollingtop.atlas._chaos import CHAOS_MODELS, free_key, has_angle

    on_level = [key for key in axes if key in LEVEL_KEYS]
    if on_level:
        raise AtlasError(
            f"axes {', '.join(on_level)}: the {model} model has no reduction; a chaos atlas "
            "takes body keys and angle (oblique) as axes, the level is the [initial] state's"
        )
    if not isinstance(data.get("initial"), dict):
        raise AtlasError(
            f"a chaos atlas of the {model} model needs an [initial] table (gamma, omega, "
            f"{free_key(model)}): each cell runs on that state's level"
        )
    t_end, seeds = _chaos_options(data.pop("chaos", None))
    if "level" in data:
        raise AtlasError(
            f"[level]: the {model} model has no reduction; a chaos atlas runs on the level of "
            "the [initial] state (leave out [level])"
        )
    contact = dict(data.get("contact", {}))
    if "angle" in axes:
        contact["angle"] = float(axes["angle"][0])
    data["contact"] = contact
    sc, body_t = _first_admissible(data, axes)
    if not sc.body.symmetric or sc.body.has_shell:  # pragma: no branch
        raise AtlasError(
            "a chaos atlas needs a dynamically symmetric body (I1 = I2) without a shell"
        )
    y0 = sc.require_state()
    fixed = {k: float(getattr(sc.body, k)) for k in BODY_KEYS}
    fixed.update({k: float(body_t[k]) for k in BODY_KEYS if k in axes})
    fixed.update(zip(STATE_KEYS, (float(x) for x in (*y0[12:15], *y0[3:6])), strict=True))
    fixed["free"] = float(data["initial"].get(free_key(model), 0.0))
    fixed["model"] = float(CHAOS_MODELS.index(model))
    fixed["t_end"], fixed["seeds"] = t_end, float(seeds)
    if has_angle(model):
        fixed["angle"] = float(sc.model.parameter_values["angle"])
    return AtlasSpec(fixed, axes, kind="chaos")


def load_atlas_spec(path: str | os.PathLike[str]) -> AtlasSpec:
    """Read and validate an atlas spec (a TOML scenario file with an ``[axes]`` table)."""
    path = Path(path)
    text = read_input_text(path, "atlas spec", MAX_SPEC_BYTES, ScenarioError)
    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError, ValueError) as exc:
        raise AtlasError(f"{path}: invalid TOML: {exc}") from None
    try:
        return atlas_spec_from_dict(data)
    except RollingTopError as exc:
        raise AtlasError(f"{path}: {exc}") from None
