"""One registry of scalar test problems, shared by the tests, the stress suite and benchmarks.

Each entry is an equation (as text, so derivatives are exact), a bracket with a sign
change, an open-method start, and optionally a fixed-point form. No answers are stored
here: the tests compute reference roots independently (40-digit mpmath).
"""

from __future__ import annotations

from dataclasses import dataclass

from .expression import equation_problem
from .freudenstein import fourbar_equation
from .scalar import ScalarProblem


@dataclass(frozen=True)
class CatalogEntry:
    name: str
    equation: str | None
    bracket: tuple[float, float]
    x0: float
    x1: float
    g: str | None = None
    note: str = ""

    def problem(self) -> ScalarProblem:
        if self.equation is None:
            return fourbar_equation(70.0)
        return equation_problem(self.equation, self.g)


CATALOG: tuple[CatalogEntry, ...] = (
    CatalogEntry("quadratic-high", "x**2 - 4*x + 1", (3.0, 5.0), 5.0, 4.5, note="seed 000, x0 = 5"),
    CatalogEntry("quadratic-low", "x**2 - 4*x + 1", (0.0, 1.0), 1.0, 0.5, g="(x**2 + 1)/4",
                 note="seed 000, x0 = 1"),
    CatalogEntry("cubic", "x**3 - 2*x - 5", (2.0, 3.0), 2.0, 3.0, note="Wallis's cubic"),
    CatalogEntry("kepler", "x - 0.8*sin(x) - 1", (0.0, 3.0), 1.0, 2.0, g="1 + 0.8*sin(x)",
                 note="Kepler's equation, e = 0.8, M = 1"),
    CatalogEntry("exp-linear", "exp(x) - 3*x", (0.0, 1.0), 0.0, 0.5, g="exp(x)/3"),
    CatalogEntry("cos-fixed-point", "cos(x) - x", (0.0, 1.0), 1.0, 0.5, g="cos(x)"),
    CatalogEntry("log", "log(x) + x - 2", (1.0, 2.0), 1.5, 2.0, g="2 - log(x)"),
    CatalogEntry("steep-atan", "atan(10*(x - 0.3))", (0.0, 1.0), 0.35, 0.4,
                 note="Newton diverges from far starts"),
    CatalogEntry("fourbar-seed-002", None, (50.0, 60.0), 50.0, 60.0,
                 note="seed 002 at alpha = 70 deg, phi in degrees"),
)


def entry(name: str) -> CatalogEntry:
    for e in CATALOG:
        if e.name == name:
            return e
    raise KeyError(name)
