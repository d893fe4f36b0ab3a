"""Bisection: halve a bracket [a, b] with f(a) f(b) < 0, keeping the half with the sign change.

Update: c = (a + b) / 2; keep [a, c] if f(a) and f(c) differ in sign, else [c, b].
Order 1, rate 1/2: e_{k+1} = e_k / 2 with e_k = (b_k - a_k) / 2. One evaluation per
step (two to start). A-priori count: (b - a) / 2^(n+1) <= tol gives
n >= log2((b - a) / tol) - 1 (the student report's bisection convergence analysis,
docs/worked_examples.md P2).
Never fails on a valid bracket; it finds *a* root of odd multiplicity, or a pole
where f changes sign (the residual then does not shrink: check it).
Rows follow the student report (docs/worked_examples.md P2): the interval being bisected, its midpoint
c, e = (b - a) / 2, computed as b/2 - a/2 (the same bits for brackets of normal numbers,
and no overflow for a bracket as wide as [-1e308, 1e308]).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from ..iterate import Loop, build_loop
from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .common import new_state, same_sign


class BisectionState(NamedTuple):
    x: float
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    a: float
    fa: float
    b: float
    fb: float
    row_a: float
    row_fa: float
    row_b: float
    row_fb: float


def init_bracket(problem: ScalarProblem, a: float,
                 b: float) -> tuple[float, float, tuple[Status, str] | None]:
    """Evaluate f at both ends; return (f(a), f(b), stop) where stop is set when the
    bracket is unusable (same sign, non-finite) or an end is already an exact root."""
    fa = problem.f(a)
    fb = problem.f(b)
    v = problem.var
    if not (fa == fa and fb == fb and abs(fa) != float("inf") and abs(fb) != float("inf")):
        return fa, fb, (Status.NON_FINITE, f"f({v}={a:g}) = {fa!r}, f({v}={b:g}) = {fb!r}")
    if fa == 0.0:
        return fa, fb, (Status.CONVERGED_EXACT, f"f is zero at the bracket end {v} = {a!r}")
    if fb == 0.0:
        return fa, fb, (Status.CONVERGED_EXACT, f"f is zero at the bracket end {v} = {b!r}")
    if same_sign(fa, fb):
        return fa, fb, (
            Status.INVALID_BRACKET,
            f"f(a) and f(b) must have different signs: f({a:g}) = {fa:.6g}, f({b:g}) = {fb:.6g}",
        )
    return fa, fb, None


def halvings_needed(a: float, b: float, tol: float) -> int:
    """The steps bisection takes to bring its error within ``tol``: step k's error is half
    the bracket it halves, (b - a) / 2^k, so the least k with (b - a) / 2^k <= tol (the
    a-priori count above, whose n is the table's last row, k - 1: rows are numbered from
    0), from h = b/2 - a/2 (no overflow) and exact scalings of it by powers of two.
    Exact where the midpoints are (brackets far wider than their spacing of doubles); an
    upper bound where the run stops earlier: at an exact zero, with rtol > 0, or at the
    rounding level."""
    lo, hi = (a, b) if a <= b else (b, a)
    h = 0.5 * hi - 0.5 * lo
    if h <= tol:
        return 1 if h > 0.0 else 0
    k = max(1, math.ceil(math.log2(h) - math.log2(tol)) + 1)
    while k > 1 and math.ldexp(h, 2 - k) <= tol:  # log2 rounded up past an exact power of two
        k -= 1
    while math.ldexp(h, 1 - k) > tol:
        k += 1
    return k


@frozen
class Bisection:
    name: ClassVar[str] = "bisection"
    bracketing: ClassVar[bool] = True
    can_diverge: ClassVar[bool] = False
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 0
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
            Column("e", "x"),
        )

    def init(self, problem: ScalarProblem, a: float, b: float) -> BisectionState:
        if a > b:
            a, b = b, a
        fa, fb, stop = init_bracket(problem, a, b)
        x = a if stop and fa == 0.0 else b if stop and fb == 0.0 else 0.5 * a + 0.5 * b
        return BisectionState(x, fa if x == a else fb if x == b else None, 0.5 * b - 0.5 * a, stop,
                              a, fa, b, fb, a, fa, b, fb)

    def step(self, problem: ScalarProblem, s: BisectionState) -> BisectionState:
        a, fa, b, fb = s.a, s.fa, s.b, s.fb
        c = 0.5 * a + 0.5 * b
        fc = problem.f(c)
        if same_sign(fc, fa):
            return new_state(BisectionState, (c, fc, 0.5 * b - 0.5 * a, None, c, fc, b, fb, a, fa, b, fb))
        return new_state(BisectionState, (c, fc, 0.5 * b - 0.5 * a, None, a, fa, c, fc, a, fa, b, fb))

    def initial_row(self, problem: ScalarProblem, s: BisectionState) -> None:
        return None

    def cap_detail(self, bracket: tuple[float, float], tol: float, rtol: float, iterations: int,
                   err: float) -> str:
        """The iteration cap's message for bisection: it says how many halvings the bracket
        needed, known before the first (:func:`halvings_needed`), and what to raise."""
        n = halvings_needed(*bracket, tol)
        bound = "at most " if rtol else ""
        return (f"{iterations} iterations, last error {err:.3g}; this bracket needs {bound}{n:,} "
                f"halvings to reach tol = {tol:g}: raise --max-iter / max_iter to that")

    def row(self, problem: ScalarProblem, s: BisectionState, i: int) -> tuple[Any, ...]:
        return (i, s.row_a, s.row_fa, s.row_b, s.row_fb, s.x, s.err)

    def run_lean(self, problem: ScalarProblem, s: BisectionState, crit: Any,
                 certify: Any = None) -> tuple[BisectionState, Status, str, int]:
        """Bisection with recording off: :data:`BISECTION_LOOP`, the generic loop's outcome
        without a state per step (tests/test_compile.py, tests/test_kernel.py)."""
        return bisection_lean(problem, s.a, s.fa, s.b, s.fb, s.x, s.fx, s.err, crit.tol, crit.rtol,
                              crit.ftol, crit.max_iter)


BISECTION_LOOP = Loop(
    signature="bisection_lean(problem, a, fa, b, fb, x, fx, err, tol, rtol, ftol, max_iter)",
    setup="f = problem.f",
    step="""\
        c = 0.5 * a + 0.5 * b
        fc = f(c)
        """,
    after="""\
        x, fx, err = c, fc, 0.5 * b - 0.5 * a
        if _same_sign(fc, fa):
            a, fa = c, fc
        else:
            b, fb = c, fc
        """,
    result="_State(x, fx, err, None, a, fa, b, fb, a, fa, b, fb), status, detail, k")
"""Bisection's loop: the stopping rule of :mod:`linkage.iterate` around halving the bracket."""

bisection_lean = build_loop(BISECTION_LOOP, {"_State": BisectionState, "_same_sign": same_sign},
                            fixed_source=True)
