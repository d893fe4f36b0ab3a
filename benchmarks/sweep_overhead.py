"""Issue 33's "no fixed costs per call": ``linkage.sweep`` of a four-bar against the four-bar's
closed form written directly in numpy, at 361 positions (where a fixed cost per call shows)
and at 1,000,000 (where the per-position cost shows).

The four-bar is sample_inputs/crank_rocker.toml. Two baselines: the circle intersection of
the coupler and the rocker about the crank pin, open branch, in twelve numpy lines
(:func:`tight_fourbar`, "written tight"), and the library's own numpy closed form of a
four-bar (:func:`library_fourbar`, ``linkage bench``'s). Before timing, each answer is
checked against the sweep's (largest difference printed, and refused above 1e-9 deg). Each
set is timed interleaved in one run (one untimed call of each, then the repeats taken in
turn), and the medians printed with the ratio of each round's pair (the sweep and a
baseline timed one after the other): their median and quartiles. Ratios, not seconds,
are what carry across a shared machine.

    python benchmarks/sweep_overhead.py                    # 101 repeats at 361, 7 at 1e6
    python benchmarks/sweep_overhead.py --repeats 301 --big-repeats 11
    python benchmarks/sweep_overhead.py --small-only       # the 361 row alone
    python benchmarks/sweep_overhead.py --profile          # cProfile (tottime) of 2,000 small sweeps
    python benchmarks/sweep_overhead.py --lines            # line timing of the closed-form path
                                                           # (needs line_profiler)

Before and after a change, in one session: export the earlier tree (``git archive REV src |
tar -x -C /tmp/before``) and alternate ``PYTHONPATH=/tmp/before/src python
benchmarks/sweep_overhead.py`` with the run on this tree.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import linkage

SAMPLE = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def tight_fourbar(theta2_deg: np.ndarray, r1: float, r2: float, r3: float, r4: float) -> np.ndarray:
    """theta3, theta4 (deg, shape (N, 2)) of the four-bar's open branch: the crank pin B, the
    rocker pivot O4 = (r1, 0), and the coupler-rocker pin C where the circles of radius r3
    about B and r4 about O4 meet, on the side of B -> O4 the open branch takes."""
    t = np.radians(theta2_deg)
    bx, by = r2 * np.cos(t), r2 * np.sin(t)
    ux, uy = r1 - bx, -by
    d2 = ux * ux + uy * uy
    a = (r3 * r3 - r4 * r4 + d2) / (2.0 * d2)  # along B -> O4, as a fraction of |B O4|
    h = np.sqrt(r3 * r3 / d2 - a * a)  # across it, the same fraction
    cx, cy = a * ux - h * uy, a * uy + h * ux  # C - B
    out = np.empty((len(t), 2))
    out[:, 0] = np.degrees(np.arctan2(cy, cx))
    out[:, 1] = np.degrees(np.arctan2(by + cy, bx + cx - r1))
    return out


def library_fourbar(theta2_deg: np.ndarray, r1: float, r2: float, r3: float, r4: float) -> np.ndarray:
    """The same from the library's numpy closed form of a four-bar by its crank
    (``fourbar_by_crank_np``, open side by ``is_open_np``): ``linkage bench``'s baseline."""
    from linkage.problems.assembly import fourbar_by_crank_np, is_open_np

    (first, second), _ = fourbar_by_crank_np(r1, r2, r3, r4, 0.0, np.radians(theta2_deg))
    open_side = is_open_np(*first)
    return np.degrees(np.stack((np.where(open_side, first[0], second[0]),
                                np.where(open_side, first[1], second[1])), axis=1))


def interleaved(fns: dict[str, Callable[[], Any]], repeats: int) -> dict[str, list[float]]:
    """Each function's seconds, round by round: one untimed call of each, then ``repeats``
    rounds taken in turn, so that the machine's noise hits all alike."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    for rep in range(repeats + 1):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            if rep:
                times[k].append(time.perf_counter() - t0)
    return times


def quartiles(xs: list[float]) -> tuple[float, float, float]:
    """(lower quartile, median, upper quartile)."""
    if len(xs) < 2:
        return xs[0], xs[0], xs[0]
    q1, q2, q3 = statistics.quantiles(xs, n=4)
    return q1, q2, q3


def paired(times: dict[str, list[float]], base: str) -> tuple[float, float, float]:
    """Quartiles of the sweep's time over ``base``'s, round by round (interleaved pairs)."""
    return quartiles([a / b for a, b in zip(times["sweep"], times[base])])


def largest_difference(sweep: Any, ref: np.ndarray) -> float:
    """The largest difference (deg, modulo a turn) between a sweep's theta3, theta4 and
    the baseline's."""
    got = np.stack([np.asarray(sweep.column(n), dtype=float) for n in ("theta3", "theta4")], axis=1)
    return float(np.max(np.abs((got - ref + 180.0) % 360.0 - 180.0)))


