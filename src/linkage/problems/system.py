"""A system of n equations in n unknowns, with what the tables need to show it."""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import field
from typing import Any

from ..records import frozen
from ..units import degrees, radians

Vector = Sequence[float]
Residual = Callable[[Vector], list[float]]
Jacobian = Callable[[Vector], list[list[float]]]


@frozen
class SystemProblem:
    """Phi(q) = 0. Unknowns are held in internal units (radians for angles).

    ``kinds`` says, per unknown, ``angle`` or ``length`` (or ``""`` for plain numbers);
    tables show angles in degrees and steps in radians and degrees. ``reference``
    optionally returns closed-form solutions, one per assembly branch.
    """

    F: Residual
    J: Jacobian | None = None
    names: tuple[str, ...] = ()
    kinds: tuple[str, ...] = ()
    length_unit: str = ""
    equation_names: tuple[str, ...] = ()
    x0: tuple[float, ...] | None = None
    title: str = ""
    reference: Callable[[], dict[str, dict[str, float]] | None] | None = None
    branch_of: Callable[[dict[str, float]], str] | None = None
    """Names the assembly branch of a solution (display units); None: use the sign of det J."""
    meta: dict[str, Any] = field(default_factory=dict)
    length_scale: float = 1.0
    """The mechanism's size (its longest length): residual tolerances are relative to it,
    so a mechanism behaves the same in metres, millimetres or micrometres."""

    @property
    def step_scales(self) -> tuple[float, ...] | None:
        """Per unknown, what a step is measured against: 1 for angles (rad), the length
        scale for lengths; None when every unknown is measured as it is."""
        from ..rules import step_scales

        return step_scales(self.kinds, self.length_scale)

    @property
    def n(self) -> int:
        return len(self.names)

    def to_display(self, q: Vector) -> list[float]:
        """Internal values to interface units: radians become degrees."""
        return [degrees(v) if k == "angle" else v for v, k in zip(q, self.kinds)]

    def from_display(self, values: Vector) -> list[float]:
        return [radians(v) if k == "angle" else v for v, k in zip(values, self.kinds)]

    def unit(self, i: int) -> str:
        return "deg" if self.kinds[i] == "angle" else self.length_unit

    def step_unit(self, i: int) -> str:
        return "rad" if self.kinds[i] == "angle" else self.length_unit


def generic_system(F: Residual, n: int, J: Jacobian | None = None) -> SystemProblem:
    """Wrap a bare residual function of n unknowns (no units, names x1..xn)."""
    names, kinds, equations = generic_labels(n)
    return SystemProblem(F=F, J=J, names=names, kinds=kinds, equation_names=equations)


@functools.lru_cache(maxsize=64)
def generic_labels(n: int) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    return tuple(f"x{i + 1}" for i in range(n)), ("",) * n, tuple(f"F{i + 1}" for i in range(n))


class LeanProblem:
    """What Newton's lean loop reads on its common path (F, J, step_scales), with the full
    problem built by ``build()`` only if anything else is asked for (a refused or
    singular step hands over to the method, which reads more)."""

    __slots__ = ("F", "J", "_build", "_full", "step_scales")

    def __init__(self, F: Residual, J: Jacobian | None, step_scales: tuple[float, ...] | None,
                 build: Callable[[], SystemProblem]) -> None:
        self.F, self.J, self.step_scales, self._build, self._full = F, J, step_scales, build, None

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        full = self._full
        if full is None:
            full = self._full = self._build()
        return getattr(full, name)
