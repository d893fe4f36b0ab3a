"""``linkage stress``: a seeded battery that tries to break every method.

Families (expected outcome in brackets; a deviation is counted when it does not hold):

1. ``classic``: the Alefeld-Potra-Shi test functions (ACM TOMS 748, 1995, Table 1, with
   their parameters and brackets) and Chandrupatla's test functions (Adv. Eng. Software
   28, 1997), plus multiple roots, a jump and a pole inside a bracket. [Every method
   either converges to the reference root, or stops with a named reason; at a jump or a
   pole no method may claim a root.]
2. ``fourbar-equation`` and ``fourbar``: random Freudenstein input-output equations (closed
   form for both roots) and random four-bar loop systems, link ratios 1e-3..1e3,
   absolute scales 1e-6..1e6, some within 1e-8 deg of a limit position. [Converge to
   the root or branch started near, another one, or stop with a named reason.]
3. ``bad-starts``: Newton at f' = 0, at an inflection point, far from any root, on a
   Newton cycle (x^3 - 2x + 2 from 0), on the wrong branch. [A named stop, or any root.]
4. ``tiny-tol``: tolerances at and below machine epsilon. [Converged only if the answer
   really is that good (or f is exactly zero); otherwise precision_limit, never a run to
   the iteration cap.]
5. ``non-finite``: NaN or inf from f, from f', or given as input. [A named stop
   (non_finite, domain_error) or an input error; never a claimed root.]

A result is *false convergence* when it claims convergence but is farther from every
reference root than its tolerance allows (and f is not exactly zero there), or claims
convergence where there is no root. That count must be 0. Reference roots come from
40-digit mpmath (or closed forms), never from the methods under test.
"""

from __future__ import annotations

import math
import random
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError
from ..methods import SCALAR_METHODS
from ..problems.catalog import Case, classic_cases, mgh_cases
from ..solve.system import SYSTEM_METHODS
from ..units import degrees
from .stress_cases import (
    bad_start_cases,
    fourbar_cases,
    fourbar_equation_cases,
    fourbar_mechanism,
    mp_fourbar_positions,
    non_finite_cases,
    tiny_tol_cases,
)

EPS = sys.float_info.epsilon


@dataclass
class Tally:
    cases: int = 0
    right: int = 0
    other: int = 0
    failed: int = 0
    false: int = 0
    crashed: int = 0
    iterations: list[int] = field(default_factory=list)
    worst_error: float = 0.0
    examples: list[str] = field(default_factory=list)


# --- running ------------------------------------------------------------------------------------


def start_arguments(case: Case, method: str) -> dict[str, Any] | None:
    if method in ("bisection", "regula-falsi", "hybrid"):
        return {"bracket": case.bracket} if case.bracket is not None else None
    if method == "secant":
        if case.x0 is None:
            return None
        x1 = (
            case.x1
            if case.x1 is not None
            else (case.x0 + 0.5 if case.bracket is None else 0.5 * (case.bracket[0] + case.bracket[1]))
        )
        return {"x0": case.x0, "x1": x1} if x1 != case.x0 else None
    if method == "newton":
        return {"x0": case.x0} if case.x0 is not None and case.fprime is not None else None
    if method == "fixed-point":
        return {"x0": case.x0} if case.x0 is not None and case.g is not None else None
    return None


def allowed_error(case: Case, root: float) -> float:
    """How far from the root a claimed convergence may be: the tolerance the method was
    given (the step test bounds the error only up to a modest factor for open methods),
    never less than a few units in the last place, plus the problem's conditioning
    (rounding in f moves an ill-conditioned root; no method can do better)."""
    return (
        10.0 * (case.tol + case.rtol * abs(root)) + 4.0 * math.ulp(root) + 4.0 * EPS * abs(root) + case.slack
    )


def judge(case: Case, result: Any, tally: Tally) -> None:
    tally.cases += 1
    tally.iterations.append(result.iterations)
    if not result.converged:
        tally.failed += 1
        return
    x = result.x
    fx = result.residual
    if not case.roots:
        tally.false += 1
        tally.examples.append(
            f"{case.name}: claimed {result.status.value} at x = {x!r} where there is no root"
        )
        return
    err = min(abs(x - r) for r in case.roots)
    nearest = min(case.roots, key=lambda r: abs(x - r))
    tally.worst_error = max(tally.worst_error, err)
    exact_zero = fx == 0.0 or (isinstance(fx, float) and case.f(x) == 0.0)
    if err <= allowed_error(case, nearest) or exact_zero:
        if nearest == case.roots[0] or len(case.roots) == 1:
            tally.right += 1
        else:
            tally.other += 1
        return
    tally.false += 1
    tally.examples.append(
        f"{case.name}: claimed {result.status.value} at x = {x!r}, "
        f"{err:.3g} from the root {nearest!r} (tol {case.tol:g}, rtol {case.rtol:g})"
    )


