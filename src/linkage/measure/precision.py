"""Work precision: run time against achieved error, for every method and the alternatives.

For each problem and each tolerance, every contender solves the same problem many
times: the median time per solve over several timed batches (and their spread), the
achieved error against a 40-digit mpmath reference, iterations and evaluations.
Contenders: linkage's methods (the registry, :data:`linkage.methods.METHODS`) with history
recording on and off; scipy.optimize when scipy is installed (root_scalar's counterpart of
each registered method that has one, and its bracketing methods that have none; root's
hybr and lm; fsolve); and a plain hand-written Newton loop (:mod:`.hand`), the floor any
library pays over.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Any

from ..records import frozen
from .hand import hand_newton, hand_newton_2x2
from .timing import time_per_call

QUICK_TOLERANCES = (1e-3, 1e-8, 1e-13)
FULL_TOLERANCES = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
PROBLEMS = ("freudenstein", "quadratic", "fourbar", "rapier")
SCIPY_BRACKETING = ("brentq", "ridder", "toms748")
"""root_scalar's bracketing methods that no registered method runs (the registry's ``scipy``)."""
SCIPY_KEYWORDS = {"fprime": "fprime", "fsecond": "fprime2"}
"""root_scalar's keyword for each problem function a registered method needs."""


@frozen
class Measurement:
    problem: str
    contender: str
    tol: float
    seconds: float  # median per solve
    spread: tuple[float, float]  # min and max of the batch medians
    error: float
    iterations: int | None
    nfev: int | None


# --- problems ----------------------------------------------------------------------------------


def scalar_problem(name: str) -> dict[str, Any]:
    """A bench problem from the registry, with its root at 40 digits (the reference)."""
    import mpmath as mp

    from ..problems.catalog import BENCH_SCALAR, entry

    e = entry(BENCH_SCALAR[name])
    if e.equation is None:  # the Freudenstein four-bar equation at alpha = 70 deg
        d = mp.pi / 180
        with mp.workdps(40):
            a = 70 * d
            big_a, big_b = mp.mpf(5) / 2 + mp.cos(a), mp.sin(a)
            k = mp.mpf(5) / 3 * mp.cos(a) + mp.mpf(11) / 6
            root = float(mp.degrees(mp.atan2(big_b, big_a) + mp.acos(k / mp.sqrt(big_a**2 + big_b**2))))
    else:
        with mp.workdps(40):
            root = float(mp.findroot(lambda x: x**2 - 4 * x + 1, e.x0))
    return {"problem": e.problem(), "bracket": e.bracket, "x0": e.x0, "x1": e.x1, "root": root}


def system_problem(name: str) -> dict[str, Any]:

    import mpmath as mp

    from ..kinematics.loading import load
    from ..problems.catalog import BENCH_SYSTEMS
    from ..samples import sample_path
    from .stress_cases import mp_fourbar_positions

    m = load(sample_path(BENCH_SYSTEMS[name]))
    p = m.problem()
    if name == "fourbar":
        exact = mp_fourbar_positions(90, 30, 60, 45, 65.0)["open"]
        root = (exact["theta3"], exact["theta4"])
    else:
        from ..problems.loops import DRIVER, LoopModel

        model = LoopModel.compile(m)
        drv = mp.mpf(m.driver.value)

        def fmp(*q: Any) -> list[Any]:
            out = []
            for terms in model.terms:
                x = y = mp.mpf(0)
                for sign, lc, li, ac, ai, off in terms:
                    r = q[li] if li >= 0 else (drv if li == DRIVER else mp.mpf(lc))
                    th = (q[ai] if ai >= 0 else (drv if ai == DRIVER else mp.mpf(ac))) + mp.mpf(off)
                    x += sign * r * mp.cos(th)
                    y += sign * r * mp.sin(th)
                out += [x, y]
            return out

        with mp.workdps(40):
            root = tuple(float(v) for v in mp.findroot(fmp, [mp.mpf(v) for v in p.x0]))
    return {"problem": p, "x0": p.x0, "root": root}


def scalar_contenders(
    spec: dict[str, Any], tol: float
) -> list[tuple[str, Callable[[], Any], Callable[[Any], Any]]]:
    """(name, call, summarise) where summarise turns the call's value into (x, iters, nfev)."""
    from ..methods import METHODS
    from ..solve import solve_scalar

    p = spec["problem"]
    # the registered methods whose needs the problem supplies (a g for fixed point, say)
    entries = [e for e in METHODS.values() if all(getattr(p, attr) is not None for attr, _ in e.needs)]
    out: list[tuple[str, Callable[[], Any], Callable[[Any], Any]]] = []
    for e in entries:
        kw: dict[str, Any] = (
            {"bracket": spec["bracket"]} if e.bracketing else {"x0": spec["x0"], "x1": spec["x1"]}
        )
        for record in (False, True):
            out.append(
                (
                    f"linkage {e.name} (history {'on' if record else 'off'})",
                    lambda m=e.name, kw=kw, record=record: solve_scalar(
                        p, method=m, tol=tol, max_iter=2000, record=record, **kw
                    ),
                    lambda r: (r.x, r.iterations, r.nfev),
                )
            )
    f, fp = p.f, p.fprime
    out.append(
        (
            "hand-written Newton (10 lines)",
            lambda: hand_newton(f, fp, spec["x0"], tol),
            lambda x: (x, None, None),
        )
    )
    try:
        from scipy.optimize import root_scalar
    except ImportError:
        return out
    scipy_runs = [(e.scipy, scipy_keywords(e, spec)) for e in entries if e.scipy is not None]
    scipy_runs += [(method, scipy_bracket(spec)) for method in SCIPY_BRACKETING]
    for method, kw in scipy_runs:
        out.append(
            (
                f"scipy root_scalar {method}",
                lambda method=method, kw=kw: root_scalar(f, method=method, xtol=tol, **kw),
                lambda r: (r.root, r.iterations, r.function_calls),
            )
        )
    return out


