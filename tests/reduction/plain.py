"""docs/model.md's one-degree-of-freedom formulas, written plainly with mpmath for the tests.

Independent of the package (which works in a signed nutation angle with analytic derivatives):
these follow ``docs/model.md``, "One degree of freedom" and "Reduced variables", literally, in the
paper's variable ``gamma3``, at any mpmath precision.
"""

import mpmath as mp


def U(b, M3, C1, C2, g3):
    """``U(gamma3)`` of docs/model.md."""
    g3 = mp.mpf(g3)
    s = mp.sqrt(1 - g3**2)
    I1v = (b.R * (M3 - C1 * g3) + b.a3 * (M3 * g3 - C1)) / s + C2 + M3 * b.a3 * mp.acos(g3)
    return (
        (C1 - M3 * g3) ** 2 / (2 * b.I1 * s**2)
        + b.m * I1v**2 / (2 * b.I1**2)
        + (b.m * b.g * b.a3 * g3)
    )


def rho(b, g3):
    return b.I1 + b.m * (b.a3**2 + b.R**2 + 2 * b.a3 * b.R * g3)


def field(b, M3, x):
    """Reduced system (3.3) at ``x = (gamma3, v_tau, w_n, w_tau)``."""
    g3, v_tau, w_n, w_tau = x
    s = mp.sqrt(1 - g3**2)
    k = b.R + b.a3 * g3
    return [
        s * w_tau,
        w_tau * w_n * k / s,
        w_tau * (M3 / b.I1 + g3 * w_n / s),
        -(
            b.m * b.a3 * s * (b.g + b.R * w_tau**2)
            + M3 * w_n
            + b.I1 * g3 * w_n**2 / s
            + b.m * v_tau * w_n * k / s
        )
        / rho(b, g3),
    ]


def turning_points(b, M3, C1, C2, h, guesses):
    """Roots of ``h = U(gamma3)`` near ``guesses`` (mpmath findroot at working precision)."""
    return [
        mp.findroot(lambda g: U(b, M3, C1, C2, g) - h, (x - 1e-9, x + 1e-9), solver="anderson")
        for x in guesses
    ]


def period(b, M3, C1, C2, h, g_lo, g_hi):
    """``T = 2 int dgamma3 / |gamma3'|`` with ``gamma3'^2 = 2 s^2 (h - U)/rho`` (tanh-sinh
    quadrature copes with the inverse square roots at the ends)."""

    def f(g):
        return 1 / mp.sqrt(2 * (1 - g**2) * (h - U(b, M3, C1, C2, g)) / rho(b, g))

    return 2 * mp.quad(f, [g_lo, g_hi])
