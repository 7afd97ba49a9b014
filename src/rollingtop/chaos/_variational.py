"""The section map's derivative from the variational equations (issue 38, item 2).

``P^K`` takes section coordinates ``x`` to those of the ``K``-th crossing:
``P^K(x) = sigma(phi(tau_K(x), S(x)))`` with ``S`` the state rebuilt from ``x``
(:func:`~rollingtop.chaos._section_map.section_state`), ``phi`` the flow, ``tau_K`` the time
of the ``K``-th crossing of the section ``g(y) = 0`` and ``sigma`` the section coordinates
(:func:`~rollingtop.chaos._section_map.section_coordinates`). By the chain rule, with
``Phi = d phi / d y`` the flow's derivative over one period ``T = tau_K(x)`` and ``f`` the
vector field at the end point ``y_T``,

    ``DP^K = D sigma(y_T) (I - f dg(y_T) / (dg(y_T) f)) Phi DS(x)``

(differentiating ``g(phi(tau_K(x), S(x))) = 0`` gives ``d tau_K``; only the last crossing's
correction enters, the intermediate ones cancel). ``Phi`` applied to each column of ``DS`` is
the compiled tangent (variational) integration of :mod:`rollingtop._compiled._tangent`, run one
period from the orbit's state: it carries the tangent vector renormalised with its growth
summed in ``ctrl[LOG_SUM]``, so ``Phi d = |d| exp(LOG_SUM) delta(T)``. The algebraic maps
``S`` and ``sigma`` are differentiated by central differences (no integration inside: their
error is the difference quotient's, ``~1e-10`` relative), ``g = s w_tau = w . (e3 x gamma)``
(the stepper's event function, :mod:`rollingtop.chaos.section`) exactly.

Why not the central differences of the flow that Newton uses: their error is the flow's
round-off divided by the step (``rtol / 1e-5 ~ 1e-6`` at ``rtol = 1e-11``) plus the step's
square times the third derivative; the variational integration's error is held by its error
control on the tangent vector, to ``max(rtol, 1e-8)`` of its norm per step
(:data:`rollingtop._compiled._tangent.TANGENT_TOL`): measured, the multipliers agree with
Richardson-extrapolated differences at ``rtol = 1e-13`` to ``3e-7``.
"""

from __future__ import annotations

import math

import numpy as np

from rollingtop._compiled import for_code
from rollingtop._compiled._dop853 import FINISHED
from rollingtop._compiled._kernel import workspace
from rollingtop._compiled._tangent import LOG_SUM, N_AUG, NORM, REACHED_VERTICAL
from rollingtop._errors import IntegrationError
from rollingtop._jit import call
from rollingtop._layout import N_STATE
from rollingtop._types import FloatArray
from rollingtop.chaos._section_map import SectionMap, section_coordinates, section_state
from rollingtop.chaos.lyapunov import _compile_indicators, _run_chunks

__all__ = ["ThroughVertical", "variational_jacobian"]


class ThroughVertical(IntegrationError):
    """The period passes through the vertical, where the flow has no derivative."""


#: Relative step of the central differences of the algebraic maps ``S`` and ``sigma`` (the cube
#: root of the machine epsilon: truncation and round-off balance near ``eps^(2/3)``).
ALGEBRAIC_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))
#: Accepted steps at most of one period's tangent integration.
MAX_STEPS = 2_000_000

_W, _GAMMA = slice(3, 6), slice(12, 15)


def _section_gradient(y: FloatArray, d: FloatArray) -> float:
    """``dg(y) d`` for ``g = w . (e3 x gamma) = -w1 gamma2 + w2 gamma1``."""
    w, g = y[_W], y[_GAMMA]
    dw, dgam = d[_W], d[_GAMMA]
    return float(-dw[0] * g[1] - w[0] * dgam[1] + dw[1] * g[0] + w[1] * dgam[0])