def scipy_bracket(spec: dict[str, Any]) -> dict[str, Any]:
    """root_scalar's keywords for a bracketing method: the bracket, and the relative
    tolerance at scipy's own default for brentq, 4 eps."""
    return {"bracket": spec["bracket"], "rtol": 4 * sys.float_info.epsilon}


def scipy_keywords(entry: Any, spec: dict[str, Any]) -> dict[str, Any]:
    """root_scalar's start and functions for the registered method ``entry``, from its
    ``starts`` and ``needs``."""
    if entry.bracketing:
        return scipy_bracket(spec)
    kw: dict[str, Any] = {"x0": spec["x0"]}
    if entry.starts == "x0 x1":
        kw["x1"] = spec["x1"]
    p = spec["problem"]
    kw.update({SCIPY_KEYWORDS[attr]: getattr(p, attr) for attr, _ in entry.needs})
    return kw


def system_contenders(
    name: str, spec: dict[str, Any], tol: float
) -> list[tuple[str, Callable[[], Any], Callable[[Any], Any]]]:
    from ..solve import SYSTEM_METHODS, solve_system

    p = spec["problem"]
    out: list[tuple[str, Callable[[], Any], Callable[[Any], Any]]] = []
    for m in SYSTEM_METHODS:
        for record in (False, True):
            out.append(
                (
                    f"linkage {m} (history {'on' if record else 'off'})",
                    lambda m=m, record=record: solve_system(
                        p, method=m, tol=tol, max_iter=100, record=record
                    ),
                    lambda r: (r.x, r.iterations, r.nfev),
                )
            )
    if name == "fourbar":
        # target 2 is stated for user callables: the same F and J passed as plain
        # functions, as the hand loop and scipy get them
        x0 = tuple(float(v) for v in spec["x0"])
        out.append(
            (
                "linkage newton, callables F and J (history off)",
                lambda: solve_system(p.F, x0, jac=p.J, tol=tol, max_iter=100, record=False),
                lambda r: (r.x, r.iterations, r.nfev),
            )
        )
        out.append(
            (
                "hand-written 2x2 Newton (Cramer)",
                lambda: hand_newton_2x2(p.F, p.J, spec["x0"], tol),
                lambda x: (x, None, None),
            )
        )
    try:
        from scipy.optimize import fsolve, root
    except ImportError:
        return out
    for method in ("hybr", "lm"):
        out.append(
            (
                f"scipy root {method} (analytic J)",
                lambda method=method: root(p.F, spec["x0"], jac=p.J, method=method, options={"xtol": tol}),
                lambda r: (tuple(r.x), None, r.nfev),
            )
        )
    out.append(
        (
            "scipy fsolve (analytic J)",
            lambda: fsolve(p.F, spec["x0"], fprime=p.J, xtol=tol, full_output=True),
            lambda r: (tuple(r[0]), None, r[1]["nfev"]),
        )
    )
    return out


def error_of(x: Any, root: Any) -> float:
    if isinstance(root, tuple):
        return max(abs(a - b) for a, b in zip(x, root))
    return abs(x - root)


def count_measurements(problems: Sequence[str], tolerances: Sequence[float]) -> int:
    """How many measurements ``measure`` will make (for a progress bar)."""
    total = 0
    for name in problems:
        spec = scalar_problem(name) if name in ("freudenstein", "quadratic") else system_problem(name)
        contenders = (scalar_contenders(spec, 1e-6) if name in ("freudenstein", "quadratic")
                      else system_contenders(name, spec, 1e-6))
        total += len(contenders) * len(tolerances)
    return total


def measure(
    problems: Sequence[str],
    tolerances: Sequence[float],
    repeats: int,
    budget: float,
    progress: Callable[[str], None] | None = None,
) -> list[Measurement]:
    out = []
    for name in problems:
        spec = scalar_problem(name) if name in ("freudenstein", "quadratic") else system_problem(name)
        for tol in tolerances:
            contenders = (
                scalar_contenders(spec, tol)
                if name in ("freudenstein", "quadratic")
                else system_contenders(name, spec, tol)
            )
            for label, call, summarise in contenders:
                if progress:
                    progress(f"{name} {label} tol {tol:g}")
                try:
                    value = call()
                except Exception:
                    continue
                x, iters, nfev = summarise(value)
                med, lo, hi = time_per_call(call, repeats, budget)
                out.append(
                    Measurement(name, label, tol, med, (lo, hi), error_of(x, spec["root"]), iters, nfev)
                )
    return out


def has_pylinkage() -> bool:
    try:
        import pylinkage  # noqa: F401
    except ImportError:
        return False
    return True


def has_scipy() -> bool:
    try:
        import scipy  # noqa: F401
    except ImportError:
        return False
    return True


MEASUREMENT_HEADERS = ("problem", "contender", "tol", "time per solve (us)", "fastest batch (us)",
                       "slowest batch (us)", "error", "iterations", "evaluations")


def measurement_rows(results: Sequence[Any]) -> list[tuple[Any, ...]]:
    """The measurements as the table's rows, times in microseconds."""
    return [(m.problem, m.contender, m.tol, m.seconds * 1e6,
             m.spread[0] * 1e6, m.spread[1] * 1e6, m.error, m.iterations, m.nfev)
            for m in results]
