"""The compiled kernels by kernel code, for the tests: each call goes to the compiled package of
the code's own model (:func:`rollingtop._compiled.for_code`), as the library's callers do."""

from rollingtop._compiled import for_code
from rollingtop._compiled._kernel import new_workspace, reaction

__all__ = [
    "constraint_rows",
    "contact_forces",
    "diagnostics",
    "new_workspace",
    "project",
    "project_velocity_rows",
    "reaction",
    "rhs",
    "rhs_rows",
]


def rhs(code, *args):
    return for_code(code).dynamics.rhs(code, *args)


def rhs_rows(code, *args):
    return for_code(code).dynamics.rhs_rows(code, *args)


def project(code, *args):
    return for_code(code).dynamics.project(code, *args)


def project_velocity_rows(code, *args):
    return for_code(code).dynamics.project_velocity_rows(code, *args)


def constraint_rows(code, *args):
    return for_code(code).dynamics.constraint_rows(code, *args)


def diagnostics(code, *args):
    return for_code(code).dynamics.diagnostics(code, *args)


def contact_forces(code, *args):
    return for_code(code).dynamics.contact_forces(code, *args)
