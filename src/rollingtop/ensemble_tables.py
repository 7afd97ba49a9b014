"""Ensembles from tables: initial states from columns of values (a CSV file or a grid), each
row validated like a scenario's ``[initial]`` table, and the memory check that refuses an
ensemble too large to hold before anything is allocated."""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TypeAlias

import numpy as np

from rollingtop._errors import RollingTopError, ScenarioError
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.contact import ContactModel
from rollingtop.io import read_input_text
from rollingtop.scenario import (
    InitialConditions,
    Scenario,
    check_memory,
    short_name,
    short_repr,
)

__all__ = ["Columns", "check_ensemble_memory", "grid_table", "read_table", "states_from_table"]

#: Columns of initial values, each of one value per trajectory (:func:`states_from_table`).
Columns: TypeAlias = Mapping[str, Sequence[float] | FloatArray]

#: Largest CSV table of initial states read (bytes).
MAX_TABLE_BYTES = 64 << 20
#: Rough memory of one trajectory without samples (input and final states, statistics,
#: integrals, the Python objects of its row), and of one kept sample of one trajectory (the
#: samples array, the dataset and its serialised file), used to refuse ensembles that cannot fit
#: in :func:`rollingtop.scenario.memory_limit` before anything is allocated.
BYTES_PER_TRAJECTORY = 4096
BYTES_PER_TRAJECTORY_SAMPLE = 3 * N_STATE * 8


def check_ensemble_memory(n: int, samples: int | None, what: str = "the ensemble") -> None:
    """Refuse (``ScenarioError``, with the size) an ensemble of ``n`` trajectories keeping
    ``samples`` samples each whose memory exceeds :func:`rollingtop.scenario.memory_limit`."""
    needed = n * (BYTES_PER_TRAJECTORY + (samples or 0) * BYTES_PER_TRAJECTORY_SAMPLE)
    label = f"{what} ({n} trajectories" + (f" of {samples} samples)" if samples else ")")
    check_memory(label, needed)


_VECTOR_KEYS = {"gamma": 3, "omega": 3, "alpha": 3, "position": 2, "v": 3}


def _column_map(model: ContactModel) -> dict[str, tuple[str, int | None]]:
    """Column name -> (initial-condition key, component index or None)."""
    cols: dict[str, tuple[str, int | None]] = {}
    vectors = _VECTOR_KEYS | {k: n for k, n in model.free_velocity.items() if n > 1}
    for key, n in vectors.items():
        for i in range(n):
            cols[f"{key}{i + 1}"] = (key, i)
    for key, n in model.free_velocity.items():
        if n == 1:
            cols[key] = (key, None)
    cols["theta"] = ("theta", None)  # gamma = (0, sin theta, cos theta)
    return cols


def states_from_table(scenario: Scenario, columns: Columns) -> FloatArray:
    """Initial states from the scenario's initial conditions with some values replaced per row.

    ``columns`` maps names to equal-length sequences: ``gamma1..3, omega1..3, alpha1..3,
    position1..2, v1..3`` (a full velocity), the model's free components (``v_tau``;
    ``v_horizontal1..2``), or ``theta`` (``gamma = (0, sin theta, cos theta)``). Every row is
    validated like a scenario's ``[initial]`` table; errors name the row.
    """
    model = scenario.model
    allowed = _column_map(model)
    unknown = [c for c in columns if c not in allowed]
    if unknown:
        shown = ", ".join(short_name(c) for c in unknown[:5]) + (
            ", ..." if len(unknown) > 5 else ""
        )
        raise ScenarioError(
            f"unknown column {shown} for model {model.name!r} (allowed: {', '.join(allowed)})"
        )
    lengths = {len(v) for v in columns.values()}
    if len(lengths) != 1:
        raise ScenarioError("columns of the ensemble table have different lengths")
    (n,) = lengths
    base = scenario.initial
    if base is None:
        base = InitialConditions.from_state(scenario.require_state())
    from rollingtop.dynamics.state import initial_state

    states = np.empty((n, N_STATE))
    for row in range(n):
        # the vectors of initial_state, each where given
        fields: dict[str, list[float]] = {
            "gamma": list(base.gamma),
            "omega": list(base.omega),
            "position": list(base.position),
        }
        if base.alpha is not None:
            fields["alpha"] = list(base.alpha)
        if base.v is not None:
            fields["v"] = list(base.v)
        free: dict[str, float | list[float]] = {
            k: (float(v) if isinstance(v, int | float) else list(v)) for k, v in base.free.items()
        }
        for name, values in columns.items():
            key, i = allowed[name]
            x = float(values[row])
            if key == "theta":
                fields["gamma"] = [0.0, math.sin(x), math.cos(x)]
                if "alpha" not in {allowed[c][0] for c in columns}:
                    fields.pop("alpha", None)
            elif key in model.free_velocity:
                if i is None:
                    free[key] = x
                else:
                    old = free.get(key, [0.0] * model.free_velocity[key])
                    vec = [old] if isinstance(old, float) else list(old)
                    vec[i] = x
                    free[key] = vec
            else:
                if key not in fields:
                    raise ScenarioError(f"row {row + 1}: column {name} needs a base value of {key}")
                assert i is not None  # a vector's column names its component (_column_map)
                fields[key][i] = x
        if any(allowed[c][0] == "v" for c in columns):
            free = {}
        elif any(allowed[c][0] in model.free_velocity for c in columns):
            fields.pop("v", None)
        try:
            states[row] = initial_state(
                scenario.body,
                model,
                free=free,
                gamma=fields["gamma"],
                omega=fields["omega"],
                alpha=fields.get("alpha"),
                position=fields["position"],
                v=fields.get("v"),
            )
        except RollingTopError as exc:  # name the row
            raise type(exc)(f"ensemble row {row + 1}: {exc}") from None
    return states