def run_scalar(cases: Sequence[Case], methods: Sequence[str]) -> dict[tuple[str, str], Tally]:
    from ..solve import solve_scalar

    tallies: dict[tuple[str, str], Tally] = {}
    for case in cases:
        for method in methods:
            start = start_arguments(case, method)
            if start is None:
                continue
            t = tallies.setdefault((case.family, method), Tally())
            try:
                result = solve_scalar(
                    case.f,
                    method=method,
                    fprime=case.fprime,
                    g=case.g,
                    tol=case.tol,
                    rtol=case.rtol,
                    max_iter=2000 if method == "bisection" else 500,
                    record=False,
                    **start,
                )
            except InputError:
                t.cases += 1
                t.failed += 1  # refused at the front door, with a message: a named outcome
                continue
            except Exception as exc:
                t.cases += 1
                t.crashed += 1
                t.examples.append(f"{case.name}: {type(exc).__name__}: {exc}")
                continue
            judge(case, result, t)
    return tallies


def run_fourbars(items: Sequence[dict[str, Any]], methods: Sequence[str]) -> dict[tuple[str, str], Tally]:
    from ..problems.closed_form import wrap_degrees
    from ..solve import solve_system

    tallies: dict[tuple[str, str], Tally] = {}
    for it in items:
        problem = fourbar_mechanism(it).problem()
        for method in methods:
            t = tallies.setdefault(("fourbar", method), Tally())
            t.cases += 1
            try:
                result = solve_system(problem, method=method, tol=1e-10, max_iter=100, record=False)
            except Exception as exc:
                t.crashed += 1
                t.examples.append(f"links {it['links']}: {type(exc).__name__}: {exc}")
                continue
            t.iterations.append(result.iterations)
            if not result.converged:
                t.failed += 1
                continue
            t3, t4 = (degrees(v) for v in result.x)
            reference = mp_fourbar_positions(*it["links"], it["theta2"])
            errs = {
                b: max(
                    abs(wrap_degrees(t3 - degrees(s["theta3"]))),
                    abs(wrap_degrees(t4 - degrees(s["theta4"]))),
                )
                for b, s in reference.items()
            }
            best = min(errs, key=errs.get) if errs else None
            # near a limit the two branches merge: sqrt(1e-8 deg) apart is one position
            allow = 1e-6 if not it["near_limit"] else 1e-2
            if best is not None and errs[best] <= allow:
                t.worst_error = max(t.worst_error, errs[best])
                if best == it["branch"]:
                    t.right += 1
                else:
                    t.other += 1
            else:
                t.false += 1
                t.examples.append(
                    f"links {it['links']}, theta2 {it['theta2']}: claimed {result.status.value} "
                    f"{min(errs.values()) if errs else math.nan:.3g} deg from the closed form"
                )
    return tallies


def hybrid_against_bisection(cases: Sequence[Case]) -> dict[str, Any]:
    """Done-when 2 of the stress issue: the hybrid on every bracketed classic case."""
    from ..solve import solve_scalar

    rows = []
    for case in cases:
        if case.bracket is None or not case.roots:
            continue
        fa, fb = case.f(case.bracket[0]), case.f(case.bracket[1])
        if not ((fa < 0) != (fb < 0) or fa == 0 or fb == 0):
            continue
        h, b = (solve_scalar(case.f, method=method, bracket=case.bracket, tol=1e-300, rtol=4 * EPS,
                             max_iter=cap, record=False)
                for method, cap in (("hybrid", 2000), ("bisection", 4000)))
        r = case.roots[0]
        ok = h.converged and (abs(h.x - r) <= 4 * EPS * abs(r) or case.f(h.x) == 0.0)
        rows.append((case.name, ok, h.iterations, b.iterations, h.status.value))
    return {
        "cases": len(rows),
        "within_4_eps": sum(r[1] for r in rows),
        "hybrid_iterations": sum(r[2] for r in rows),
        "bisection_iterations": sum(r[3] for r in rows),
        "failures": [r for r in rows if not r[1]],
        "rows": rows,
    }


