"""Analytic inverse kinematics: geometric subproblems and the solvers built on them."""
