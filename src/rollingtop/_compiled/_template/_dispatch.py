"""What each model's compiled dispatch provides: the template's stand-in, never compiled.

:func:`rollingtop._compiled._instances.dispatch_source` writes one ``_dispatch`` module per
group of kernels with these names and signatures, each calling the model module's own functions
(:mod:`rollingtop.contact`, whose package docstring lists them) with the kernel's variant: the
code minus the model's first code where the model has variants, the constant 0 otherwise.
"""

from __future__ import annotations

from rollingtop._types import FloatArray, Workspace

#: Whether the model has closed-form accelerations (``accel``); if not, the right-hand side is
#: the general path (rows and a Cholesky solve). Imported by name as a global constant: numba
#: prunes the branch not taken before typing (not for an attribute of a module), so a model with
#: a closed form never compiles the general path into its stepper.
CLOSED_ACCEL = True
#: Whether the model has a closed-form velocity projection (``project_velocity``).
CLOSED_PROJECTION = True
#: Whether the stepper's stage loop inlines the right-hand side (the model module's
#: ``INLINE_RHS``, default ``False``). Inlined, the paper's model runs 15 % faster against the C
#: limit (a call passes the workspace's five arrays field by field, twelve times a step); but
#: the right-hand side is then compiled twice, in the stepper and on its own: for a model with
#: a long closed form (``parallel``, ``shell-rotor``) that was 10-20 s of a first run.
INLINE_RHS = False
#: The model's kernel codes (its own, then its variants').
CODES: tuple[int, ...] = ()


#: What the stand-ins raise if called: the instances' dispatch modules replace them.
NEVER_CALLED = "the template's dispatch is a stand-in, never called: see the module docstring"


def rows(
    code: int, p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray
) -> int:
    """The constraint rows of kernel ``code``, their bias and force directions; their number."""
    raise NotImplementedError(NEVER_CALLED)


def accel(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """Closed-form accelerations of kernel ``code`` into ``dy[:6]``; the number of rows."""
    raise NotImplementedError(NEVER_CALLED)


def project_velocity(code: int, p: FloatArray, y: FloatArray) -> None:
    """Closed-form velocity projection of kernel ``code``, in place."""
    raise NotImplementedError(NEVER_CALLED)


def direction_rate(code: int, p: FloatArray, y: FloatArray) -> float:
    """``psi_nu'`` under kernel ``code`` (0 unless it carries a constraint direction)."""
    raise NotImplementedError(NEVER_CALLED)


def sync_direction(code: int, y: FloatArray) -> None:
    """Re-synchronise ``psi_nu`` with the axis azimuth after a step, as kernel ``code`` does."""
    raise NotImplementedError(NEVER_CALLED)


def carries_direction(code: int) -> bool:
    """Whether kernel ``code`` carries its constraint direction in ``psi_nu``."""
    raise NotImplementedError(NEVER_CALLED)