def run_mgh(methods: Sequence[str]) -> dict[tuple[str, str], Tally]:
    """The 66 Moré-Garbow-Hillstrom square systems (MINPACK's hybrd tests) with the exact
    Jacobian: a success with max|F| above ``SOLVED_RESIDUAL`` is a false convergence;
    with scipy installed, scipy's hybr and lm run beside ours."""
    from .mgh_table import SOLVED_RESIDUAL, has_scipy, ours, scipy_root

    solvers: dict[str, Any] = {}
    for m in methods:
        if m == "newton":
            solvers["newton"] = ours("newton", True, "newton")
        elif m == "lm":
            solvers["lm"] = ours("lm", True, "lm")
    if has_scipy() and solvers:
        solvers["scipy-hybr"] = scipy_root("hybr")
        solvers["scipy-lm"] = scipy_root("lm")
    tallies: dict[tuple[str, str], Tally] = {}
    for label, system, factor in mgh_cases():
        for name, solver in solvers.items():
            t = tallies.setdefault(("mgh", name), Tally())
            t.cases += 1
            try:
                o = solver(label, system, system.start(factor))
            except Exception as exc:  # a crash is what this battery exists to find
                t.crashed += 1
                t.examples.append(f"{label}: {type(exc).__name__}: {exc}")
                continue
            if o.solved:
                t.right += 1
            elif o.false_success:
                t.false += 1
                t.examples.append(f"{label}: claimed success with max|F| = {o.residual:.3g} "
                                  f"> {SOLVED_RESIDUAL:g}")
            else:
                t.failed += 1
    return tallies


def scalar_methods_of(methods: Sequence[str] | None) -> list[str]:
    """The scalar methods a run with ``--method`` ``methods`` (None: all) tries."""
    return [m for m in (methods or SCALAR_METHODS) if m in SCALAR_METHODS]


def stress_tables(methods: Sequence[str] | None) -> tuple[str, ...]:
    """The tables of the battery's report (render.tools.stress_report): the summary, and
    the hybrid's record where the run tries the hybrid."""
    return ("summary", "hybrid") if "hybrid" in scalar_methods_of(methods) else ("summary",)


def run(
    quick: bool = True,
    seed: int = 0,
    methods: Sequence[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """The whole battery; deterministic for a given seed."""
    rng = random.Random(seed)
    t0 = time.perf_counter()
    scalar_methods = scalar_methods_of(methods)
    system_methods = [m for m in (methods or SYSTEM_METHODS) if m in SYSTEM_METHODS]
    classic = classic_cases()
    if quick:
        classic = classic[::3] + classic[-3:]
    tallies: dict[tuple[str, str], Tally] = {}
    equations = fourbar_equation_cases(rng, 60 if quick else 600)
    for family, cases in (
        ("classic", classic),
        ("fourbar-equation", equations),
        ("bad-starts", bad_start_cases()),
        ("tiny-tol", tiny_tol_cases()),
        ("non-finite", non_finite_cases()),
    ):
        if progress:
            progress(family)
        tallies.update(run_scalar(cases, scalar_methods))
    if progress:
        progress("fourbar")
    tallies.update(run_fourbars(fourbar_cases(rng, 60 if quick else 1500), system_methods))
    if not quick:
        if progress:
            progress("mgh")
        tallies.update(run_mgh(system_methods))
    hybrid = hybrid_against_bisection(classic) if "hybrid" in scalar_methods else None
    return {
        "seed": seed,
        "quick": quick,
        "seconds": time.perf_counter() - t0,
        "tallies": tallies,
        "hybrid": hybrid,
    }


def is_reference(method: str) -> bool:
    """Rows of other libraries (scipy), shown for comparison and not counted as ours."""
    return method.startswith("scipy")


def totals(rows: Sequence[tuple[Any, ...]]) -> tuple[int, int]:
    """(false convergences, crashes) of our own solvers."""
    ours = [r for r in rows if not is_reference(r[1])]
    return sum(r[6] for r in ours), sum(r[7] for r in ours)


def summary_rows(report: dict[str, Any]) -> list[tuple[Any, ...]]:
    rows = []
    for (family, method), t in sorted(report["tallies"].items()):
        its = t.iterations or [0]
        rows.append(
            (
                family,
                method,
                t.cases,
                t.right,
                t.other,
                t.failed,
                t.false,
                t.crashed,
                statistics.median(its),
                max(its),
                t.worst_error,
            )
        )
    return rows


SUMMARY_HEADERS = (
    "family",
    "method",
    "cases",
    "right root/branch",
    "other root/branch",
    "failed (named)",
    "false convergence",
    "crashes",
    "median iterations",
    "worst iterations",
    "worst error",
)
