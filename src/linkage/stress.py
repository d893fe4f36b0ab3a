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

from .errors import InputError
from .methods import SCALAR_METHODS
from .problems.catalog import Case, classic_cases, mgh_cases
from .problems.classic import mp_root

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


# --- family 2: random four-bar loop systems ---------------------------------------------------


def fourbar_cases(rng: random.Random, count: int) -> list[dict[str, Any]]:
    from .problems.closed_form import Indeterminate, cos_band_arcs, fourbar_positions

    out: list[dict[str, Any]] = []
    while len(out) < count:
        scale = 10 ** rng.uniform(-6, 6)
        ratios = [10 ** rng.uniform(-3, 3) for _ in range(3)]
        r1 = scale
        r2, r3, r4 = (scale * x for x in ratios)
        near_limit = rng.random() < 0.3
        lo, hi = (r3 - r4) ** 2, (r3 + r4) ** 2
        arcs = cos_band_arcs(
            (r1 * r1 + r2 * r2 - hi) / (2 * r1 * r2), (r1 * r1 + r2 * r2 - lo) / (2 * r1 * r2), 0.0
        )
        if arcs == []:
            continue
        if arcs is None:
            theta2 = rng.uniform(-180, 180)
            near_limit = False
        else:
            a, b = arcs[rng.randrange(len(arcs))]
            if b - a < 1e-6:
                continue
            theta2 = (b - 1e-8 if rng.random() < 0.5 else a + 1e-8) if near_limit else rng.uniform(a, b)
        try:
            if not fourbar_positions(r1, r2, r3, r4, 0.0, theta2=math.radians(theta2)):
                continue
        except Indeterminate:
            continue
        sols = mp_fourbar_positions(r1, r2, r3, r4, theta2)
        if not sols:
            continue
        branch = rng.choice(sorted(sols))
        exact = sols[branch]
        perturb = 0.0 if near_limit else rng.uniform(-8, 8)
        out.append(
            {
                "links": (r1, r2, r3, r4),
                "theta2": theta2,
                "branch": branch,
                "exact": exact,
                "guess": (math.degrees(exact["theta3"]) + perturb, math.degrees(exact["theta4"]) - perturb),
                "near_limit": near_limit,
                "scale": scale,
            }
        )
    return out


def fourbar_equation_cases(rng: random.Random, count: int) -> list[Case]:
    """Random Freudenstein equations: (R2 + cos a) cos phi + sin a sin phi = R1 cos a + R3, so
    phi = atan2(sin a, R2 + cos a) +- acos(K / sqrt(A^2 + B^2)) in closed form; some
    within 1e-8 deg of the limit where the two roots merge."""
    from .problems.freudenstein import fourbar_equation

    out: list[Case] = []
    while len(out) < count:
        r1, r2 = 10 ** rng.uniform(-3, 3), 10 ** rng.uniform(-3, 3)
        alpha = rng.uniform(-180, 180)
        a = math.radians(alpha)
        big_a, big_b = r2 + math.cos(a), math.sin(a)
        norm = math.hypot(big_a, big_b)
        if norm == 0.0:
            continue
        near = rng.random() < 0.2
        # choose R3 so that |K| / norm is a random ratio below 1 (or within 1e-12 of it)
        ratio = (1 - 1e-12) if near else rng.uniform(-0.99, 0.99)
        r3 = ratio * norm - r1 * math.cos(a)
        roots = _mp_fourbar_roots(alpha, r1, r2, r3)
        if roots is None:
            continue
        p = fourbar_equation(alpha, r1, r2, r3)
        # f's rounding (terms of size |K|, |A|, |B| cancel) moves a root by eps_f / |f'|
        terms = abs(r1 * math.cos(a)) + abs(r3) + abs(r2) + 2.0  # the sizes that cancel in f
        slope = min(abs(p.fprime(r)) for r in roots)  # type: ignore[misc]
        slack = 16 * EPS * terms / slope if slope > 0 else math.inf
        root = roots[0]
        width = max(1e-6, min(abs(roots[0] - roots[1]) / 3, rng.uniform(0.1, 20)))
        bracket = (root - width * rng.uniform(0.1, 1), root + width * rng.uniform(0.1, 1))
        if p.f(bracket[0]) * p.f(bracket[1]) >= 0:
            bracket = None  # type: ignore[assignment]
        x0 = root + rng.uniform(-1, 1) * (width if not near else 1e-3)
        out.append(
            Case(
                "fourbar-equation",
                f"R=({r1:.3g},{r2:.3g},{r3:.3g}) alpha={alpha:.4g}",
                p.f,
                p.fprime,
                bracket,
                x0,
                x0 + 0.1 * width,
                roots + tuple(r + 360 * k for r in roots for k in (-1, 1)),
                tol=1e-10,
                g=None,
                slack=slack,
            )
        )
    return out


