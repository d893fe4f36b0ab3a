"""Issue 33's "no fixed costs per call": ``linkage.sweep`` of a four-bar against the four-bar's
closed form written directly in numpy, at 361 positions (where a fixed cost per call shows)
and at 1,000,000 (where the per-position cost shows).

The four-bar is sample_inputs/crank_rocker.toml. Two baselines: the circle intersection of
the coupler and the rocker about the crank pin, open branch, in twelve numpy lines
(:func:`tight_fourbar`, "written tight"), and the library's own numpy closed form of a
four-bar (:func:`library_fourbar`, ``linkage bench``'s). Before timing, each answer is
checked against the sweep's (largest difference printed, and refused above 1e-9 deg). Each
set is timed interleaved in one run (one untimed call of each, then the repeats taken in
turn), and the medians and their ratios printed: ratios, not seconds, are what carry across a shared machine.

    python benchmarks/sweep_overhead.py                    # 101 repeats at 361, 7 at 1e6
    python benchmarks/sweep_overhead.py --repeats 301 --big-repeats 11
    python benchmarks/sweep_overhead.py --profile          # cProfile of 200 small sweeps
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


def interleaved(fns: dict[str, Callable[[], Any]], repeats: int) -> dict[str, float]:
    """Median seconds of each function: one untimed call of each, then ``repeats`` rounds
    taken in turn, so that the machine's noise hits both alike."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    for rep in range(repeats + 1):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            if rep:
                times[k].append(time.perf_counter() - t0)
    return {k: statistics.median(ts) for k, ts in times.items()}


def largest_difference(sweep: Any, ref: np.ndarray) -> float:
    """The largest difference (deg, modulo a turn) between a sweep's theta3, theta4 and
    the baseline's."""
    got = np.stack([np.asarray(sweep.column(n), dtype=float) for n in ("theta3", "theta4")], axis=1)
    return float(np.max(np.abs((got - ref + 180.0) % 360.0 - 180.0)))


BASELINES = {"tight": tight_fourbar, "library": library_fourbar}


def pair(m: Any, grid: np.ndarray, v: dict[str, float], repeats: int) -> tuple[dict[str, float], float]:
    """(median seconds of the sweep and of each baseline, the largest difference) at ``grid``."""
    fns: dict[str, Callable[[], Any]] = {
        k: (lambda f=f: f(grid, v["r1"], v["r2"], v["r3"], v["r4"])) for k, f in BASELINES.items()}
    values = grid.tolist() if len(grid) <= 1000 else grid  # a short sweep as a user writes it
    got = linkage.sweep(m, values)
    diff = max(largest_difference(got, fn()) for fn in fns.values())
    if not diff <= 1e-9:
        raise SystemExit(f"a baseline is not the sweep's answer: they differ by {diff:g} deg")
    return interleaved({"sweep": lambda: linkage.sweep(m, values), **fns}, repeats), diff


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=101, help="rounds at 361 positions")
    ap.add_argument("--big-repeats", type=int, default=7, help="rounds at 1,000,000 positions")
    ap.add_argument("--profile", action="store_true", help="cProfile 200 sweeps of 361 and stop")
    args = ap.parse_args()
    m = linkage.load_mechanism(SAMPLE)
    v = {k: q.value for k, q in m.parameters.items()}
    small = np.arange(361, dtype=float)
    if args.profile:
        import cProfile
        import pstats

        values = small.tolist()
        linkage.sweep(m, values)
        prof = cProfile.Profile()
        prof.enable()
        for _ in range(200):
            linkage.sweep(m, values)
        prof.disable()
        pstats.Stats(prof).sort_stats("cumulative").print_stats(25)
        return
    rows = [("361 positions", small, args.repeats, 3.0),
            ("1,000,000 positions", np.linspace(0.0, 360.0, 1_000_000), args.big_repeats, 1.5)]
    for label, grid, repeats, target in rows:
        t, diff = pair(m, grid, v, repeats)
        print(f"{label}: linkage.sweep {t['sweep'] * 1e3:.3f} ms, numpy closed form tight "
              f"{t['tight'] * 1e3:.3f} ms, the library's {t['library'] * 1e3:.3f} ms "
              f"(largest difference {diff:.1e} deg)")
        print(f"  linkage.sweep / tight {t['sweep'] / t['tight']:.2f}x, / the library's "
              f"{t['sweep'] / t['library']:.2f}x (issue 33's target: <= {target}x)")


if __name__ == "__main__":
    main()
