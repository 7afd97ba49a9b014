"""The reduced system (paper eq. 3.3) as an integrable system of its own.

State ``x = (gamma3, v_tau, w_n, w_tau)``; ``M3`` is a parameter (Lagrange integral). With
``s = sqrt(1 - gamma3^2)`` and ``rho(gamma3) = I1 + m (a3^2 + R^2 + 2 a3 R gamma3)``:

    gamma3' = s w_tau
    v_tau'  = w_tau w_n (R + a3 gamma3) / s
    w_n'    = w_tau (M3 / I1 + gamma3 w_n / s)
    rho w_tau' = -( m a3 s (g + R w_tau^2) + M3 w_n + I1 gamma3 w_n^2 / s
                    + m v_tau w_n (R + a3 gamma3) / s )

It conserves ``h``, ``C1`` and ``C2`` (:func:`reduced_integrals_of`) and has the invariant measure
``rho dv_tau dw_n dgamma3 dw_tau``.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rollingtop.body import SphericalTop
from rollingtop.dynamics.integrals import F6_reduced

__all__ = ["normal_force", "reduced_rhs", "reduced_integrals_of", "integrate_reduced"]

FloatArray: TypeAlias = NDArray[np.float64]
ComplexArray: TypeAlias = NDArray[np.complex128]


def reduced_rhs(body: SphericalTop, M3: float, x: FloatArray) -> FloatArray:
    """Right-hand side of eq. (3.3).

    Parameters
    ----------
    body : SphericalTop
    M3 : float
        Lagrange integral ``I3 w3``.
    x : ndarray, shape (4, ...)
        ``(gamma3, v_tau, w_n, w_tau)``, vectorised over the trailing axes.

    Returns
    -------
    ndarray, shape (4, ...)
        ``(gamma3', v_tau', w_n', w_tau')``.
    """
    g3, v_tau, w_n, w_tau = x
    R, m, g, a3, I1 = body.R, body.m, body.g, body.a3, body.I1
    s = np.sqrt(1 - g3 * g3)
    rho = body.rho(g3)
    k = R + a3 * g3
    return np.array(
        [
            s * w_tau,
            w_tau * w_n * k / s,
            w_tau * (M3 / I1 + g3 * w_n / s),
            -(
                m * a3 * s * (g + R * w_tau**2)
                + M3 * w_n
                + I1 * g3 * w_n**2 / s
                + m * v_tau * w_n * k / s
            )
            / rho,
        ]
    )


def normal_force(body: SphericalTop, M3: float, x: ArrayLike) -> FloatArray:
    """The normal force of the plane at reduced states ``x`` (shape ``(4, ...)``, as in
    :func:`reduced_rhs`), in closed form: shape ``(...)``.

    The centre of mass is at height ``R + a3 gamma3`` and only gravity and the normal force act
    on it vertically (the meridian constraint's force is along ``nu``, horizontal), so
    ``N = m (g + a3 gamma3'')`` with ``gamma3'' = s w_tau' - gamma3 w_tau^2`` (``gamma3' = s
    w_tau``, ``s' = -gamma3 w_tau``) and ``w_tau'`` from eq. (3.3). A phase portrait shades
    where ``N < 0`` with it, in NumPy: the reduction's pictures need no compiled code.
    """
    x = np.asarray(x, dtype=float)
    g3, w_tau = x[0], x[3]
    s = np.sqrt(1 - g3 * g3)
    dw_tau = reduced_rhs(body, M3, x)[3]
    N: FloatArray = body.m * (body.g + body.a3 * (s * dw_tau - g3 * w_tau * w_tau))
    return N


def reduced_integrals_of(body: SphericalTop, M3: float, x: ArrayLike) -> dict[str, FloatArray]:
    """``h, C1, C2`` of reduced states ``x`` (shape ``(4, ...)``), ``docs/model.md`` definitions;
    each of shape ``(...)``. ``C2`` is :func:`rollingtop.dynamics.integrals.F6_reduced`."""
    g3, v_tau, w_n, w_tau = np.asarray(x, dtype=float)
    m, g, a3, I1 = body.m, body.g, body.a3, body.I1
    s = np.sqrt(1 - g3 * g3)
    return {
        "h": m * v_tau**2 / 2 + I1 * w_n**2 / 2 + body.rho(g3) * w_tau**2 / 2 + m * g * a3 * g3,
        "C1": g3 * M3 - I1 * s * w_n,
        "C2": F6_reduced(body, M3, g3, s, np.arccos(g3), v_tau, w_n),
    }


def integrate_reduced(
    body: SphericalTop,
    M3: float,
    x0: ArrayLike,
    t_eval: ArrayLike,
    *,
    rtol: float = 1e-12,
    atol: float = 1e-14,
) -> FloatArray:
    """Integrate eq. (3.3) from ``x0`` (shape ``(4,)``) with ``solve_ivp`` (DOP853) and return
    the states at the increasing times ``t_eval`` (shape ``(n,)``), shape ``(4, n)``.

    A 4-dimensional smooth system away from the poles: SciPy's integrator is adequate here.
    """
    t_eval = np.asarray(t_eval, dtype=float)
    from scipy.integrate import solve_ivp  # on first use: a third of a second to import

    sol = solve_ivp(
        lambda t, x: reduced_rhs(body, M3, x),
        (t_eval[0], t_eval[-1]),
        np.asarray(x0, dtype=float),
        method="DOP853",
        rtol=rtol,
        atol=atol,
        t_eval=t_eval,
    )
    if not sol.success:
        raise RuntimeError(f"reduced integration failed: {sol.message}")
    y: FloatArray = sol.y
    return y


def reduced_eigenvalues(body: SphericalTop, M3: float, x0: FloatArray) -> ComplexArray:
    """Eigenvalues of :func:`reduced_rhs` linearised at the reduced state ``x0`` (shape (4,)),
    by central differences (:meth:`rollingtop.reduction.LevelSet.linearised_eigenvalues`);
    NaN where the differences leave the domain (round-off distance from a pole)."""
    from rollingtop._numdiff import DIFF_STEP, central_jacobian

    steps = DIFF_STEP * np.maximum(1.0, np.abs(x0))
    # stay inside (-1, 1): near a pole the step in gamma3 shrinks with the distance to it
    steps[0] = min(steps[0], 0.25 * (1.0 - abs(float(x0[0]))))
    D = central_jacobian(lambda x: reduced_rhs(body, M3, x), x0, steps)
    if not np.all(np.isfinite(D)):
        return np.full(4, complex(np.nan, np.nan))
    out: ComplexArray = np.linalg.eigvals(D).astype(complex)
    return out
