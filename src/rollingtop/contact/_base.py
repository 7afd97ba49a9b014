"""What every contact model declares: its name, constraints, free velocities, integrals, and the
compiled kernels (model x variant) that integrate it."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

import numpy as np

from rollingtop._errors import ContactModelError
from rollingtop._layout import CONTACT_PARAMS, N_CONTACT_PARAMS
from rollingtop._types import ComplexArray, FloatArray

if TYPE_CHECKING:
    from rollingtop.body import SphericalTop

#: The free velocity components given to :attr:`ContactModel.velocity`: a number for a scalar
#: component, an array for a vector one.
FreeVelocity: TypeAlias = Mapping[str, float | FloatArray]
#: ``velocity(body, gamma, omega, alpha, beta, free) -> v`` (:attr:`ContactModel.velocity`).
VelocityFunction: TypeAlias = Callable[
    ["SphericalTop", FloatArray, FloatArray, FloatArray, FloatArray, FreeVelocity], FloatArray
]


@dataclass(frozen=True)
class RuleParameter:
    """A parameter of a contact model's own rule (not of the body), given in a scenario's
    ``[contact]`` table and carried to the compiled kernels in a slot of ``p``
    (:data:`rollingtop._layout.CONTACT_PARAMS`) as its offset from :attr:`default` (a slot left
    0 is the default).

    Attributes
    ----------
    name : str
        The key in ``[contact]`` and the keyword of :meth:`ContactModel.with_parameters`.
    default : float
        The value the model is registered with (its module's constant).
    description : str
        One line.
    positive : bool
        Whether a value must be ``> 0`` (else any finite number).
    maximum : float
        A value must be below this (the ``parallel`` model's disk about the vertical: below 1,
        the largest tilt).
    """

    name: str
    default: float
    description: str
    positive: bool = True
    maximum: float = math.inf


class VerticalDirection(Protocol):
    """``direction(omega, alpha, beta, psi_nu=0.0) -> psi_nu``
    (:attr:`Vertical.direction`)."""

    def __call__(
        self, omega: FloatArray, alpha: FloatArray, beta: FloatArray, psi_nu: float = 0.0, /
    ) -> float: ...


@dataclass(frozen=True)
class Kernel:
    """One compiled variant of a contact model's equations: the model, and the variant of its
    constraint directions.

    Attributes
    ----------
    model : str
        Name of the model (:attr:`ContactModel.name`).
    variant : str or None
        ``None`` for the model's own equations; else the name of a variant that carries a
        constraint direction through an orientation where the model's geometric one is undefined
        (the meridian model's ``"south"`` and ``"north"`` pole cases: the direction's azimuth is
        the state's ``psi_nu``, see :mod:`rollingtop.contact.meridian`).
    code : int
        The kernel code, assigned by the registry (:mod:`rollingtop.contact`); the model's
        compiled package (:mod:`rollingtop._compiled`) selects the variant by it.
    carries_direction : bool
        Whether the state's ``psi_nu`` is a carried constraint direction: a variant, or the
        own kernel of a model that always carries it (:attr:`Vertical.carries_direction`);
        set by the registry.
    """

    model: str
    variant: str | None
    code: int
    carries_direction: bool = False


#: The kernels of each registered model by its name, its own first, then its variants in
#: declaration order: set by the registry (:mod:`rollingtop.contact`, which imports this module)
#: as it numbers the kernels, read by :attr:`ContactModel.kernels`.
_KERNELS_OF: dict[str, tuple[Kernel, ...]] = {}


def register_kernels(kernels: Mapping[str, tuple[Kernel, ...]]) -> None:
    """Record each model's kernels (the registry's numbering, :data:`_KERNELS_OF`)."""
    _KERNELS_OF.update(kernels)


#: An integral of states ``Y`` (shape ``(..., 18)``) of a body: values of shape ``(...)``.
IntegralForm: TypeAlias = Callable[["SphericalTop", FloatArray], FloatArray]


@dataclass(frozen=True)
class Vertical:
    """How a contact model meets a vertical symmetry axis, ``gamma = (0, 0, +-1)``
    (:attr:`ContactModel.vertical`). The defaults are a model whose constraint directions are
    regular there.

    Attributes
    ----------
    singular : callable or None
        ``singular(body, gamma) -> str | None``: why no motion of this model can start at this
        orientation (``None`` where one can).
    tolerance : float
        Below this ``sqrt(gamma1^2 + gamma2^2)`` an initial axis counts as vertical and is set
        exactly vertical, ``gamma = (0, 0, +-1)`` (0: never; the models whose constraint
        directions are regular at the vertical need no such rule).
    direction : callable or None
        ``direction(omega, alpha, beta, psi_nu) -> psi_nu``: for a model that carries a
        constraint direction in the state (the meridian model's pole variants), its azimuth
        ``psi_nu`` in the fixed frame (``nu = cos(psi_nu) alpha + sin(psi_nu) beta``) at an
        exactly vertical axis, given the angular velocity and the frame; ``psi_nu`` is the value
        to keep where the model leaves the direction free. ``None``: the state's ``psi_nu`` is
        the axis azimuth, 0 at the vertical (unused by the model).
    variants : tuple of str
        Names of the model's variants (:class:`Kernel`), each compiled as a kernel of its own.
    select_variant : callable or None
        ``select_variant(body, y) -> str | None``: the variant for a motion from state ``y``
        (:func:`rollingtop.contact.meridian.select_variant`); ``None``: never a variant.
    spin : callable or None
        ``spin(body, pole) -> omega3``: closed form of the critical spin rate of the vertical
        spin on the pole ``pole`` (+1: ``gamma3 = 1``, the south pole on the plane; -1: north)
        for a dynamically symmetric body, above which it is linearly stable; 0 when every spin
        rate is (:mod:`rollingtop.stability`). ``None``: no closed form.
    eigenvalues : callable or None
        ``eigenvalues(body, omega3, pole) -> complex ndarray``: the eigenvalues of the
        linearisation at the vertical spin, for a model whose equations are singular at the
        vertical (the meridian model: its constraint direction is undefined there). ``None``: the
        generic linearisation in ``(v, w, gamma)`` on the constraint manifold applies.
    through_reduction : bool
        Whether the vertical spin is analysed through the reduction instead (the meridian
        model, singular at the vertical, with the paper's whole reduction): the eigenvalues are
        those of the reduced motion at the pole of the pole level
        (:func:`rollingtop.stability.pole_eigenvalues`), which :mod:`rollingtop.stability`
        computes. A declaration only: the contact package never imports the reduction.
    carries_direction : bool
        Whether the model's own kernel carries its constraint direction in the state's
        ``psi_nu`` (the ``parallel`` model, whose direction ``tau`` is undefined at the vertical
        that its motions reach generically, :mod:`rollingtop.contact.parallel`), as the variants
        of the meridian model do on their pole levels.
    determined : bool
        Whether the state at a vertical axis determines the motion after it (``False`` for the
        ``parallel`` model: a one-parameter family of continuations leaves the pole,
        :mod:`rollingtop.contact.parallel`); tools that need a unique flow there (the tangent
        dynamics of :mod:`rollingtop.chaos`) stop before it.
    """

    singular: Callable[[SphericalTop, FloatArray], str | None] | None = None
    tolerance: float = 0.0
    direction: VerticalDirection | None = None
    variants: tuple[str, ...] = ()
    select_variant: Callable[[SphericalTop, FloatArray], str | None] | None = None
    spin: Callable[[SphericalTop, int], float] | None = None
    eigenvalues: Callable[[SphericalTop, float, int], ComplexArray] | None = None
    through_reduction: bool = False
    carries_direction: bool = False
    determined: bool = True


@dataclass(frozen=True)
class Symbolic:
    """A contact model as the symbolic layer (:mod:`rollingtop.symbolic`) sees it
    (:attr:`ContactModel.symbolic`): sympy is passed in, so that the model never imports it.

    Attributes
    ----------
    directions : callable
        ``directions(sp, gamma) -> list of sympy 3-vectors``: the directions ``d_k`` of the
        constraints ``(vp, d_k) = 0`` in the body frame, as functions of the sympy symbols
        ``gamma`` (the symbolic layer derives the equations from them).
    velocity : callable
        ``velocity(gamma, tau, wxr, free) -> v``: the centre-of-mass velocity on the constraint
        manifold in terms of the free components ``free`` (sympy symbols), the unit vector
        ``tau = e3 x gamma / s`` and ``w x r`` (the symbolic analogue of
        :attr:`ContactModel.velocity`).
    omega : callable or None
        ``omega(gamma, tau, spin) -> w``: the angular velocity on the manifold of the
        constraints :attr:`ContactModel.spin_directions`, in terms of the sympy symbol ``spin``
        and ``tau`` (rational in ``gamma``); ``None`` with no such constraints.
    claims : str or None
        ``"module:function"`` of the symbolic layer returning further claims for
        :func:`rollingtop.symbolic.verify` (a reduced system, particular cases); imported only
        there.
    """

    directions: Callable[[ModuleType, Any], list[Any]]
    velocity: Callable[[Any, Any, Any, Any], Any]
    omega: Callable[[Any, Any, Any], Any] | None = None
    claims: str | None = None


@dataclass(frozen=True)
class OwnVelocity:
    """The velocity of its own that a model's kinetic energy has beyond the body's
    (:attr:`ContactModel.own`; the ``shell-rotor`` pair: the shell's spin relative to the
    rotor), kept in the state's last slot. With it the general row path of the dynamics (mass
    matrix ``diag(m, m, m, I)``) does not apply: the model's closed forms are the equations.

    Attributes
    ----------
    name : str
        Name of the state's last slot in the outputs (``shell_spin``).
    value : callable
        ``value(body, y) -> float``: the slot for a new state whose ``v``, ``w`` and frame are
        set (:func:`rollingtop.initial_state`).
    integrals : mapping of str to callable
        The model's own form of each integral whose lone-body form
        (:mod:`rollingtop.dynamics.integrals`) the extra kinetic energy changes, by the same
        name (``energy``, ``jellett``, ``F6``: :mod:`rollingtop.contact._shell_pair`);
        :func:`rollingtop.dynamics.integrals.evaluate` uses them for this model.
    """

    name: str
    value: Callable[[SphericalTop, FloatArray], float]
    integrals: Mapping[str, IntegralForm]


@dataclass(frozen=True)
class ContactModel:
    """A set of ideal constraints at the contact point, with everything that follows from it.

    A model lives in one module of :mod:`rollingtop.contact`, which also defines its compiled
    constraint rows (``rows``) and, optionally, their closed forms (``accel``,
    ``project_velocity``) and the carried direction of its variants (``direction_rate``,
    ``sync_direction``); the registry (:data:`rollingtop.contact.MODELS`) lists it. Everything
    else in the package asks the model. Its fields come in groups: what it is (name,
    constraints, velocity), its integrals and reduction, its behaviour at a vertical axis
    (:class:`Vertical`), its symbolic form (:class:`Symbolic`), a velocity of its own
    (:class:`OwnVelocity`) and its presentation (outputs, colour, devices).

    Attributes
    ----------
    name : str
        Name used in scenario files and on the command line.
    description : str
        One line, for help texts.
    constraints : tuple of str
        Human-readable name of each constraint row, in kernel order.
    free_velocity : dict of str to int
        Velocity components the constraints leave free, each with its length (1: scalar).
    velocity : callable
        ``velocity(body, gamma, omega, alpha, beta, free) -> v``: the body-frame CoM velocity,
        shape (3,), that satisfies the constraints for the given free components.
    spin_directions : callable or None
        ``spin_directions(gamma) -> {name: d}``: the constraints on the angular velocity alone,
        ``(w, d) = 0`` (rubber rolling: no spin about the normal, ``d = gamma``), each with its
        name as an error message quotes it; written so that it serves NumPy arrays and sympy
        matrices alike (the symbolic layer adds these constraints to the contact rows). An initial
        ``omega`` that violates one is refused (:func:`rollingtop.dynamics.state.initial_state`),
        not projected. ``None``: the angular velocity is free.
    symbolic : Symbolic
        The model for the symbolic layer.
    integrals_symmetric, integrals_general : tuple of str
        First integrals that hold for a dynamically symmetric body (``I1 == I2``) and for a
        general one (names of :mod:`rollingtop.dynamics.integrals`).
    particular_integrals : callable or None
        ``particular_integrals(body) -> names``: integrals (keys of
        :data:`rollingtop.dynamics.integrals.INTEGRALS`) the model gains for particular bodies
        (``parallel``: the slip along ``nu`` when ``a3 = 0`` and ``I3 = I1``); see
        :meth:`integrals_for`.
    reduction : tuple of str
        The names of the integrals that fix a level set of the model's reduction to one degree
        of freedom (a dynamically symmetric body), in order: ``("M3", "C1", "C2")`` for the
        meridian model; empty for a model without one. The keys of a scenario's ``[level]``
        table. The reduction itself (potential, mass, level of a state, state of a level) is
        registered under the model's name in :mod:`rollingtop.reduction.models`: a declaration
        here, since the contact package never imports the reduction.
    vertical : Vertical
        The model at a vertical axis (default: regular there).
    own : OwnVelocity or None
        The model's own velocity beyond the body's (``shell-rotor``); ``None``: the state's
        last slot is the constraint direction's azimuth ``psi_nu``.
    state_outputs : callable or None
        ``state_outputs(body, Y) -> {name: array (n, 3)}``: further per-sample quantities of
        the model's states ``Y`` (n, 18) for the outputs (``shell-rotor``: the shell's angular
        velocity and the bearing's reaction torque), body frame.
    parameters : tuple of RuleParameter
        The model's own parameters (the ``parallel`` model's passage through the vertical),
        in the order of their slots of ``p``; :meth:`with_parameters` sets them.
    values : tuple of float
        This instance's values of :attr:`parameters` (empty: the defaults).
    bind : callable or None
        ``bind(values) -> {field: value}``: the fields that follow the parameters' values
        (``oblique``: its initial ``velocity`` for the angle), applied by :meth:`with_parameters`.
    colour : str
        Matplotlib colour of the model in figures that compare models.
    devices : tuple of str
        The devices of the paper's Sec. 1 (:data:`rollingtop.devices.DEVICES`) that realise
        this model's constraint, drawn by ``rollingtop animate --look`` (the meridian model:
        all three; ``shell-rotor``: the shell).
    """

    name: str
    description: str
    constraints: tuple[str, ...]
    free_velocity: dict[str, int]
    velocity: VelocityFunction
    symbolic: Symbolic
    integrals_symmetric: tuple[str, ...]
    integrals_general: tuple[str, ...]
    spin_directions: Callable[[Any], dict[str, Any]] | None = None
    particular_integrals: Callable[[SphericalTop], tuple[str, ...]] | None = None
    reduction: tuple[str, ...] = ()
    vertical: Vertical = Vertical()
    own: OwnVelocity | None = None
    state_outputs: Callable[[SphericalTop, FloatArray], dict[str, FloatArray]] | None = None
    parameters: tuple[RuleParameter, ...] = ()
    values: tuple[float, ...] = ()
    bind: Callable[[dict[str, float]], dict[str, Any]] | None = None
    colour: str = "#7f7f7f"
    devices: tuple[str, ...] = ()

    @property
    def parameter_values(self) -> dict[str, float]:
        """The model's own parameters (:attr:`parameters`) with this instance's values."""
        values = self.values or tuple(r.default for r in self.parameters)
        return {r.name: v for r, v in zip(self.parameters, values, strict=True)}

    def with_parameters(self, **values: object) -> ContactModel:
        """This model with some of its own parameters (:attr:`parameters`) set; each is
        validated here (``ContactModelError`` naming the key for an unknown one or a bad
        value). ``get_model("parallel").with_parameters(pole_disk=1e-7)``."""
        from dataclasses import replace

        known = {r.name: r for r in self.parameters}
        current = self.parameter_values
        for key, value in values.items():
            if key not in known:
                have = ", ".join(known) if known else "none"
                raise ContactModelError(
                    f"contact.{key}: the {self.name} model has no parameter {key!r} (its "
                    f"parameters: {have})"
                )
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
            number = float(value) if ok else math.nan  # type: ignore[arg-type]
            rule = known[key]
            if not (
                math.isfinite(number)
                and (number > 0 or not rule.positive)
                and number < rule.maximum
            ):
                need = "a positive number" if rule.positive else "a finite number"
                below = f" below {rule.maximum:g}" if math.isfinite(rule.maximum) else ""
                raise ContactModelError(f"contact.{key} = {value!r} must be {need}{below}")
            current[key] = number
        if len(current) > N_CONTACT_PARAMS:  # pragma: no cover - a declaration error
            raise ContactModelError(f"model {self.name!r} declares more than {N_CONTACT_PARAMS}")
        bound = self.bind(current) if self.bind is not None else {}
        return replace(self, values=tuple(current[r.name] for r in self.parameters), **bound)

    def params(self, body: SphericalTop) -> FloatArray:
        """The compiled kernels' parameter vector ``p`` for ``body`` under this model: the
        body's (:attr:`rollingtop.SphericalTop.params`) with the model's own parameters in
        their slots (:data:`rollingtop._layout.CONTACT_PARAMS`) as their offsets from their
        defaults, shape (13,): the kernels add the defaults back, so a body's ``params`` alone
        (slots 0) runs every model with its defaults."""
        p: FloatArray = body.params
        for i, (r, value) in enumerate(zip(self.parameters, self.values, strict=False)):
            p[CONTACT_PARAMS + i] = value - r.default  # the kernel adds its default back
        return p

    @property
    def own_inertia(self) -> bool:
        """Whether the model's kinetic energy is more than the body's own (:attr:`own`)."""
        return self.own is not None

    @property
    def slot_name(self) -> str:
        """Name of the state's last slot in the outputs: ``psi_nu`` (the constraint
        direction's azimuth) unless the model keeps its own velocity there (:attr:`own`)."""
        return "psi_nu" if self.own is None else self.own.name

    @property
    def integral_forms(self) -> Mapping[str, IntegralForm]:
        """The model's own form of each integral it changes from the lone body's
        (:attr:`OwnVelocity.integrals`); empty for most models."""
        return {} if self.own is None else self.own.integrals

    def integrals(self, symmetric: bool) -> tuple[str, ...]:
        """Names of the first integrals of this model for a (non-)symmetric body."""
        return self.integrals_symmetric if symmetric else self.integrals_general

    def body_for(self, body: SphericalTop) -> SphericalTop:
        """``body`` as this model takes it: a model with its own inertia needs a shell
        (``ValueError`` otherwise: without one the pair is the meridian model, singular at the
        vertical); the other models drop a shell (they do not carry it)."""
        if self.own_inertia:
            if not body.has_shell:
                raise ValueError(
                    f"model {self.name!r} needs a shell around the body (shell_mass, "
                    "shell_inertia; scenario table [shell])"
                )
            return body
        if body.has_shell:
            from dataclasses import replace

            return replace(body, shell_mass=0.0, shell_inertia=0.0)
        return body

    def integrals_for(self, body: SphericalTop) -> tuple[str, ...]:
        """Names of the first integrals of this model for ``body``: those of
        :meth:`integrals`, then those it gains for this particular body, if any."""
        own = self.integrals(body.symmetric)
        if self.particular_integrals is None:
            return own
        return own + tuple(n for n in self.particular_integrals(body) if n not in own)

    @property
    def has_vertical_spin(self) -> bool:
        """Whether the body can spin about a vertical symmetry axis (a pole on the plane,
        ``w = (0, 0, w3)``): no constraint of :attr:`spin_directions` has a vertical
        component at ``gamma = e3``. Rubber rolling forbids that spin, ``(w, gamma) = w3 = 0``
        there, so its vertical spins (:mod:`rollingtop.stability`) do not exist."""
        if self.spin_directions is None:
            return True
        e3 = np.array([0.0, 0.0, 1.0])
        return all(
            float(np.asarray(d, dtype=float) @ e3) == 0.0 for d in self.spin_directions(e3).values()
        )

    @property
    def kernels(self) -> tuple[Kernel, ...]:
        """The model's compiled kernels: its own (first), then one per variant (numbered by the
        registry, :mod:`rollingtop.contact`)."""
        try:
            return _KERNELS_OF[self.name]
        except KeyError:
            raise ContactModelError(
                f"contact model {self.name!r} is not registered (rollingtop.contact.MODULES), so "
                "it has no compiled kernels"
            ) from None

    @property
    def code(self) -> int:
        """Kernel code of the model's own equations (no variant)."""
        return self.kernels[0].code

    def kernel(self, body: SphericalTop, y: FloatArray) -> Kernel:
        """The kernel for a motion of ``body`` from state ``y``: the model's own, or the variant
        :attr:`select_variant` picks."""
        select = self.vertical.select_variant
        variant = None if select is None else select(body, y)
        for k in self.kernels:
            if k.variant == variant:
                return k
        raise ValueError(f"model {self.name!r} has no variant {variant!r}")  # pragma: no cover

    def kernel_code(self, body: SphericalTop, y: FloatArray) -> int:
        """The code of :meth:`kernel`."""
        return self.kernel(body, y).code


def contact_arm(body: SphericalTop, gamma: FloatArray) -> FloatArray:
    """Contact point seen from the centre of mass, ``r = -R gamma - a``, shape (3,)."""
    out: FloatArray = -body.R * np.asarray(gamma, dtype=float) - np.array([0.0, 0.0, body.a3])
    return out
