"""Contact models, chosen by name: the registry.

Each module of this package declares one model, and is the only place that knows it: its
:class:`~rollingtop.contact._base.ContactModel` (constraints, free velocity components,
integrals, initial-state construction, pole handling, symbolic constraint, whether it has a
reduction) and its compiled functions, all with the same signatures:

- ``rows(p, y, J, bias, dirs, variant)`` (required): the constraint rows, their bias and force
  directions; returns their number. The general path of the dynamics solves with them.
- ``accel(p, y, dy, ws, variant)`` and ``project_velocity(p, y, variant)`` (optional): closed
  forms of the accelerations and of the velocity projection, several times faster than the
  general path (the tests hold them to it).
- ``direction_rate(p, y, variant)`` and ``sync_direction(y, variant)`` (optional, for models with
  variants that carry a constraint direction in ``psi_nu``).

The variant argument is the kernel's index among the model's kernels (0 its own); a model with
variants receives it at run time, one without receives the constant 0. All of them are
``@inline`` (:func:`rollingtop._jit.inline`): the compiled dispatch inlines them with that
constant, so numba prunes the branches of the other variants before it types and lowers them
(a model's own kernel compiles none of its pole variants' code).

**Adding a model** is one module here plus one line in :data:`MODULES`: its compiled package
(:mod:`rollingtop._compiled`) is made from the template when first imported, and its cache
entries are keyed on this module's source among others. The shared model battery
(``tests/contact/test_models.py``) then runs for it.
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING

from rollingtop._errors import ContactModelError
from rollingtop.contact import meridian, oblique, parallel, rough, rubber, shell_rotor, smooth
from rollingtop.contact._base import (
    ContactModel,
    Kernel,
    OwnVelocity,
    RuleParameter,
    Symbolic,
    Vertical,
    register_kernels,
)

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: The registry: the model modules, one line each. Kernel codes follow this order (each model's
#: own kernel, then its variants), so a new model goes at the end.
MODULES: tuple[ModuleType, ...] = (
    meridian,
    smooth,
    rough,
    parallel,
    rubber,
    shell_rotor,
    oblique,
)

MODELS: dict[str, ContactModel] = {m.MODEL.name: m.MODEL for m in MODULES}
#: The model of a scenario that names none: the paper's, first in the registry.
DEFAULT_MODEL: str = MODULES[0].MODEL.name


def _kernels() -> tuple[Kernel, ...]:
    """Model by model in registry order, each model's own kernel then its variants: a model
    added at the end of :data:`MODULES` leaves every existing code as it was."""
    pairs = [(m.MODEL, v) for m in MODULES for v in (None, *m.MODEL.vertical.variants)]
    return tuple(
        Kernel(model.name, v, code, v is not None or model.vertical.carries_direction)
        for code, (model, v) in enumerate(pairs)
    )


#: Every compiled kernel, indexed by its code.
KERNELS: tuple[Kernel, ...] = _kernels()


def models_for(body: SphericalTop) -> tuple[ContactModel, ...]:
    """The registered models, in order, that take ``body``: a model with its own inertia
    (:attr:`ContactModel.own_inertia`, ``shell-rotor``) only with a shell."""
    return tuple(m for m in MODELS.values() if body.has_shell or not m.own_inertia)


__all__ = [
    "models_for",
    "DEFAULT_MODEL",
    "KERNELS",
    "MODELS",
    "MODULES",
    "ContactModel",
    "Kernel",
    "OwnVelocity",
    "RuleParameter",
    "Symbolic",
    "Vertical",
    "get_model",
    "kernel_by_code",
]


def get_model(name: str | ContactModel) -> ContactModel:
    """The contact model called ``name`` (one of :data:`MODELS`)."""
    if isinstance(name, ContactModel):
        return name
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ContactModelError(
            f"unknown contact model {name!r} (known: {', '.join(MODELS)})"
        ) from None


def kernels_of(model: ContactModel) -> tuple[Kernel, ...]:
    """The kernels of ``model``: its own first, then its variants in declaration order."""
    by_variant = {k.variant: k for k in KERNELS if k.model == model.name}
    return tuple(by_variant[v] for v in (None, *model.vertical.variants))


def kernel_by_code(code: int) -> Kernel:
    """The kernel with compiled selector ``code``."""
    return KERNELS[code]


register_kernels({model.name: kernels_of(model) for model in MODELS.values()})