BASELINES = {"tight": tight_fourbar, "library": library_fourbar}


def pair(m: Any, grid: np.ndarray, v: dict[str, float], repeats: int) -> tuple[dict[str, list[float]], float]:
    """(seconds of the sweep and of each baseline, round by round; the largest difference)
    at ``grid``."""
    fns: dict[str, Callable[[], Any]] = {
        k: (lambda f=f: f(grid, v["r1"], v["r2"], v["r3"], v["r4"])) for k, f in BASELINES.items()}
    values = grid.tolist() if len(grid) <= 1000 else grid  # a short sweep as a user writes it
    got = linkage.sweep(m, values)
    diff = max(largest_difference(got, fn()) for fn in fns.values())
    if not diff <= 1e-9:
        raise SystemExit(f"a baseline is not the sweep's answer: they differ by {diff:g} deg")
    return interleaved({"sweep": lambda: linkage.sweep(m, values), **fns}, repeats), diff


def profile(m: Any, values: list[float]) -> None:
    """cProfile of 2,000 sweeps of 361 positions, by time spent in each function itself."""
    import cProfile
    import pstats

    linkage.sweep(m, values)
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(2000):
        linkage.sweep(m, values)
    prof.disable()
    pstats.Stats(prof).sort_stats("tottime").print_stats(30)


def lines(m: Any, values: list[float]) -> None:
    """Line timing (line_profiler) of 2,000 sweeps of 361 positions through the closed-form
    engine's functions: what each line costs in microseconds."""
    from line_profiler import LineProfiler

    from linkage.kinematics import closed, sweep, vector_loops
    from linkage.rules import SystemStops

    lp = LineProfiler()
    for fn in (sweep.sweep_mechanism, closed.closed_sweep, closed._block, closed._display,
               vector_loops.VectorLoops.evaluate, SystemStops.judge):
        lp.add_function(fn)
    run = lp(lambda: linkage.sweep(m, values))
    for _ in range(2000):
        run()
    lp.print_stats(output_unit=1e-6, stripzeros=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=101, help="rounds at 361 positions")
    ap.add_argument("--big-repeats", type=int, default=7, help="rounds at 1,000,000 positions")
    ap.add_argument("--small-only", action="store_true", help="the 361-position row alone")
    ap.add_argument("--profile", action="store_true", help="cProfile 2,000 sweeps of 361 and stop")
    ap.add_argument("--lines", action="store_true", help="line timing of 2,000 sweeps of 361 and stop")
    args = ap.parse_args()
    m = linkage.load_mechanism(SAMPLE)
    v = {k: q.value for k, q in m.parameters.items()}
    small = np.arange(361, dtype=float)
    if args.profile or args.lines:
        (profile if args.profile else lines)(m, small.tolist())
        return
    rows = [("361 positions", small, args.repeats, 3.0),
            ("1,000,000 positions", np.linspace(0.0, 360.0, 1_000_000), args.big_repeats, 1.5)]
    for label, grid, repeats, target in rows[:1] if args.small_only else rows:
        t, diff = pair(m, grid, v, repeats)
        med = {k: statistics.median(ts) for k, ts in t.items()}
        print(f"{label}: linkage.sweep {med['sweep'] * 1e3:.3f} ms, numpy closed form tight "
              f"{med['tight'] * 1e3:.3f} ms, the library's {med['library'] * 1e3:.3f} ms, medians of "
              f"{repeats} (largest difference {diff:.1e} deg)")
        for base, name in (("tight", "tight"), ("library", "the library's")):
            lo, mid, hi = paired(t, base)
            print(f"  linkage.sweep / {name} {mid:.2f}x (quartiles of the {repeats} pairs {lo:.2f}-{hi:.2f}x)"
                  + (f"; issue 33's target: <= {target}x" if base == "tight" else ""))


if __name__ == "__main__":
    main()
