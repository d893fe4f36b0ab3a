"""The scalar methods, one module each, and the one registry of them: a method is one
:class:`MethodEntry` (its name, class, whether it brackets, what it needs, its theory).
The CLI, the API, the tables and the convergence analysis read this registry.

The method classes load on first use (PEP 562): a run imports only the method it uses."""

from __future__ import annotations

import math
from importlib import import_module
from typing import Any

from ..records import NamedTuple


def _plain(cls: Any, crit: Any) -> Any:
    return cls()


def _with_tolerances(cls: Any, crit: Any) -> Any:
    return cls(crit.tol, crit.rtol)


def _evaluating_f(cls: Any, crit: Any) -> Any:
    return cls(evaluate_f=crit.ftol is not None)


# A NamedTuple, not a frozen dataclass: built at import, it costs a tenth as much.
class MethodEntry(NamedTuple):
    """One scalar method. ``starts``: what it starts from (``bracket``, ``x0`` or
    ``x0 x1``); ``needs``: the problem's functions it needs beyond f, each with how an
    error message names it; ``order``: its theoretical order of convergence near a simple
    root; ``evaluations``: function evaluations per step; ``estimate_column``: for the
    convergence analysis, the history column of best estimates when the method's own error
    measure jumps (a bracket whose far end moves), else None; ``make(cls, crit)``: the
    method object for the stopping criteria; ``scipy``: the method of
    ``scipy.optimize.root_scalar`` that runs the same iteration (None where it has none),
    the contender beside it in the work-precision comparison (:mod:`linkage.measure.precision`)."""

    name: str
    module: str
    cls: str
    starts: str
    order: float
    evaluations: int
    doc: str
    needs: tuple[tuple[str, str], ...] = ()
    estimate_column: int | None = None
    make: Any = _plain
    scipy: str | None = None

    @property
    def bracketing(self) -> bool:
        return self.starts == "bracket"


GOLDEN = (1.0 + math.sqrt(5.0)) / 2.0
"""The secant method's order, (1 + sqrt 5) / 2."""

METHODS: dict[str, MethodEntry] = {e.name: e for e in (
    MethodEntry("bisection", ".bisection", "Bisection", "bracket", 1.0, 1,
                "halve the bracket, keeping the sign change", scipy="bisect"),
    MethodEntry("regula-falsi", ".regula_falsi", "RegulaFalsi", "bracket", 3.0 ** (1.0 / 3.0), 1,
                "false position, Illinois variant", estimate_column=5),
    MethodEntry("hybrid", ".hybrid", "Hybrid", "bracket", 1.839, 1,
                "Brent-style: interpolation safeguarded by bisection", estimate_column=4,
                make=_with_tolerances),
    MethodEntry("secant", ".secant", "Secant", "x0 x1", GOLDEN, 1, "the chord through the last two points",
                scipy="secant"),
    MethodEntry("newton", ".newton", "Newton", "x0", 2.0, 2, "x - f/f'",
                needs=(("fprime", "the derivative fprime"),), scipy="newton"),
    MethodEntry("halley", ".halley", "Halley", "x0", 3.0, 3, "x - 2 f f' / (2 f'^2 - f f'')",
                needs=(("fprime", "the derivative fprime"), ("fsecond", "the second derivative fsecond")),
                scipy="halley"),
    MethodEntry("fixed-point", ".fixed_point", "FixedPoint", "x0", 1.0, 1, "x = g(x)",
                needs=(("g", "the iteration function g (x = g(x))"),), make=_evaluating_f),
)}
"""Every scalar method, in the order tables list them."""


def names_and_bracketing() -> tuple[tuple[str, ...], frozenset[str]]:
    """The registered methods' names in order, and the bracketing ones'."""
    return tuple(METHODS), frozenset(name for name, e in METHODS.items() if e.bracketing)


SCALAR_METHODS: tuple[str, ...]
"""Method names in the order tables list them."""
BRACKETING: frozenset[str]
SCALAR_METHODS, BRACKETING = names_and_bracketing()

_CLASSES = {e.cls: e.module for e in METHODS.values()}


def register(entry: MethodEntry) -> None:
    """Add a method to the registry, after the ones above: a method defined outside this
    package (its ``module`` an absolute module name) runs through ``solve_scalar`` and
    ``linkage solve`` like these. Names read from the registry by a function after this
    call include it; tuples imported into a module before it do not."""
    global SCALAR_METHODS, BRACKETING
    if entry.name in METHODS:
        raise ValueError(f"a method named {entry.name!r} is registered already")
    METHODS[entry.name] = entry
    _CLASSES[entry.cls] = entry.module
    SCALAR_METHODS, BRACKETING = names_and_bracketing()


def method_class(name: str) -> Any:
    """The class of the method called ``name`` (imported on first use)."""
    cls = METHODS[name].cls
    return globals().get(cls) or __getattr__(cls)


def __getattr__(name: str) -> Any:
    module = _CLASSES.get(name)
    if module is None:
        raise AttributeError(f"module 'linkage.methods' has no attribute {name!r}")
    value = getattr(import_module(module, __name__), name)
    globals()[name] = value
    return value


__all__ = [
    "BRACKETING",
    "METHODS",
    "SCALAR_METHODS",
    "Bisection",
    "FixedPoint",
    "Hybrid",
    "MethodEntry",
    "Newton",
    "RegulaFalsi",
    "Secant",
    "method_class",
    "names_and_bracketing",
    "register",
]
