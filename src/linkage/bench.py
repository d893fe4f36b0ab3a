"""``linkage bench``: run time against achieved error, for every method and the alternatives.

For each problem and each tolerance, every contender solves the same problem many
times: the median time per solve over several timed batches (and their spread), the
achieved error against a 40-digit mpmath reference, iterations and evaluations.
Contenders: linkage's methods with history recording on and off; scipy.optimize
(root_scalar's bisect, brentq, ridder, toms748, newton, secant, halley; root's hybr
and lm; fsolve) when scipy is installed; and a plain hand-written Newton loop, the
floor any library pays over. Ratios are taken between timings made in the same run.
"""

from __future__ import annotations

import math
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

QUICK_TOLERANCES = (1e-3, 1e-8, 1e-13)
FULL_TOLERANCES = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
PROBLEMS = ("freudenstein", "quadratic", "fourbar", "rapier")


@dataclass(frozen=True)
class Measurement:
    problem: str
    contender: str
    tol: float
    seconds: float  # median per solve
    spread: tuple[float, float]  # min and max of the batch medians
    error: float
    iterations: int | None
    nfev: int | None


def time_per_call(fn: Callable[[], Any], repeats: int, budget: float) -> tuple[float, float, float]:
    """Median, min and max seconds per call over ``repeats`` batches of about ``budget`` s."""
    n = 1
    while True:
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        dt = time.perf_counter() - t0
        if dt >= budget / 4 or n >= 1 << 20:
            break
        n *= 4
    n = max(1, int(n * budget / max(dt, 1e-9)))
    per = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        per.append((time.perf_counter() - t0) / n)
    return statistics.median(per), min(per), max(per)


# --- problems ----------------------------------------------------------------------------------


def scalar_problem(name: str) -> dict[str, Any]:
    """A bench problem from the registry, with its root at 40 digits (the reference)."""
    import mpmath as mp

    from .problems.catalog import BENCH_SCALAR, entry

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

    from .kinematics.loading import load
    from .problems.catalog import BENCH_SYSTEMS
    from .samples import sample_path
    from .stress import mp_fourbar_positions

    m = load(sample_path(BENCH_SYSTEMS[name]))
    p = m.problem()
    if name == "fourbar":
        exact = mp_fourbar_positions(90, 30, 60, 45, 65.0)["open"]
        root = (exact["theta3"], exact["theta4"])
    else:
        from .problems.loops import DRIVER, LoopModel

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


# --- contenders --------------------------------------------------------------------------------


def hand_newton(f: Callable[[float], float], fp: Callable[[float], float], x: float, tol: float) -> float:
    """The floor: Newton in ten lines of plain Python."""
    for _ in range(100):
        step = f(x) / fp(x)
        x -= step
        if abs(step) <= tol:
            return x
    return x


def hand_newton_2x2(
    F: Callable[..., list[float]], J: Callable[..., list[list[float]]], q: Sequence[float], tol: float
) -> tuple[float, float]:
    """The floor for a four-bar: Newton with Cramer's rule, no checks."""
    a, b = q
    for _ in range(50):
        f1, f2 = F((a, b))
        (j11, j12), (j21, j22) = J((a, b))
        det = j11 * j22 - j12 * j21
        da = (-f1 * j22 + f2 * j12) / det
        db = (-f2 * j11 + f1 * j21) / det
        a, b = a + da, b + db
        if abs(da) <= tol and abs(db) <= tol:
            break
    return a, b


