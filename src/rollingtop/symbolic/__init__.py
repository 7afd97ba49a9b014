"""Symbolic layer (sympy): derivation of the equations and machine-checked claims.

- :mod:`.equations`: the constrained equations derived from the Lagrangian (Poincare form,
  multipliers eliminated) for every registered contact model, symmetric or general body.
- :mod:`.claims`: first integrals, identities, the reduction (3.3) and the invariant measure,
  decided by exact simplification or exact evaluation at random rational points.
- :mod:`.discover`: linear integrals of the reduced system from an ansatz (finds ``F6``).

Imported on demand (sympy is an optional dependency: ``pip install rollingtop[symbolic]``).
"""

from rollingtop.symbolic.claims import ClaimResult, check, claims_for, verify
from rollingtop.symbolic.discover import discover_linear_integrals
from rollingtop.symbolic.equations import derive, rhs_function

__all__ = [
    "ClaimResult",
    "check",
    "claims_for",
    "derive",
    "discover_linear_integrals",
    "rhs_function",
    "verify",
]
