"""The scalar methods, one module each, and the registry the CLI and API look names up in.

The method classes load on first use (PEP 562): a run imports only the method it uses."""

from __future__ import annotations

from importlib import import_module
from typing import Any

SCALAR_METHODS: tuple[str, ...] = (
    "bisection", "regula-falsi", "hybrid", "secant", "newton", "fixed-point",
)
"""Method names in the order tables list them."""

BRACKETING = frozenset({"bisection", "regula-falsi", "hybrid"})

_CLASSES = {"Bisection": ".bisection", "FixedPoint": ".fixed_point", "Hybrid": ".hybrid",
            "Newton": ".newton", "RegulaFalsi": ".regula_falsi", "Secant": ".secant"}


def __getattr__(name: str) -> Any:
    module = _CLASSES.get(name)
    if module is None:
        raise AttributeError(f"module 'linkage.methods' has no attribute {name!r}")
    value = getattr(import_module(module, __name__), name)
    globals()[name] = value
    return value


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
