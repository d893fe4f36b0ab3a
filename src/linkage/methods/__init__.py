"""The scalar methods, one module each, and the registry the CLI and API look names up in."""

from __future__ import annotations

from .bisection import Bisection
from .fixed_point import FixedPoint
from .hybrid import Hybrid
from .newton import Newton
from .regula_falsi import RegulaFalsi
from .secant import Secant

SCALAR_METHODS: tuple[str, ...] = (
    "bisection", "regula-falsi", "hybrid", "secant", "newton", "fixed-point",
)
"""Method names in the order tables list them."""

BRACKETING = frozenset({"bisection", "regula-falsi", "hybrid"})

__all__ = [
    "BRACKETING",
    "SCALAR_METHODS",
    "Bisection",
    "FixedPoint",
    "Hybrid",
    "Newton",
    "RegulaFalsi",
    "Secant",
]
