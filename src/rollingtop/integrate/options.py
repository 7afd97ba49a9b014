"""Options of one integration: end time, tolerances, samples, step bound (validated).

A scenario's ``[integration]`` table builds them (:mod:`rollingtop.scenario`), and so may a
caller of :func:`rollingtop.simulate` without any file. Values are checked at construction;
messages name them ``integration.<key>``, as in a scenario file.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rollingtop._checks import check_memory, number, short_repr
from rollingtop._errors import ScenarioError

__all__ = ["BYTES_PER_SAMPLE", "DEFAULTS", "MAX_STEPS_LIMIT", "IntegrationOptions"]

#: Integration defaults. ``atol`` defaults to ``rtol / 100`` when not given.
DEFAULTS: dict[str, float | int | None] = {
    "t_end": 10.0,
    "rtol": 1e-10,
    "atol": None,
    "samples": 1001,
    "max_steps": 10**8,
    "project_integrals": False,
}
#: Largest ``max_steps`` (the integrator's own "no limit").
MAX_STEPS_LIMIT = 2**62
#: Rough memory of one output sample of a single run (state, diagnostics, integrals, the
#: dataset and its serialised file), used to refuse ``samples`` that cannot fit.
BYTES_PER_SAMPLE = 1024


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
        Number of equally spaced samples in ``[0, t_end]``, >= 2; their memory must fit in
        :func:`rollingtop._checks.memory_limit` (:data:`BYTES_PER_SAMPLE` each).
    max_steps : int
        Bound on accepted steps, ``1 <= max_steps <= 2**62``.
    project_integrals : bool
        Hold every integral the model claims for the body
        (:meth:`~rollingtop.contact.ContactModel.integrals_for`) at its initial value by a
        projection of the velocity after every accepted step and at every sample
        (:mod:`rollingtop._compiled._template.invariants`).

    Raises
    ------
    ScenarioError
        A value of the wrong type or out of its range, quoted (shortened) in one line.
    """

    t_end: float = 10.0
    rtol: float = 1e-10
    atol: float | None = None
    samples: int = 1001
    max_steps: int = 10**8
    project_integrals: bool = False

    def __post_init__(self) -> None:
        w = "integration"
        t_end = number(w, "t_end", self.t_end)
        rtol = number(w, "rtol", self.rtol)
        atol = rtol / 100 if self.atol is None else number(w, "atol", self.atol)
        samples = int(number(w, "samples", self.samples, integer=True))
        max_steps = int(number(w, "max_steps", self.max_steps, integer=True))
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
        flag: object = self.project_integrals
        if not isinstance(flag, bool):
            given = short_repr(flag)
            raise ScenarioError(f"integration.project_integrals = {given} must be true or false")
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
    def t_eval(self) -> NDArray[np.float64]:
        """Sample times ``linspace(0, t_end, samples)``, shape (samples,)."""
        return np.linspace(0.0, self.t_end, self.samples)