def _mp_fourbar_roots(alpha: float, r1: float, r2: float, r3: float) -> tuple[float, float] | None:
    """Both roots (deg) of the Freudenstein equation in closed form, at 40 digits, from the
    exact double inputs: phi = atan2(B, A) +- acos(K / sqrt(A^2 + B^2))."""
    import mpmath as mp

    with mp.workdps(40):
        a = mp.radians(mp.mpf(alpha))
        big_a, big_b = mp.mpf(r2) + mp.cos(a), mp.sin(a)
        k = mp.mpf(r1) * mp.cos(a) + mp.mpf(r3)
        ratio = k / mp.sqrt(big_a**2 + big_b**2)
        if abs(ratio) > 1:
            return None
        base, half = mp.atan2(big_b, big_a), mp.acos(ratio)
        return float(mp.degrees(base + half)), float(mp.degrees(base - half))


# --- families 3 to 5 ---------------------------------------------------------------------------


def bad_start_cases() -> list[Case]:
    from .problems.expression import equation_problem

    def eq(text: str) -> tuple[Callable[[float], float], Callable[[float], float]]:
        p = equation_problem(text)
        return p.f, p.fprime  # type: ignore[return-value]

    q, qp = eq("x**2 - 4*x + 1")
    c, cp = eq("x**3 - 2*x + 2")
    a, ap = eq("atan(x)")
    k, kp = eq("x - 0.8*sin(x) - 1")
    roots_q = (2 - math.sqrt(3), 2 + math.sqrt(3))
    return [
        Case("bad-starts", "f' = 0 at the start", q, qp, None, 2.0, 2.5, roots_q),
        Case("bad-starts", "near f' = 0 (P1, x0 = 2.5)", q, qp, None, 2.5, 2.4, roots_q),
        Case("bad-starts", "Newton cycle x^3 - 2x + 2 from 0", c, cp, None, 0.0, 1.0, (-1.7692923542386314,)),
        Case("bad-starts", "inflection, atan from 1.5", a, ap, None, 1.5, 1.6, (0.0,)),
        Case("bad-starts", "far start, atan from 1e6", a, ap, None, 1e6, 2e6, (0.0,)),
        Case("bad-starts", "far start, Kepler from 1e3", k, kp, None, 1e3, 900.0, (mp_root_kepler(),)),
        Case("bad-starts", "no real root, x**2 + 1e-3", *eq("x**2 + 1e-3"), None, 1.0, 0.5, ()),
    ]


def mp_root_kepler() -> float:
    import mpmath as mp

    return mp_root(lambda x: x - mp.mpf("0.8") * mp.sin(x) - 1, 0.0, 3.0)


def tiny_tol_cases() -> list[Case]:
    out = []
    for tol in (EPS, EPS / 4, 1e-20, 1e-300):
        out.append(
            Case(
                "tiny-tol",
                f"sqrt 2, tol {tol:.2g}",
                lambda x: x * x - 2,
                lambda x: 2 * x,
                (1.0, 2.0),
                1.0,
                2.0,
                (math.sqrt(2),),
                tol=tol,
            )
        )
        out.append(
            Case(
                "tiny-tol",
                f"Freudenstein four-bar, tol {tol:.2g}",
                *_fourbar_fd(),
                (50.0, 60.0),
                50.0,
                60.0,
                (54.887763188779143,),
                tol=tol,
            )
        )
        out.append(
            Case(
                "tiny-tol",
                f"x**2 - 4 (exact root 2), tol {tol:.2g}",
                lambda x: x * x - 4,
                lambda x: 2 * x,
                (0.0, 3.0),
                3.0,
                2.5,
                (2.0,),
                tol=tol,
            )
        )
    return out


def _fourbar_fd() -> tuple[Callable[[float], float], Callable[[float], float]]:
    from .problems.freudenstein import fourbar_equation

    p = fourbar_equation(70.0)
    return p.f, p.fprime  # type: ignore[return-value]


def non_finite_cases() -> list[Case]:
    nan, inf = math.nan, math.inf
    return [
        Case(
            "non-finite",
            "f is NaN left of 0.5",
            lambda x: nan if x < 0.5 else x - 1,
            lambda x: 1.0,
            (0.0, 2.0),
            0.0,
            0.2,
            (1.0,),
        ),
        Case(
            "non-finite",
            "f is inf at the start",
            lambda x: inf if x == 0 else x - 1,
            lambda x: 1.0,
            (0.0, 2.0),
            0.0,
            3.0,
            (1.0,),
        ),
        Case("non-finite", "f' is NaN", lambda x: x - 1, lambda x: nan, None, 3.0, 2.0, (1.0,)),
        Case(
            "non-finite",
            "f overflows",
            lambda x: math.exp(x) - 1e300 if x < 700 else math.exp(x),
            lambda x: math.exp(x),
            None,
            800.0,
            790.0,
            (math.log(1e300),),
        ),
        Case(
            "non-finite",
            "sqrt(x) - 1 from -1 (domain)",
            lambda x: math.sqrt(x) - 1,
            lambda x: 0.5 / math.sqrt(x),
            None,
            -1.0,
            0.5,
            (1.0,),
        ),
        Case("non-finite", "NaN start", lambda x: x - 1, lambda x: 1.0, (nan, 2.0), nan, nan, (1.0,)),
        Case("non-finite", "inf bracket", lambda x: x - 1, lambda x: 1.0, (-inf, inf), inf, 2.0, (1.0,)),
    ]


