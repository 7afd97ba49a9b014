"""Constrained dynamics: state layout, compiled right-hand side, projections, integrals."""