def _directional(func: object, y: FloatArray, d: FloatArray) -> FloatArray:
    """Central difference of the algebraic map ``func`` at ``y`` along ``d``."""
    scale = float(np.max(np.abs(d)))
    if scale == 0.0:
        return np.zeros_like(np.asarray(func(y)))  # type: ignore[operator]
    e = ALGEBRAIC_STEP * max(1.0, float(np.max(np.abs(y[:15])))) / scale
    out: FloatArray = (func(y + e * d) - func(y - e * d)) / (2.0 * e)  # type: ignore[operator]
    return out


def state_derivative(P: SectionMap, x: FloatArray) -> FloatArray:
    """``DS(x)``: the rebuilt state's derivative by each section coordinate, shape (4, 18)."""
    h = ALGEBRAIC_STEP * np.maximum(1.0, np.abs(x))
    rows = []
    for i in range(x.size):
        up, down = x.copy(), x.copy()
        up[i] += h[i]
        down[i] -= h[i]
        rows.append(
            (section_state(P.body, P.model, up) - section_state(P.body, P.model, down))
            / (2.0 * h[i])
        )
    return np.array(rows)


def variational_jacobian(
    P: SectionMap, x: FloatArray, period: float, *, stop_at_vertical: bool = True
) -> FloatArray:
    """``DP^K(x)`` (shape (4, 4), ``DP[:, j] = dP^K / dx_j``) for the crossing ``x`` whose
    ``K``-th return comes after ``period``, from the variational equations (module
    docstring).

    ``stop_at_vertical``: refuse (:class:`ThroughVertical`) a period that passes through the
    vertical (the tangent kernel's ``s_stop``), where the exact model's flow has no derivative.
    ``False`` carries the tangent through, which only measures the regularised rule: its
    derivative there is of order ``1 / pole_disk`` and the tangent's difference quotients (step
    ``~6e-6``, wider than the disk) do not resolve it (tried on the example's orbits through the
    vertical: multipliers of ``1e6``).
    """
    y0 = section_state(P.body, P.model, x)
    code = P.model.kernel_code(P.body, y0)
    p = P.model.params(P.body)
    atol = P.rtol * 1e-2
    stop = 1.0 if stop_at_vertical else 0.0
    t = np.array([float(period)])
    DS = state_derivative(P, x)
    _compile_indicators(code, p, y0, DS[0], P.rtol, atol, stop)
    columns = []
    y_end = np.full(N_STATE, np.nan)
    for d0 in DS:
        size = math.sqrt(float(np.sum(d0[:NORM] ** 2)))
        stats = np.zeros(4)
        z, ctrl = _run_chunks(
            code,
            p,
            y0.copy(),
            d0 / size,
            t,
            P.rtol,
            atol,
            MAX_STEPS,
            np.full((1, 3), np.nan),
            np.full((1, N_STATE), np.nan),
            stats,
            stop,
        )
        if int(stats[0]) == REACHED_VERTICAL:
            raise ThroughVertical("the period passes through the vertical")
        if int(stats[0]) != FINISHED or not np.all(np.isfinite(z[:N_AUG])):
            raise IntegrationError(
                f"the variational integration over one period stopped (status {int(stats[0])})"
            )
        y_end = z[:N_STATE].copy()
        columns.append(size * math.exp(float(ctrl[LOG_SUM])) * z[N_STATE : 2 * N_STATE])
    f = np.zeros(N_STATE)
    call(for_code(code).dynamics.rhs, code, p, y_end, f, workspace())
    df = _section_gradient(y_end, f)

    def coords(y: FloatArray) -> FloatArray:
        out: FloatArray = section_coordinates(P.model, y)
        return out

    J = np.empty((4, len(columns)))
    for j, v in enumerate(columns):
        on_section = v - f * (_section_gradient(y_end, v) / df)
        J[:, j] = _directional(coords, y_end, on_section)
    return J
