"""The oblique family (:mod:`rollingtop.contact.oblique`): its claims beyond the integrals.

The constraint direction is ``d = cos(phi) nu + sin(phi) tau`` with ``phi`` a symbol, through
``t = tan(phi / 2)`` (:data:`rollingtop.symbolic.equations.PHI_T`): every claim below, and the
model's integrals (energy, Jellett's) that ``rollingtop verify`` checks for every model, hold for
every ``phi`` at once. The claims here: the two ends of the family are the paper's and the
companion paper's constraints (``t = 0``: ``d`` is ``nu`` up to its positive length ``s``;
``t = 1``: ``d`` is ``tau`` up to ``s``); and what the search of
:mod:`rollingtop.symbolic.oblique_search` finds for the balanced ball (``a3 = 0``, ``I3 = I1``)
at every angle it samples, proved here for every ``phi`` and every such body: the contact
point's slip along ``d x gamma`` and the area integral are conserved.
"""

from __future__ import annotations

import sympy as sp

from rollingtop.symbolic.claims import Claim, s_sym
from rollingtop.symbolic.equations import PHI_T, SYMBOLS

__all__ = ["claims"]


def _direction() -> sp.Matrix:
    from rollingtop.contact import get_model

    return get_model("oblique").symbolic.directions(sp, SYMBOLS.gamma)[1]


def claims() -> list[Claim]:
    """``d(t = 0) = e3 - gamma3 gamma`` (the paper's ``s nu``) and ``d(t = 1) = e3 x gamma``
    (the companion paper's ``s tau``), componentwise, as identities."""
    d = _direction()
    e3 = sp.Matrix([0, 0, 1])
    g = SYMBOLS.gamma
    ends = {
        "phi = 0: d is the paper's direction nu": (0, e3 - g[2] * g),
        "phi = pi/2: d is the companion paper's direction tau": (1, e3.cross(g)),
    }
    out = []
    for name, (t, want) in ends.items():
        gap = sum((sp.expand(d[i].subs(PHI_T, t) - want[i])) ** 2 for i in range(3))
        out.append(Claim(name, "oblique", sp.expand(gap), "identity"))
    S = SYMBOLS
    g = S.gamma
    t = PHI_T
    cos_phi, sin_phi = (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2)
    # e = d x gamma = -sin(phi) nu + cos(phi) tau, nu = (e3 - g3 gamma)/s, tau = e3 x gamma/s
    e = (-sin_phi * (e3 - g[2] * g) + cos_phi * e3.cross(g)) / s_sym
    r = -S.R * g - sp.Matrix([0, 0, S.a3])
    slip = (S.v + S.w.cross(r)).dot(e)
    ball = ((S.a3, 0), (S.I3, S.I1))
    out.append(
        Claim(
            "balanced ball: slip along d x gamma conserved (every phi)",
            "oblique",
            slip,
            params=ball,
        )
    )
    area = S.I1 * (S.w[0] * g[0] + S.w[1] * g[1]) + S.I3 * S.w[2] * g[2]
    out.append(
        Claim("balanced ball: area integral conserved (every phi)", "oblique", area, params=ball)
    )
    return out
