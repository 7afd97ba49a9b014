"""Each contact model's reduction to one degree of freedom, by the model's name.

A model declares the integrals that fix a level of its reduction
(:attr:`rollingtop.contact.ContactModel.reduction`); its :class:`Reduction` here says how to
build the level (a :class:`~rollingtop.reduction.LevelSet` kind: the potential, the mass, the
precession and the centre of mass's velocity as functions of the nutation angle), how to read
it and the reduced energy off a full state, and how the reduced energy relates to the full one.
Everything downstream -- steady motions, orbits, quadratures, portraits, starting a motion on a
level -- takes the level and asks it, whatever the model.

=========  ========================  ======================================================
model      level                     reduced energy ``h``
=========  ========================  ======================================================
meridian   ``M3, C1, C2``            ``E - I3 w3^2/2 - m g R`` (paper eq. 3.11)
smooth     ``M3, C1, p_horizontal``  ``E - I3 w3^2/2 - m g R``
rough      ``jellett, routh``        ``E - m g R``
rubber     ``rubber_spin``           ``E - m g R``
shell-     ``M3, jellett, C2``       ``E - M3^2/(2 I3) - m g R``
rotor
=========  ========================  ======================================================
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop._errors import ScenarioError
from rollingtop._layout import W
from rollingtop.body import SphericalTop, largest_input
from rollingtop.contact import MODELS, ContactModel, get_model
from rollingtop.reduction.level import Level, LevelSet, LevelSetError
from rollingtop.reduction.rough import RoughLevel, rough_integrals
from rollingtop.reduction.rubber import RubberLevel, rubber_integrals
from rollingtop.reduction.shell_rotor import ShellRotorLevel, shell_rotor_integrals
from rollingtop.reduction.smooth import SmoothLevel, smooth_integrals
from rollingtop.reduction.variables import reduced_integrals

__all__ = ["ATLAS_MODELS", "REDUCTIONS", "Reduction", "closed_form_diagram", "reduction_of"]


@dataclass(frozen=True)
class Reduction:
    """How a contact model's motions of a dynamically symmetric body reduce to one degree of
    freedom.

    Attributes
    ----------
    model : str
        The contact model's name.
    level_type : type
        The :class:`~rollingtop.reduction.LevelSet` kind of its levels; its ``integrals`` are
        the level's names (the model's :attr:`~rollingtop.contact.ContactModel.reduction`).
    integrals : callable
        ``integrals(body, Y) -> dict``: the level's integrals and the reduced energy ``h`` of
        states ``Y`` (shape ``(..., 18)``), each of shape ``(...)``.
    energy : str
        What ``h`` is, in terms of the full energy ``E``.
    sources : str
        Where the reduction comes from.
    axis : str
        The integral of the level its classification varies
        (:func:`rollingtop.reduction.classify.critical_values`, ``rollingtop bifurcation``): the
        one that shapes ``U`` most.
    atlas : bool
        Whether a parameter atlas classifies this model's levels (``rollingtop atlas``: a body
        without a shell, so not the shell-rotor pair's).
    closed_form_diagram : bool
        Whether the whole of the paper's reduction applies (Sec. 3): the closed-form bifurcation
        diagram in ``(C2, h)`` with its folds and regions, rotation numbers over it, the
        ``[level]`` atlas, and the reduction's symbolic claims (the identity of its integrals,
        its invariant measure). The others classify along :attr:`axis` by the numerical
        critical values (:mod:`rollingtop.reduction.classify`). The meridian model's only, so
        far.
    """

    model: str
    level_type: type[Level]
    integrals: Callable[[SphericalTop, ArrayLike], dict[str, NDArray[np.float64]]]
    energy: str
    sources: str
    axis: str
    atlas: bool = True
    closed_form_diagram: bool = False

    @property
    def names(self) -> tuple[str, ...]:
        """The names of the integrals that fix a level."""
        return self.level_type.integrals

    def level(self, body: SphericalTop, values: Mapping[str, float], scale: float = 0.0) -> Level:
        """The level set of ``body`` with the integrals ``values`` (every name of
        :attr:`names`; a missing or unknown one is a :class:`ScenarioError` listing them)."""
        missing = [n for n in self.names if n not in values]
        unknown = [n for n in values if n not in self.names]
        if missing or unknown:
            what = f"missing {', '.join(missing)}" if missing else f"unknown {', '.join(unknown)}"
            raise ScenarioError(
                f"a level of the {self.model} model's reduction is fixed by "
                f"{', '.join(self.names)} ({what})"
            )
        given = {n: float(values[n]) for n in self.names}
        make = cast("Callable[..., Level]", self.level_type)  # a concrete kind, not Level
        return make(body, **given, scale=scale)

    def level_of_state(self, body: SphericalTop, y: ArrayLike) -> Level:
        """The level set the state ``y`` (shape (18,)) lies on; ``|I w|`` is the round-off scale
        of ``M3`` and ``C1`` in the pole decision (:class:`~rollingtop.reduction.LevelSet`)."""
        y = np.asarray(y, dtype=float)
        try:
            with np.errstate(all="ignore"):  # a value beyond doubles is said below, in one line
                values = self.integrals(body, y)
                scale = float(np.linalg.norm(body.inertia * y[W]))
        except OverflowError:  # Python's float arithmetic raises where numpy's gives inf
            values, scale = {n: np.array(math.inf) for n in (*self.names, "h")}, math.inf
        bad = [n for n in (*self.names, "h") if not np.isfinite(values[n])]
        if bad or not np.isfinite(scale):
            raise LevelSetError(
                f"the level of the state is not finite ({', '.join(bad) or '|I w|'} = "
                f"{float(values[bad[0]]) if bad else scale:g}): {largest_input(body, y)[0]} "
                "overflows double precision in the integrals' products; rescale the "
                "scenario's units"
            )
        return self.level(body, {n: float(values[n]) for n in self.names}, scale=scale)

    def reduced_energy(self, body: SphericalTop, y: ArrayLike) -> float:
        """The reduced energy ``h`` of the state ``y`` (:attr:`energy`)."""
        return float(self.integrals(body, np.asarray(y, dtype=float))["h"])


REDUCTIONS: dict[str, Reduction] = {
    r.model: r
    for r in (
        Reduction(
            "meridian",
            LevelSet,
            reduced_integrals,
            "E - I3 w3^2/2 - m g R",
            "Kilin and Ivanova 2023, Sec. 3 (eqs. 3.8-3.11)",
            axis="C2",
            closed_form_diagram=True,
        ),
        Reduction(
            "smooth",
            SmoothLevel,
            smooth_integrals,
            "E - I3 w3^2/2 - m g R",
            "Lagrange's top about its centre of mass with the vertical motion's mass "
            "(Routh, Advanced Rigid Dynamics, Sec. 242)",
            axis="C1",
        ),
        Reduction(
            "rough",
            RoughLevel,
            rough_integrals,
            "E - m g R",
            "Routh's sphere: Jellett's and Routh's integrals (Routh, Advanced Rigid "
            "Dynamics, Sec. 243; Borisov and Mamaev, Rigid Body Dynamics)",
            axis="jellett",
        ),
        Reduction(
            "rubber",
            RubberLevel,
            rubber_integrals,
            "E - m g R",
            "rolling without slipping or spinning: the integral linear in w "
            "(Borisov, Mamaev and Bizyaev 2013; rollingtop.reduction.rubber)",
            axis="rubber_spin",
        ),
        Reduction(
            "shell-rotor",
            ShellRotorLevel,
            shell_rotor_integrals,
            "E - I3 w3^2/2 - m g R",
            "the pair's Lagrange, Jellett and F6 integrals (rollingtop.symbolic.shell_rotor;"
            " the meridian model's reduction as the shell's mass and inertia vanish)",
            axis="C2",
            atlas=False,  # the pair's shell is not among an atlas's axes
        ),
    )
}


#: The models a parameter atlas classifies (:attr:`Reduction.atlas`), in registry order: an
#: atlas's ``model`` axis holds indices into this tuple.
ATLAS_MODELS: tuple[str, ...] = tuple(r.model for r in REDUCTIONS.values() if r.atlas)


def reduction_of(model: str | ContactModel) -> Reduction:
    """The reduction of ``model`` (a name or a :class:`ContactModel`); a
    :class:`ScenarioError` in one line for a model without one, naming those with one and what
    serves the others."""
    model = get_model(model) if isinstance(model, str) else model
    if model.reduction and model.name in REDUCTIONS:
        return REDUCTIONS[model.name]
    names = ", ".join(m.name for m in MODELS.values() if m.reduction and m.name in REDUCTIONS)
    raise ScenarioError(
        f"the {model.name} model has no reduction to one degree of freedom (models with one: "
        f"{names}); explore its motions with `rollingtop simulate`, `section` and `chaos`"
    )


def closed_form_diagram(model: str | ContactModel) -> bool:
    """Whether ``model`` has the whole of the paper's reduction
    (:attr:`Reduction.closed_form_diagram`); ``False`` for a model without a reduction."""
    model = get_model(model)
    reduction = REDUCTIONS.get(model.name) if model.reduction else None
    return reduction is not None and reduction.closed_form_diagram