def scalar_contenders(
    spec: dict[str, Any], tol: float
) -> list[tuple[str, Callable[[], Any], Callable[[Any], Any]]]:
    """(name, call, summarise) where summarise turns the call's value into (x, iters, nfev)."""
    from .methods import BRACKETING, SCALAR_METHODS
    from .solve import solve_scalar

    p = spec["problem"]
    out: list[tuple[str, Callable[[], Any], Callable[[Any], Any]]] = []
    for m in SCALAR_METHODS:
        if m == "fixed-point" and p.g is None:
            continue
        kw: dict[str, Any] = (
            {"bracket": spec["bracket"]} if m in BRACKETING else {"x0": spec["x0"], "x1": spec["x1"]}
        )
        for record in (False, True):
            name = f"linkage {m} (history {'on' if record else 'off'})"
            out.append(
                (
                    name,
                    lambda m=m, kw=kw, record=record: solve_scalar(
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
    fpp = p.fsecond
    a, b = spec["bracket"]
    for method in ("bisect", "brentq", "ridder", "toms748"):
        out.append(
            (
                f"scipy root_scalar {method}",
                lambda method=method: root_scalar(
                    f, method=method, bracket=(a, b), xtol=tol, rtol=4 * sys.float_info.epsilon
                ),
                lambda r: (r.root, r.iterations, r.function_calls),
            )
        )
    out.append(
        (
            "scipy root_scalar newton",
            lambda: root_scalar(f, method="newton", x0=spec["x0"], fprime=fp, xtol=tol),
            lambda r: (r.root, r.iterations, r.function_calls),
        )
    )
    out.append(
        (
            "scipy root_scalar secant",
            lambda: root_scalar(f, method="secant", x0=spec["x0"], x1=spec["x1"], xtol=tol),
            lambda r: (r.root, r.iterations, r.function_calls),
        )
    )
    out.append(
        (
            "scipy root_scalar halley",
            lambda: root_scalar(f, method="halley", x0=spec["x0"], fprime=fp, fprime2=fpp, xtol=tol),
            lambda r: (r.root, r.iterations, r.function_calls),
        )
    )
    return out


def system_contenders(
    name: str, spec: dict[str, Any], tol: float
) -> list[tuple[str, Callable[[], Any], Callable[[Any], Any]]]:
    from .solve import solve_system

    p = spec["problem"]
    out: list[tuple[str, Callable[[], Any], Callable[[Any], Any]]] = []
    for m in ("newton", "newton-fd", "lm"):
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


def cold_start(repeats: int = 5, extra: dict[str, list[str]] | None = None) -> dict[str, float]:
    """Median wall time of fresh interpreters running the CLI, and the floor it is
    compared with (``python -c "import rich.table"``), interleaved so that the machine's
    noise hits every command alike.

    Timed as an installed package runs: with its bytecode cached. pip compiles it at
    install time; an editable install writes it on first import, unless
    PYTHONDONTWRITEBYTECODE is set (as on some CI machines), in which case every start
    would compile our sources again (about 20 ms). So the variable is dropped for these
    runs and each command runs once untimed first.
    """
    import os

    from .samples import sample_path

    commands = {
        "python -c 'import rich.table' (floor)": [sys.executable, "-c", "import rich.table"],
        "linkage solve": [sys.executable, "-m", "linkage", "solve"],
        "linkage solve FILE": [sys.executable, "-m", "linkage", "solve",
                               str(sample_path("fourbar_me581.toml"))],
        "linkage sweep crank_rocker.toml": [sys.executable, "-m", "linkage", "sweep",
                                            str(sample_path("crank_rocker.toml"))],
    }
    commands.update(extra or {})
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    times: dict[str, list[float]] = {label: [] for label in commands}
    for rep in range(repeats + 1):
        for label, cmd in commands.items():
            t0 = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=False, env=env)
            if rep:
                times[label].append(time.perf_counter() - t0)
    return {label: statistics.median(ts) for label, ts in times.items()}


def numpy_fourbar(theta2_deg: Any, r1: float, r2: float, r3: float, r4: float) -> Any:
    """Open-branch theta3, theta4 (deg) of a four-bar at every theta2, vectorised in numpy
    (the closed form's numpy twin, :func:`~linkage.problems.assembly.fourbar_by_crank_np`):
    the baseline of the batch engine."""
    import numpy as np

    from .problems.assembly import fourbar_by_crank_np, is_open_np

    (first, second), _ = fourbar_by_crank_np(r1, r2, r3, r4, 0.0, np.radians(theta2_deg))
    open_side = is_open_np(*first)
    t3 = np.degrees(np.where(open_side, first[0], second[0]))
    t4 = np.degrees(np.where(open_side, first[1], second[1]))
    return np.stack((t3, t4), axis=1)


def has_pylinkage() -> bool:
    try:
        import pylinkage  # noqa: F401
    except ImportError:
        return False
    return True


WATT_CLOSED = "linkage.sweep watt_sixbar.toml 361 positions"
WATT_ONE = "one-at-a-time sweep watt_sixbar.toml 361 positions"


def sweep_times(repeats: int = 5, batch_positions: int | None = 1_000_000) -> dict[str, float]:
    """Median seconds: ``linkage.sweep`` of crank_rocker.toml over 0..360 step 1 beside
    pylinkage's ``Linkage.step_fast`` on the same geometry (when installed); the same
    sweep of watt_sixbar.toml beside the one-at-a-time engine (``batch=False``), all four
    interleaved; and a batch sweep of ``batch_positions`` (None: not run) beside the numpy
    closed form. Each time is of the whole call, the front door's checks and the result
    included."""
    import numpy as np

    from .kinematics.loading import load
    from .kinematics.sweep import sweep_mechanism
    from .samples import sample_path

    m = load(sample_path("crank_rocker.toml"))
    w = load(sample_path("watt_sixbar.toml"))
    v = {k: q.value for k, q in m.parameters.items()}
    values = [float(k) for k in range(361)]
    pair: dict[str, Callable[[], Any]] = {"linkage.sweep 361 positions": lambda: sweep_mechanism(m, values),
                                          WATT_CLOSED: lambda: sweep_mechanism(w, values),
                                          WATT_ONE: lambda: sweep_mechanism(w, values, batch=False)}
    if has_pylinkage():
        import pylinkage as pl

        o2, o4 = pl.Ground(0.0, 0.0), pl.Ground(v["r1"], 0.0)
        crank = pl.Crank(o2, radius=v["r2"], angular_velocity=math.radians(1.0), initial_angle=0.0)
        b = pl.RRRDyad(crank, o4, distance1=v["r3"], distance2=v["r4"], x=v["r1"] + 37.0, y=71.0)
        lk = pl.Linkage([o2, o4, crank, b])
        pair["pylinkage step_fast 361 positions"] = lambda: lk.step_fast(iterations=361)
    out = {k: t for k, (t, _, _) in interleaved(pair, max(repeats, 5)).items()}
    if batch_positions is None:
        return out
    grid = np.linspace(0.0, 360.0, batch_positions)
    big = interleaved({
        f"numpy closed form {batch_positions:,} positions":
            lambda: numpy_fourbar(grid, v["r1"], v["r2"], v["r3"], v["r4"]),
        f"linkage.sweep {batch_positions:,} positions (batch)": lambda: sweep_mechanism(m, grid, batch=True),
    }, max(3, min(5, repeats)))
    out.update({k: t for k, (t, _, _) in big.items()})
    out.update(scan_times(repeats, SCAN_DESIGNS if batch_positions >= 1_000_000 else SCAN_DESIGNS // 10))
    return out


SCAN_DESIGNS = 2_000
"""Designs in the scan target's comparison (issue 19); --quick scans a tenth."""


def scan_keys(designs: int) -> tuple[str, str]:
    """The sweep-table keys of the six-bar scan and the four-bar scan."""
    return (f"linkage.scan {designs:,} Watt six-bar designs x 360 positions",
            f"linkage.scan {designs:,} crank-rocker designs x 360 positions")


def scan_times(repeats: int, designs: int) -> dict[str, float]:
    """Median seconds of the same scan (r2, r3, r4 sampled; 0..359 deg; in-process, one
    chunk after another) of watt_sixbar.toml and crank_rocker.toml, taken in turn
    (benchmarks/scan.py --sixbar is the same comparison)."""
    from .samples import sample_path
    from .scan import scan

    vary = {"r2": (20.0, 60.0), "r3": (80.0, 160.0), "r4": (50.0, 120.0)}
    six, four = scan_keys(designs)
    runs = interleaved({
        key: (lambda f=f: scan(str(sample_path(f)), vary, samples=designs, scheduler="synchronous"))
        for key, f in ((six, "watt_sixbar.toml"), (four, "crank_rocker.toml"))}, max(3, min(5, repeats)))
    return {k: t for k, (t, _, _) in runs.items()}


def interleaved(fns: dict[str, Callable[[], Any]], repeats: int) -> dict[str, tuple[float, list[float], Any]]:
    """(median seconds, the timings, the last result) of each function: one untimed run of
    each first (a model compiles once, as in a session; numpy's first runs also pay for
    fresh pages), then the repeats taken in turn, so that the machine's noise hits all
    alike."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    last: dict[str, Any] = {}
    for rep in range(repeats + 1):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            last[k] = fn()
            if rep:
                times[k].append(time.perf_counter() - t0)
    return {k: (statistics.median(ts), ts, last[k]) for k, ts in times.items()}


TARGETS = (
    # (target, ratio label, numerator, denominator, bound: met when ratio <= bound, or >= -bound)
    ("1. scalar Newton, history off, within 2x of the hand loop", "linkage / hand",
     ("freudenstein", "linkage newton (history off)"),
     ("freudenstein", "hand-written Newton (10 lines)"), 2.0),
    ("1. scalar Newton, history on, within 3x of the hand loop", "linkage / hand",
     ("freudenstein", "linkage newton (history on)"),
     ("freudenstein", "hand-written Newton (10 lines)"), 3.0),
    ("1. scalar Newton at least 10x faster than scipy root_scalar newton", "scipy / linkage",
     ("freudenstein", "scipy root_scalar newton"), ("freudenstein", "linkage newton (history off)"), -10.0),
    ("2. four-bar Newton (user F, J), history off, within 2x of hand 2x2 Newton", "linkage / hand",
     ("fourbar", "linkage newton, callables F and J (history off)"),
     ("fourbar", "hand-written 2x2 Newton (Cramer)"), 2.0),
    ("2. four-bar Newton at least 3x faster than scipy root hybr", "scipy / linkage",
     ("fourbar", "scipy root hybr (analytic J)"),
     ("fourbar", "linkage newton, callables F and J (history off)"), -3.0),
)


def targets(ms: Sequence[Measurement], cold: dict[str, float],
            sweeps: dict[str, float] | None = None) -> list[tuple[str, str, float | None, bool | None]]:
    """(target, comparison, measured ratio, met; None where this run cannot judge it) for
    issue 10's targets, from this run; solve times are compared at the tolerance nearest
    1e-12."""

    def at(problem: str, contender: str) -> Measurement | None:
        cands = [m for m in ms if m.problem == problem and m.contender == contender]
        return min(cands, key=lambda m: abs(math.log10(m.tol) + 12), default=None)

    def ratio(a: float | None, b: float | None) -> float | None:
        return a / b if a and b and a == a and b == b else None

    rows: list[tuple[str, str, float | None, bool | None]] = []
    for label, comparison, num, den, bound in TARGETS:
        a, b = at(*num), at(*den)
        r = ratio(a.seconds if a else None, b.seconds if b else None)
        rows.append((label, comparison, r, r is not None and (r <= bound if bound > 0 else r >= -bound)))
    sw = sweeps or {}
    rows += sweep_targets(sw)
    big_key = next((k for k in sw if k.endswith("(batch)")), "")
    ref = next((v for k, v in sw.items() if k.startswith("numpy closed form")), None)
    r = ratio(sw.get(big_key), ref)
    if big_key and "1,000,000 positions" not in big_key:
        # --quick sweeps fewer positions; the target is stated at a million (and a smaller
        # sweep pays its coarse pass over fewer positions), so it is not judged here
        size = big_key.removeprefix("linkage.sweep ").removesuffix(" (batch)")
        rows.append((f"4. linkage.sweep of {size} (the target: 1,000,000) against numpy closed form",
                     "linkage / numpy", r, None))
    else:
        rows.append(("4. linkage.sweep of 1,000,000 positions within 2x of numpy closed form",
                     "linkage / numpy", r, r is not None and r <= 2.0))
    six, four = scan_keys(SCAN_DESIGNS)
    r = ratio(sw.get(six), sw.get(four))
    if r is None and any(k.startswith("linkage.scan") for k in sw):  # --quick: fewer designs
        six, four = scan_keys(SCAN_DESIGNS // 10)
        rows.append((f"issue 19: scan of {SCAN_DESIGNS // 10:,} Watt six-bar designs (the target: "
                     f"{SCAN_DESIGNS:,}) against the crank-rocker's", "six-bar / four-bar",
                     ratio(sw.get(six), sw.get(four)), None))
    else:
        rows.append((f"issue 19: scan of {SCAN_DESIGNS:,} Watt six-bar designs x 360 positions within 3x "
                     "of the crank-rocker's", "six-bar / four-bar", r, r is not None and r <= 3.0))
    floor = cold.get("python -c 'import rich.table' (floor)")
    for label, key, bound in (
            ("5. linkage solve cold start within 1.6x of import rich.table", "linkage solve", 1.6),
            ("5. linkage sweep FILE cold start within 2.0x of import rich.table",
             "linkage sweep crank_rocker.toml", 2.0)):
        r = ratio(cold.get(key), floor)
        rows.append((label, "linkage / import", r, r is not None and r <= bound))
    return rows


def sweep_targets(sw: dict[str, float]) -> list[tuple[str, str, float | None, bool | None]]:
    """Issue 19's sweep targets from :func:`sweep_times`' medians: crank_rocker.toml at
    least 2x faster than pylinkage's step_fast, watt_sixbar.toml at least 5x faster than
    the one-at-a-time engine (n/a where this run could not time both)."""

    def ratio(a: float | None, b: float | None) -> float | None:
        return a / b if a and b and a == a and b == b else None

    py = next((v for k, v in sw.items() if k.startswith("pylinkage")), None)
    r = ratio(py, sw.get("linkage.sweep 361 positions"))
    out: list[tuple[str, str, float | None, bool | None]] = [
        ("3. linkage.sweep of crank_rocker.toml 0..360 step 1 at least 2x faster than pylinkage step_fast",
         "pylinkage / linkage", r, None if r is None else r >= 2.0)]
    r = ratio(sw.get(WATT_ONE), sw.get(WATT_CLOSED))
    out.append(("6. linkage.sweep of watt_sixbar.toml 0..360 step 1 at least 5x faster than the "
                "one-at-a-time sweep", "one-at-a-time / linkage", r, None if r is None else r >= 5.0))
    return out


def has_scipy() -> bool:
    try:
        import scipy  # noqa: F401
    except ImportError:
        return False
    return True


def time_per_solve(problem: Any, kwargs: dict[str, Any]) -> float:
    """Seconds per solve with recording off, the median of short timed batches."""
    from .solve import solve_scalar

    kw = dict(kwargs, record=False)
    times = []
    for _ in range(5):
        n = 0
        t0 = time.perf_counter()
        while True:
            solve_scalar(problem, **kw)
            n += 1
            dt = time.perf_counter() - t0
            if dt > 0.002:
                break
        times.append(dt / n)
    times.sort()
    return times[len(times) // 2]


MEASUREMENT_HEADERS = ("problem", "contender", "tol", "time per solve (us)", "fastest batch (us)",
                       "slowest batch (us)", "error", "iterations", "evaluations")


def measurement_rows(results: Sequence[Any]) -> list[tuple[Any, ...]]:
    """The measurements as the table's rows, times in microseconds."""
    return [(m.problem, m.contender, m.tol, m.seconds * 1e6,
             m.spread[0] * 1e6, m.spread[1] * 1e6, m.error, m.iterations, m.nfev)
            for m in results]


SWEEP_OUTPUT_POSITIONS = 360_001
"""Issue 20's output targets: crank_rocker.toml over 0..360 step 0.001."""


def sweep_output_targets(repeats: int = 3) -> list[tuple[str, str, float | None, bool | None]]:
    """Issue 20's targets, measured in this run: ``linkage sweep crank_rocker.toml --step
    0.001 --to 360 -o FILE`` in a fresh process (the median of ``repeats``) against
    ``linkage.sweep`` of the same 360,001 positions in this process plus an interpreter's
    start (``python -c pass``): CSV within 2x, parquet within 1.5x (parquet: n/a without
    pyarrow)."""
    import os
    import tempfile

    from .kinematics.loading import load
    from .kinematics.sweep import sweep_mechanism
    from .samples import sample_path

    path = str(sample_path("crank_rocker.toml"))
    m = load(path)
    values = [k * 0.001 for k in range(SWEEP_OUTPUT_POSITIONS)]

    def median(run: Callable[[], Any]) -> float:  # of the repeats, as every timing here
        times = []
        for _ in range(max(repeats, 1)):
            t0 = time.perf_counter()
            run()
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    api = median(lambda: sweep_mechanism(m, values))
    start = median(lambda: subprocess.run([sys.executable, "-c", "pass"], check=False, env=env))
    rows: list[tuple[str, str, float | None, bool | None]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for suffix, bound in (("csv", 2.0), ("parquet", 1.5)):
            if suffix == "parquet":
                try:
                    import pyarrow.parquet  # noqa: F401
                except ImportError:
                    rows.append((f"issue 20: sweep of 360,001 positions to {suffix} within {bound}x of "
                                 "linkage.sweep + python start", "cli / api", None, None))
                    continue
            out = os.path.join(tmp, f"sweep.{suffix}")
            cmd = [sys.executable, "-m", "linkage", "sweep", path, "--step", "0.001", "--to", "360",
                   "-o", out]
            runs: list[int] = []
            cli = median(lambda c=cmd, codes=runs: codes.append(  # type: ignore[misc]
                subprocess.run(c, check=False, capture_output=True, env=env).returncode))
            label = f"issue 20: sweep of 360,001 positions to {suffix} within {bound}x of " \
                    "linkage.sweep + python start"
            if any(runs):  # a command that failed fast is no measurement
                rows.append((label, "cli / api", None, None))
                continue
            r = cli / (api + start)
            rows.append((label, "cli / api", r, r <= bound))
    return rows