_GRID = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^:]+):([^:]+):(\d+)\s*$")


def grid_table(spec: str, samples: int | None = None) -> dict[str, FloatArray]:
    """Columns of a Cartesian grid from ``"name=start:stop:count,name=..."``.

    The grid's size is checked against the memory limit (with ``samples`` kept per
    trajectory, if given) before anything is allocated.
    """
    axes = []
    for part in spec.split(","):
        shown = short_repr(part.strip())
        m = _GRID.match(part)
        if not m:
            raise ScenarioError(f"--grid {shown}: expected name=start:stop:count")
        name, a, b, count = m.groups()
        try:
            a, b = float(a), float(b)
        except ValueError:
            raise ScenarioError(f"--grid {shown}: start and stop must be numbers") from None
        if len(count) > 18:
            raise ScenarioError(f"--grid {shown}: count is too large")
        count = int(count)
        if not (math.isfinite(a) and math.isfinite(b)):
            raise ScenarioError(f"--grid {shown}: start and stop must be finite")
        if count < 1:
            raise ScenarioError(f"--grid {shown}: count must be >= 1")
        axes.append((name, a, b, count))
    names = [a[0] for a in axes]
    if len(set(names)) != len(names):
        raise ScenarioError("--grid names a column twice")
    check_ensemble_memory(math.prod(a[3] for a in axes), samples, "--grid")
    mesh = np.meshgrid(*[np.linspace(a, b, n) for _, a, b, n in axes], indexing="ij")
    return {name: m.ravel() for name, m in zip(names, mesh, strict=True)}


def read_table(path: str | os.PathLike[str]) -> dict[str, FloatArray]:
    """Columns of a CSV file with a header row (``#`` comment lines allowed)."""
    path = Path(path)
    text = read_input_text(path, "table", MAX_TABLE_BYTES, ScenarioError)
    lines = [
        (k, ln)
        for k, ln in enumerate(text.splitlines(), start=1)
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if len(lines) < 2:
        raise ScenarioError(f"{path}: expected a header row and at least one data row")
    header = [h.strip() for h in lines[0][1].split(",")]
    if len(set(header)) != len(header):
        raise ScenarioError(f"{path}: the header names a column twice")
    check_ensemble_memory(len(lines) - 1, None, f"{path}")
    data = np.empty((len(lines) - 1, len(header)))
    for row, (k, line) in enumerate(lines[1:]):
        cells = line.split(",")
        if len(cells) != len(header):
            raise ScenarioError(f"{path}: line {k} has {len(cells)} values, header {len(header)}")
        for i, cell in enumerate(cells):
            try:
                data[row, i] = x = float(cell)
            except ValueError:
                raise ScenarioError(
                    f"{path}: line {k}: {short_repr(cell.strip())} is not a number"
                ) from None
            if not math.isfinite(x):
                raise ScenarioError(
                    f"{path}: line {k}: {short_repr(cell.strip())} is not a finite number"
                )
    return {h: data[:, i] for i, h in enumerate(header)}
