"""Numerical building blocks with no physics in them: quadrature rules, directions and their
geometry, one-dimensional optimisation, a least-recently-used cache."""
