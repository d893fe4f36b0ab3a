"""Regula falsi, Illinois variant: the secant through the bracket ends, kept bracketed.

Update: c = b - F(b) (b - a) / (F(b) - F(a)) with F the stored end values; keep the
sub-bracket with the sign change. Plain regula falsi keeps one end for ever (linear
convergence); Illinois halves the stored value of an end retained twice in a row,
which restores superlinear convergence of order 3^(1/3) = 1.442 (Dowell and Jarratt,
BIT 11, 1971). One evaluation per step, two to start. A candidate that rounding puts
outside the open bracket is replaced by the midpoint, so the bracket always holds.
Error measure: the bracket width |b - a|, which bounds |c - r| because c is an end.
Where the secant's products over- or underflow (brackets as wide as [-1e308, 1e308],
values near 1e-300) its point comes from the ratio of the end values instead
(:func:`secant_from_ratio`), and a bracket wider than the largest double is bisected
(tests/test_extreme_brackets.py).
"""

from __future__ import annotations

from typing import Any, ClassVar

from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .bisection import init_bracket
from .common import new_state, same_sign


class RegulaFalsiState(NamedTuple):
    x: float
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    a: float
    fa: float
    b: float
    fb: float
    wa: float
    wb: float
    side: int
    row_a: float
    row_fa: float
    row_b: float
    row_fb: float


def secant_from_ratio(a: float, fa: float, b: float, fb: float) -> float:
    """Regula falsi's point c = b - F(b) (b - a) / (F(b) - F(a)) where that overflowed (c inf
    or NaN, or c = b from a difference F(b) - F(a) beyond the largest double) or underflowed
    (F(b) (b - a) = 0: tiny values on a tiny bracket), on a bracket of finite width: the
    same point from the end with the smaller |F|, as a + (b - a) / (1 - F(b) / F(a)) (or
    its mirror from b). F(b) / F(a) < 0, so the divisor is at least 1 and no product of
    values is formed; a ratio beyond the largest double gives the end itself, which the
    step replaces by the midpoint, as it does where the width itself overflows (so that
    a bracket wider than the largest double is bisected, and is finite from then on)."""
    width = b - a
    return a + width / (1.0 - fb / fa) if abs(fa) <= abs(fb) else b - width / (1.0 - fa / fb)


@frozen
class RegulaFalsi:
    name: ClassVar[str] = "regula-falsi"
    bracketing: ClassVar[bool] = True
    can_diverge: ClassVar[bool] = False
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 2
    step_evals: ClassVar[int] = 1

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (
            Column("i", "index"),
            Column("a", "x"),
            Column("f(a)", "f"),
            Column("b", "x"),
            Column("f(b)", "f"),
            Column("c", "x"),
            Column("f(c)", "f"),
            Column("width", "x"),
        )

    def init(self, problem: ScalarProblem, a: float, b: float) -> RegulaFalsiState:
        if a > b:
            a, b = b, a
        fa, fb, stop = init_bracket(problem, a, b)
        x, fx = (a, fa) if abs(fa) < abs(fb) else (b, fb)
        return RegulaFalsiState(x, fx, b - a, stop, a, fa, b, fb, 1.0, 1.0, 0, a, fa, b, fb)

    def step(self, problem: ScalarProblem, s: RegulaFalsiState) -> RegulaFalsiState:
        a, fa, b, fb, wa, wb, side = s.a, s.fa, s.b, s.fb, s.wa, s.wb, s.side
        big_fa = fa * wa
        big_fb = fb * wb
        denominator = big_fb - big_fa
        # (weights halved many times can underflow: then the secant is undefined)
        c = b - big_fb * (b - a) / denominator if denominator != 0.0 else a
        if not a < c < b:  # rounding put c at or past an end, a weight underflowed, or:
            if c != a and (c - c != 0.0 or (c == b and (denominator - denominator != 0.0
                                                       or big_fb * (b - a) == 0.0))):
                c = secant_from_ratio(a, big_fa, b, big_fb)  # an overflow or underflow on the way
                if not a < c < b:  # (the width itself overflowed: bisect)
                    c = 0.5 * a + 0.5 * b
            else:
                c = 0.5 * a + 0.5 * b
        fc = problem.f(c)
        if same_sign(fc, fb):
            b, fb, wb = c, fc, 1.0
            if side == -1:
                wa *= 0.5
            side = -1
        else:
            a, fa, wa = c, fc, 1.0
            if side == 1:
                wb *= 0.5
            side = 1
        return new_state(RegulaFalsiState, (
            c, fc, b - a, None, a, fa, b, fb, wa, wb, side, s.a, s.fa, s.b, s.fb))

    def initial_row(self, problem: ScalarProblem, s: RegulaFalsiState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: RegulaFalsiState, i: int) -> tuple[Any, ...]:
        return (i, s.row_a, s.row_fa, s.row_b, s.row_fb, s.x, s.fx, s.err)