# --- running ------------------------------------------------------------------------------------


def _start(case: Case, method: str) -> dict[str, Any] | None:
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
    from .solve import solve_scalar

    tallies: dict[tuple[str, str], Tally] = {}
    for case in cases:
        for method in methods:
            start = _start(case, method)
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


def mp_fourbar_positions(
    r1: float, r2: float, r3: float, r4: float, theta2_deg: float
) -> dict[str, dict[str, float]]:
    """Both branches (rad) at 40 digits: the double-precision circle intersection loses
    half its digits when the circles are nearly tangent (a tiny coupler)."""
    import mpmath as mp

    with mp.workdps(40):
        t2 = mp.radians(mp.mpf(theta2_deg))
        ax, ay = mp.mpf(r2) * mp.cos(t2), mp.mpf(r2) * mp.sin(t2)
        dx, dy = ax - r1, ay
        d = mp.sqrt(dx * dx + dy * dy)
        if d == 0 or d > r3 + r4 or d < abs(mp.mpf(r3) - r4):
            return {}
        a = (mp.mpf(r4) ** 2 - mp.mpf(r3) ** 2 + d * d) / (2 * d)
        h = mp.sqrt(max(mp.mpf(r4) ** 2 - a * a, 0))
        ux, uy = dx / d, dy / d
        out = {}
        for sign in (1, -1):
            bx, by = r1 + a * ux - sign * h * uy, a * uy + sign * h * ux
            t3, t4 = mp.atan2(by - ay, bx - ax), mp.atan2(by, bx - r1)
            out["open" if mp.sin(t4 - t3) > 0 else "crossed"] = {"theta3": float(t3), "theta4": float(t4)}
        return out


def fourbar_mechanism(it: dict[str, Any]) -> Any:
    """A random four-bar of :func:`fourbar_cases` as a mechanism (metres, closed form)."""
    from .kinematics.loading import parse_mechanism

    r1, r2, r3, r4 = it["links"]
    unit = {"unit": "m"}
    doc = {
        "name": "random four-bar",
        "length_unit": "m",
        "parameters": {
            "r1": {"value": r1, **unit},
            "r2": {"value": r2, **unit},
            "r3": {"value": r3, **unit},
            "r4": {"value": r4, **unit},
            "theta1": {"value": 0.0, "unit": "deg"},
        },
        "driver": {"name": "theta2", "value": it["theta2"], "unit": "deg"},
        "unknowns": {
            "theta3": {"guess": it["guess"][0], "unit": "deg"},
            "theta4": {"guess": it["guess"][1], "unit": "deg"},
        },
        "loops": [
            {
                "name": "L",
                "vectors": [
                    {"length": "r2", "angle": "theta2"},
                    {"length": "r3", "angle": "theta3"},
                    {"length": "r4", "angle": "theta4", "sign": -1},
                    {"length": "r1", "angle": "theta1", "sign": -1},
                ],
            }
        ],
    }
    return parse_mechanism(doc)


def run_fourbars(items: Sequence[dict[str, Any]], methods: Sequence[str]) -> dict[tuple[str, str], Tally]:
    from .problems.closed_form import wrap_degrees
    from .solve import solve_system

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
            t3, t4 = (math.degrees(v) for v in result.x)
            reference = mp_fourbar_positions(*it["links"], it["theta2"])
            errs = {
                b: max(
                    abs(wrap_degrees(t3 - math.degrees(s["theta3"]))),
                    abs(wrap_degrees(t4 - math.degrees(s["theta4"]))),
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
    from .solve import solve_scalar

    rows = []
    for case in cases:
        if case.bracket is None or not case.roots:
            continue
        fa, fb = case.f(case.bracket[0]), case.f(case.bracket[1])
        if not ((fa < 0) != (fb < 0) or fa == 0 or fb == 0):
            continue
        h = solve_scalar(
            case.f,
            method="hybrid",
            bracket=case.bracket,
            tol=1e-300,
            rtol=4 * EPS,
            max_iter=2000,
            record=False,
        )
        b = solve_scalar(
            case.f,
            method="bisection",
            bracket=case.bracket,
            tol=1e-300,
            rtol=4 * EPS,
            max_iter=4000,
            record=False,
        )
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


def run(
    quick: bool = True,
    seed: int = 0,
    methods: Sequence[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """The whole battery; deterministic for a given seed."""
    rng = random.Random(seed)
    t0 = time.perf_counter()
    scalar_methods = [m for m in (methods or SCALAR_METHODS) if m in SCALAR_METHODS]
    system_methods = [
        m for m in (methods or ("newton", "newton-fd", "lm")) if m in ("newton", "newton-fd", "lm")
    ]
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
