"""Convergence order and rate estimates from a recorded history, with the theory beside.

Reads only the recorded rows (e_k: the error column, i.e. the step or bracket
measure; for regula falsi and the hybrid, |x_k - x_final|); never re-runs anything.
Per row: the ratio e_{k+1}/e_k, the local order
q_k = log(e_{k+1}/e_k) / log(e_k/e_{k-1}), and the constant e_{k+1}/e_k^p for the
method's theoretical order p. The summary order is the least-squares slope of
log e_{k+1} against log e_k over the last (up to) three pairs above rounding level:
a single q_k oscillates for the secant method (its differences follow Fibonacci
ratios 2, 1.5, 1.67, ...), the slope does not.
"""

from __future__ import annotations

import math
import sys
from dataclasses import field
from typing import Any

from ..errors import InputError
from ..methods import GOLDEN, METHODS
from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Result

ROUNDING_LEVEL = 8.0 * sys.float_info.epsilon
"""Errors below this times |x| are marked as rounding noise and left out of estimates."""

THEORETICAL_ORDER: dict[str, float] = {**{name: e.order for name, e in METHODS.items()},
                                        "newton-fd": 2.0, "lm": 2.0}
"""Each method's order near a simple root: the scalar methods' from their registry entries."""


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class ConvergenceRow(NamedTuple):
    index: Any
    error: float
    ratio: float | None
    order: float | None
    constant: float | None
    rounding: bool


@frozen
class Convergence:
    """Estimated and theoretical convergence of one run."""

    method: str
    rows: tuple[ConvergenceRow, ...]
    order: float | None
    rate: float | None
    constant: float | None
    theory_order: float
    theory: dict[str, float] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        return {
            "order": self.order,
            "rate": self.rate,
            "constant": self.constant,
            "theory_order": self.theory_order,
            "theory": dict(self.theory),
            "notes": list(self.notes),
            "rows": [
                {"i": r.index, "error": r.error, "ratio": r.ratio, "order": r.order,
                 "constant": r.constant, "rounding": r.rounding}
                for r in self.rows
            ],
        }


ESTIMATE_COLUMN = {name: e.estimate_column for name, e in METHODS.items() if e.estimate_column is not None}
"""For these methods (their registry entries say so) the bracket width jumps whenever the
far end moves, so the estimates use |x_k - x_final| from the column of best estimates."""


def _errors(result: Result) -> list[tuple[Any, float]]:
    h = result.history
    assert h is not None
    # after a gap in a long history, only the contiguous last rows give ratios
    rows = h.rows[h.gap_at:] if h.elided else h.rows
    col = ESTIMATE_COLUMN.get(result.method)
    if col is not None:
        xs = [(r[0], r[col]) for r in rows if isinstance(r[col], float)]
        return [(i, abs(x - result.x)) for i, x in xs[:-1] if math.isfinite(x)]
    return [(r[0], abs(e)) for r, e in zip(rows, (r[h.error_column] for r in rows))
            if isinstance(e, (int, float)) and math.isfinite(e)]


def _slope(points: list[tuple[float, float]]) -> float | None:
    if len(points) < 2:
        return None
    n = len(points)
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    if sxx == 0.0:
        return None
    return sum((p[0] - mx) * (p[1] - my) for p in points) / sxx


