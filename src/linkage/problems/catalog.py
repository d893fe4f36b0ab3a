"""The one registry of test problems, shared by the tests, ``linkage stress`` and
``linkage bench`` (STYLE habit 9).

- :data:`CATALOG`: named scalar problems. Each entry is an equation (as text, so
  derivatives are exact), a bracket with a sign change, an open-method start, and
  optionally a fixed-point form. No answers are stored: references are computed
  independently (40-digit mpmath).
- :func:`classic_cases`: the Alefeld-Potra-Shi and Chandrupatla collections
  (:mod:`.classic`), with mpmath references.
- :func:`mgh_cases`: the 66 Moré-Garbow-Hillstrom square systems (:mod:`.mgh`).
- :data:`BENCH_SCALAR` and :data:`BENCH_SYSTEMS`: the problems ``linkage bench`` times,
  named by catalogue entry and sample mechanism.
"""

from __future__ import annotations

from ..records import frozen
from .classic import Case, classic_cases
from .expression import equation_problem
from .freudenstein import fourbar_equation
from .mgh import SquareSystem, mgh_cases
from .scalar import ScalarProblem

__all__ = ["BENCH_SCALAR", "BENCH_SYSTEMS", "CATALOG", "Case", "CatalogEntry", "SquareSystem",
           "classic_cases", "entry", "mgh_cases"]


@frozen
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
    CatalogEntry("quadratic-high", "x**2 - 4*x + 1", (3.0, 5.0), 5.0, 4.5, note="worked example P1, x0 = 5"),
    CatalogEntry("quadratic-low", "x**2 - 4*x + 1", (0.0, 1.0), 1.0, 0.5, g="(x**2 + 1)/4",
                 note="worked example P1, x0 = 1"),
    CatalogEntry("cubic", "x**3 - 2*x - 5", (2.0, 3.0), 2.0, 3.0, note="Wallis's cubic"),
    CatalogEntry("kepler", "x - 0.8*sin(x) - 1", (0.0, 3.0), 1.0, 2.0, g="1 + 0.8*sin(x)",
                 note="Kepler's equation, e = 0.8, M = 1"),
    CatalogEntry("exp-linear", "exp(x) - 3*x", (0.0, 1.0), 0.0, 0.5, g="exp(x)/3"),
    CatalogEntry("cos-fixed-point", "cos(x) - x", (0.0, 1.0), 1.0, 0.5, g="cos(x)"),
    CatalogEntry("log", "log(x) + x - 2", (1.0, 2.0), 1.5, 2.0, g="2 - log(x)"),
    CatalogEntry("steep-atan", "atan(10*(x - 0.3))", (0.0, 1.0), 0.35, 0.4,
                 note="Newton diverges from far starts"),
    CatalogEntry("fourbar-alpha70", None, (50.0, 60.0), 50.0, 60.0,
                 note="worked example P2 at alpha = 70 deg, phi in degrees"),
)


def entry(name: str) -> CatalogEntry:
    for e in CATALOG:
        if e.name == name:
            return e
    raise KeyError(name)


BENCH_SCALAR = {"freudenstein": "fourbar-alpha70", "quadratic": "quadratic-high"}
"""``linkage bench``'s scalar problems: its names -> catalogue entries."""

BENCH_SYSTEMS = {"fourbar": "fourbar_me581.toml", "rapier": "rapier_drive.toml"}
"""``linkage bench``'s systems: its names -> sample mechanisms."""
