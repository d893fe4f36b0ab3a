"""Equations and mechanisms: what the solvers are pointed at."""
