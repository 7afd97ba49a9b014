"""A scenario's ``[level]`` table: a level set of the model's reduction and where to start on it
(:mod:`rollingtop.scenario`; the reductions: :mod:`rollingtop.reduction.models`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rollingtop._checks import number, short_name, short_repr
from rollingtop._errors import ScenarioError
from rollingtop.body import SphericalTop
from rollingtop.contact import DEFAULT_MODEL, ContactModel, get_model

if TYPE_CHECKING:  # the reduction (and scipy.optimize) is imported where a level is needed
    from rollingtop.reduction.level import Level

    pass

__all__ = ["LevelSpec", "level_from_table"]

#: Where a motion starts on a level, after the level's own integrals (ContactModel.reduction).
_LEVEL_PLACEMENT = ("h", "gamma3", "branch", "phi", "psi")
#: Integrals a [level] may leave out: C2 (``rollingtop bifurcation`` scans it), p_horizontal
#: (the smooth model's drift: 0).
_LEVEL_OPTIONAL = {"C2": None, "p_horizontal": 0.0}


@dataclass(frozen=True)
class LevelSpec:
    """A level set of a reduction's integrals, as given in a ``[level]`` table.

    ``M3, C1, C2`` (Lagrange, area, F6) fix the level set of the meridian model, ``M3, C1,
    p_horizontal`` (Lagrange, area, the horizontal momentum's size) the smooth model's; ``h``
    (reduced energy ``E - I3 w3^2/2 - m g R``) an orbit on it. ``gamma3`` (default: the first
    orbit's lowest turning point, or its other one when the lowest lies beyond a pole passage),
    ``branch`` (sign of ``w_tau``, default +1), ``phi`` and ``psi`` (Euler angles, default 0)
    place the initial state when the scenario has no ``[initial]`` table
    (:func:`rollingtop.reduction.start.start_on_level`).
    """

    M3: float | None = None
    C1: float | None = None
    C2: float | None = None
    p_horizontal: float | None = None
    jellett: float | None = None
    routh: float | None = None
    rubber_spin: float | None = None
    h: float | None = None
    gamma3: float | None = None
    branch: int = 1
    phi: float = 0.0
    psi: float = 0.0

    def __post_init__(self) -> None:
        for key in (
            "M3",
            "C1",
            "C2",
            "p_horizontal",
            "jellett",
            "routh",
            "rubber_spin",
            "h",
            "gamma3",
            "phi",
            "psi",
        ):
            value = getattr(self, key)
            if value is not None:
                object.__setattr__(self, key, number("level", key, value))
        if isinstance(self.branch, bool) or not isinstance(self.branch, int | float):
            raise ScenarioError(f"level.branch = {short_repr(self.branch)} must be +1 or -1")
        if self.branch not in (1, -1):
            raise ScenarioError(f"level.branch = {short_repr(self.branch)} must be +1 or -1")
        object.__setattr__(self, "branch", int(self.branch))

    def level_set(self, body: SphericalTop, model: ContactModel | None = None) -> Level:
        """The :class:`~rollingtop.reduction.LevelSet` of ``body`` under ``model``'s reduction
        (default the meridian model's, ``(M3, C1, C2)``): the integrals it names
        (:attr:`ContactModel.reduction`)."""
        from rollingtop.reduction.models import reduction_of

        reduction = reduction_of(model or get_model(DEFAULT_MODEL))
        if "C2" in reduction.names and self.C2 is None:
            raise ScenarioError(
                "[level] is missing C2 (only `rollingtop bifurcation` does without it)"
            )
        values = {name: getattr(self, name) for name in reduction.names}
        values = {k: _LEVEL_OPTIONAL.get(k) if v is None else v for k, v in values.items()}
        return reduction.level(body, {k: v for k, v in values.items() if v is not None})


def level_from_table(table: Mapping[str, Any], model: ContactModel) -> LevelSpec:
    """The :class:`LevelSpec` of a scenario's ``[level]`` table under ``model``: the model's
    own integrals (:attr:`ContactModel.reduction`; a wrong name is refused with the right ones),
    then where to start; a model without a reduction is refused."""
    if not model.reduction:
        from rollingtop.reduction.models import reduction_of

        try:
            reduction_of(model)
        except ScenarioError as err:
            raise ScenarioError(f"[level]: {err}") from None
    for key in table:
        if key not in model.reduction + _LEVEL_PLACEMENT:
            raise ScenarioError(
                f"unknown key level.{short_name(key)} for the {model.name} model (its "
                f"level: {', '.join(model.reduction)}; then {', '.join(_LEVEL_PLACEMENT)})"
            )
    missing = [k for k in model.reduction if k not in table and k not in _LEVEL_OPTIONAL]
    if missing:
        raise ScenarioError(f"[level] is missing {', '.join(missing)}")
    return LevelSpec(**table)