def analyze(result: Result, problem: ScalarProblem | None = None) -> Convergence | None:
    """Estimate order, rate and constant from ``result.history``; None without history."""
    if not isinstance(result, Result):
        raise InputError(f"result must be a Result (from solve_scalar or solve_system), "
                         f"got {type(result).__name__}")
    if problem is not None and not isinstance(problem, ScalarProblem):
        raise InputError(f"problem must be None or a ScalarProblem, got {type(problem).__name__}")
    h = result.history
    if h is None:
        return None
    p = THEORETICAL_ORDER.get(result.method, 1.0)
    scale = abs(result.x) if isinstance(result.x, float) and math.isfinite(result.x) else 1.0
    floor = max(ROUNDING_LEVEL * scale, sys.float_info.min)
    entries = _errors(result)
    rows: list[ConvergenceRow] = []
    for k, (idx, e) in enumerate(entries):
        rounding = e <= floor
        ratio = order = const = None
        if k >= 1:
            e0 = entries[k - 1][1]
            if e0 > 0.0:
                ratio = e / e0
                try:
                    const = e / e0 ** p if e0 ** p > 0.0 else None
                except OverflowError:  # a huge first error: no constant to show
                    const = None
            if k >= 2 and e > 0.0 and e0 > 0.0:
                em = entries[k - 2][1]
                if em > 0.0 and e0 != em:
                    den = math.log(e0 / em)
                    order = math.log(e / e0) / den if den != 0.0 else None
        rows.append(ConvergenceRow(idx, e, ratio, order, const, rounding))
    usable = [(math.log(entries[k - 1][1]), math.log(entries[k][1]))
              for k in range(1, len(entries))
              if entries[k][1] > floor and entries[k - 1][1] > floor]
    tail = usable[-3:]
    order_est = _slope(tail)
    good = [r for r in rows if not r.rounding and r.ratio is not None]
    rate = good[-1].ratio if good else None
    constant = good[-1].constant if good else None
    theory, notes = _theory(result, problem, p)
    if any(r.rounding for r in rows):
        notes = (*notes, "rows marked 'rounding' have errors at the level of double-precision "
                 "rounding and are left out of the estimates")
    return Convergence(result.method, tuple(rows), order_est, rate, constant, p, theory, notes)


def _theory(result: Result, problem: ScalarProblem | None,
            p: float) -> tuple[dict[str, float], tuple[str, ...]]:
    theory: dict[str, float] = {"order": p}
    notes: list[str] = []
    r = result.x
    m = result.method
    unit = (result.meta or {}).get("unit", "")
    per = f" per {unit}" if unit else ""
    if m == "bisection":
        theory["rate"] = 0.5
        a, b = (result.meta or {}).get("bracket", (None, None))
        tol = (result.meta or {}).get("tol")
        if a is not None and tol and math.isfinite(abs(b - a) / tol):
            n = max(0, math.ceil(math.log2(abs(b - a) / tol) - 1.0))
            theory["a_priori_iterations"] = n + 1
            notes.append(f"a-priori bound: (b - a)/2^(n+1) <= tol needs n >= {n}, "
                         f"i.e. {n + 1} rows counting from i = 0")
    elif m == "fixed-point" and problem is not None and problem.gprime is not None:
        try:
            theory["rate"] = abs(problem.gprime(r))
            notes.append("linear convergence with rate |g'(r)|")
        except (ArithmeticError, ValueError):
            pass
    elif m in ("newton", "secant") and problem is not None and problem.fprime is not None:
        try:
            d1 = problem.fprime(r)
            d2 = problem.fsecond(r) if problem.fsecond is not None else _second_difference(problem, r)
            c = d2 / (2.0 * d1)
        except (ArithmeticError, ValueError, TypeError):
            c = math.nan
        if math.isfinite(c):
            theory["f''/(2f')"] = c
            if m == "newton":
                theory["constant"] = abs(c)
                notes.append(f"e_(k+1) ~ (f''(r)/(2f'(r))) e_k^2 with f''(r)/(2f'(r)) = {c:.6g}{per}")
            else:
                theory["constant"] = abs(c) ** (GOLDEN - 1.0)
                notes.append(f"e_(k+1) ~ |f''(r)/(2f'(r))|^0.618 e_k^1.618 = {abs(c) ** (GOLDEN - 1.0):.6g}"
                             f" e_k^1.618")
    elif m == "regula-falsi":
        notes.append("Illinois variant: order 3^(1/3) = 1.442 on smooth simple roots")
    elif m == "hybrid":
        notes.append("interpolation steps converge superlinearly (order about 1.84); "
                     "bisection steps at rate 1/2")
    return theory, tuple(notes)


def _second_difference(problem: ScalarProblem, r: float) -> float:
    h = 1e-5 * max(1.0, abs(r))
    assert problem.fprime is not None
    return (problem.fprime(r + h) - problem.fprime(r - h)) / (2.0 * h)
