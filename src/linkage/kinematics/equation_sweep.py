"""The four-bar input-output equation over alpha (the student report's table (docs/worked_examples.md
P2)): each alpha solved
from the previous alpha's root, walking along the tangent."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..records import NamedTuple
from ..units import RAD_PER_DEG


class EquationRow(NamedTuple):
    """One alpha of the table: phi is None unless the run converged."""

    alpha: float
    status: str
    phi: float | None
    iterations: int
    residual: Any


def equation_sweep(values: Sequence[float], rs: tuple[float, float, float], method: str,
                   tol: float, seed: tuple[float, float] | None = None) -> list[EquationRow]:
    """The four-bar input-output equation over alpha: the student report's table
    (docs/worked_examples.md P2), each alpha solved
    from the previous alpha's root (the first from the equation's own default start, or
    walked from ``seed``, an (alpha, phi) root on the branch to follow).

    Where the closed form (freudenstein.equation_roots) has no real root the position is
    no_solution and continuation restarts after it. A run from the tangent prediction
    can start within rounding of the root; Newton then steps between the root's
    neighbouring floats with |f| at its rounding floor, and the loop's best-residual guard
    (scaled by the start's residual, itself at that floor) never lets the step test pass:
    such a run, stopped with its last step within the tolerance, is judged by the solver's
    own root certificate (solve.certify_root: |f| within its rounding bound, or a sign
    change across x +- tol)."""
    from ..problems.freudenstein import equation_roots
    from ..result import Status

    rows: list[EquationRow] = []
    previous: tuple[float, float] | None = seed  # (alpha, phi) of the last root on the branch

    for alpha in values:
        r = None
        if not equation_roots(alpha, *rs):
            rows.append(EquationRow(alpha, "no_solution", None, 0, None))
            previous = None
            continue
        if previous is None:
            r = solve_at(alpha, None, rs, method, tol)
        else:
            # walk from the last root in steps of at most 2 degrees, predicting along the
            # tangent: the other root of the equation is never reached by a jump
            a0, phi = previous
            n = max(1, math.ceil(abs(alpha - a0) / 2.0))
            for k in range(1, n + 1):
                ak = a0 + (alpha - a0) * k / n
                ap = a0 + (alpha - a0) * (k - 1) / n
                r = solve_at(ak, phi + slope(ap, phi, rs) * (ak - ap), rs, method, tol)
                if r is None or not r.converged:
                    break
                phi = r.x
        if r is None:
            # roots exist (above), but no sign change near the prediction for a bracketing
            # method: a double root, at a limit position
            rows.append(EquationRow(alpha, Status.INVALID_BRACKET.value, None, 0, None))
            previous = None
            continue
        if r.converged:
            previous = (alpha, r.x)
        rows.append(EquationRow(alpha, r.status.value, r.x if r.converged else None, r.iterations,
                                r.residual))
    return rows


def solve_at(alpha: float, guess: float | None, rs: tuple[float, float, float], method: str,
             tol: float) -> Any:
    """The equation's root at ``alpha`` from ``guess`` (None: the equation's own start),
    by ``method``; a bracketing method from the nearest bracket around the guess; None
    where there is no start (no root, or no sign change near the guess)."""
    from ..methods import BRACKETING
    from ..problems.freudenstein import equation_roots, fourbar_equation
    from ..solve import solve_scalar

    problem = fourbar_equation(alpha, *rs)
    kw: dict[str, Any] = dict(method=method, tol=tol, max_iter=200, record=False)
    if guess is None:
        if problem.guess is None:
            # roots closer together than the default start's 10-degree grid (near a
            # limit position): the closed form's, the first in [0, 180] as that grid
            # would find it
            roots = equation_roots(alpha, *rs)
            if not roots:
                return None
            guess = min(roots, key=lambda p: (p < 0.0, p))
        elif method in BRACKETING:
            return solve_scalar(problem, bracket=problem.guess, **kw)
        else:
            # an open method starts inside the first bracket with a sign change, so
            # every method anchors on the same root (the starting root's branch)
            guess = 0.5 * (problem.guess[0] + problem.guess[1])
    if method in BRACKETING:
        width = 0.5
        while width < 90.0:  # the nearest bracket around the prediction
            lo, hi = guess - width, guess + width
            if (problem.f(lo) < 0.0) != (problem.f(hi) < 0.0):
                return solve_scalar(problem, bracket=(lo, hi), **kw)
            width *= 2.0
        return None
    kw["x0"] = guess
    if method == "secant":
        kw["x1"] = guess + 1e-3
    return certified(problem, solve_scalar(problem, **kw), tol)


def certified(problem: Any, r: Any, tol: float) -> Any:
    """The run; or, where it stopped unconverged with its last step within the
    tolerance, the solver's root certificate's verdict on its last iterate; or, where
    f is zero to its rounding but the steps stay above the tolerance (f' so small that
    rounding moves the root by more), precision_limit."""
    from dataclasses import replace

    from ..result import Status
    from ..solve import certify_root

    if r.converged or r.status not in (Status.MAX_ITER, Status.STALLED, Status.PRECISION_LIMIT):
        return r
    if r.error <= tol:
        verdict, why, n = certify_root(problem, r.x, r.residual, tol)
        if verdict is Status.CONVERGED_STEP:
            return replace(r, status=verdict, nfev=r.nfev + n,
                           detail=why or f"certified after {r.status.value}: the last step is "
                                         "within the tolerance and f is zero to its rounding")
    elif isinstance(r.residual, float) and abs(r.residual) <= problem.fbound(r.x):
        return replace(r, status=Status.PRECISION_LIMIT,
                       detail=f"f is zero to its rounding, but rounding moves the root by about "
                              f"{r.error:.1g} deg, above the tolerance {tol:g}")
    return r


def slope(alpha: float, phi: float, rs: tuple[float, float, float]) -> float:
    """dphi/dalpha on the branch: -(df/dalpha) / (df/dphi), both per degree."""
    from ..problems.freudenstein import fourbar_equation

    p = fourbar_equation(alpha, *rs)
    h = 1e-6
    dfa = (fourbar_equation(alpha + h, *rs).f(phi) - p.f(phi)) / h
    dfp = p.fprime(phi) if p.fprime is not None else RAD_PER_DEG
    return -dfa / dfp if dfp else 0.0
