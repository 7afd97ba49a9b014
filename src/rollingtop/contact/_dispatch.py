"""Compiled dispatch: kernel code -> its model's functions (GENERATED: do not edit).

Written by ``python -m rollingtop.contact._codegen`` from the registry
(:data:`rollingtop.contact.MODULES`); see that generator for why. Kernel codes:

- 0: ``meridian``
- 1: ``meridian``, variant ``south``
- 2: ``meridian``, variant ``north``
- 3: ``smooth``
- 4: ``rough``
- 5: ``parallel``
- 6: ``rubber``
- 7: ``shell-rotor``
"""

from __future__ import annotations

from rollingtop._jit import inline, kernel
from rollingtop._types import FloatArray, Workspace
from rollingtop.contact import _rows, meridian, parallel, rough, rubber, shell_rotor, smooth


@kernel
def rows(
    code: int, p: FloatArray, y: FloatArray, J: FloatArray, bias: FloatArray, dirs: FloatArray
) -> int:
    """The constraint rows of kernel ``code``; returns their number (-1: unknown code)."""
    if code == 0:
        return meridian.rows(p, y, J, bias, dirs, 0)
    if code == 1:
        return meridian.rows(p, y, J, bias, dirs, 1)
    if code == 2:
        return meridian.rows(p, y, J, bias, dirs, 2)
    if code == 3:
        return smooth.rows(p, y, J, bias, dirs, 0)
    if code == 4:
        return rough.rows(p, y, J, bias, dirs, 0)
    if code == 5:
        return parallel.rows(p, y, J, bias, dirs, 0)
    if code == 6:
        return rubber.rows(p, y, J, bias, dirs, 0)
    if code == 7:
        return shell_rotor.rows(p, y, J, bias, dirs, 0)
    return -1


@inline
def accel(code: int, p: FloatArray, y: FloatArray, dy: FloatArray, ws: Workspace) -> int:
    """Closed-form accelerations of kernel ``code``; returns the number of rows, or -1 where the
    model has no closed form (then the general path applies)."""
    if code == 0:
        return meridian.accel(p, y, dy, ws, 0)
    if code == 1:
        return meridian.accel(p, y, dy, ws, 1)
    if code == 2:
        return meridian.accel(p, y, dy, ws, 2)
    if code == 3:
        return smooth.accel(p, y, dy, ws, 0)
    if code == 4:
        return rough.accel(p, y, dy, ws, 0)
    if code == 5:
        return parallel.accel(p, y, dy, ws, 0)
    if code == 6:
        return rubber.accel(p, y, dy, ws, 0)
    if code == 7:
        return shell_rotor.accel(p, y, dy, ws, 0)
    return -1


@inline
def project_velocity(code: int, p: FloatArray, y: FloatArray) -> bool:
    """Closed-form velocity projection of kernel ``code``; ``False`` where the model has none."""
    if code == 0:
        meridian.project_velocity(p, y, 0)
        return True
    if code == 1:
        meridian.project_velocity(p, y, 1)
        return True
    if code == 2:
        meridian.project_velocity(p, y, 2)
        return True
    if code == 3:
        smooth.project_velocity(p, y, 0)
        return True
    if code == 4:
        rough.project_velocity(p, y, 0)
        return True
    if code == 5:
        parallel.project_velocity(p, y, 0)
        return True
    if code == 6:
        rubber.project_velocity(p, y, 0)
        return True
    if code == 7:
        shell_rotor.project_velocity(p, y, 0)
        return True
    return False


@inline
def direction_rate(code: int, p: FloatArray, y: FloatArray) -> float:
    """``psi_nu'`` under kernel ``code`` (0 unless it carries a constraint direction)."""
    if code == 0:
        return meridian.direction_rate(p, y, 0)
    if code == 1:
        return meridian.direction_rate(p, y, 1)
    if code == 2:
        return meridian.direction_rate(p, y, 2)
    if code == 5:
        return parallel.direction_rate(p, y, 0)
    if code == 7:
        return shell_rotor.direction_rate(p, y, 0)
    return _rows.direction_rate(p, y, 0)


@inline
def sync_direction(code: int, y: FloatArray) -> None:
    """Re-synchronise ``psi_nu`` with the axis azimuth after a step, as kernel ``code`` does."""
    if code == 0:
        meridian.sync_direction(y, 0)
        return
    if code == 1:
        meridian.sync_direction(y, 1)
        return
    if code == 2:
        meridian.sync_direction(y, 2)
        return
    if code == 5:
        parallel.sync_direction(y, 0)
        return
    if code == 7:
        shell_rotor.sync_direction(y, 0)
        return
    _rows.sync_direction(y, 0)


@inline
def carries_direction(code: int) -> bool:
    """Whether kernel ``code`` carries its constraint direction in ``psi_nu``."""
    return code == 1 or code == 2 or code == 5
