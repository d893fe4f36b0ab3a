"""One equation in one unknown, with whatever extra functions a method may use."""

from __future__ import annotations

from collections.abc import Callable

from ..records import frozen

Fn = Callable[[float], float]


@frozen
class ScalarProblem:
    """f(x) = 0, plus optional derivatives and a fixed-point form x = g(x).

    ``var`` and ``unit`` name the unknown in tables (``phi``, ``deg``). ``fsecond`` is
    used only for the theoretical convergence constant; ``u`` only for display (the
    seed's fixed-point table shows u(phi) with g = acos(u)).
    """

    f: Fn
    fprime: Fn | None = None
    fsecond: Fn | None = None
    g: Fn | None = None
    gprime: Fn | None = None
    u: Fn | None = None
    var: str = "x"
    unit: str = ""
    title: str = ""
    guess: tuple[float, float] | None = None
    """A default (x0, x1) that also brackets a root, when the problem knows one."""
    fbound: Fn | None = None
    """A bound on the rounding error of the computed f(x): |f(x)| below it is a root to
    within rounding (certifies convergence where f does not change sign)."""
