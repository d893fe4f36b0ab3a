"""Batch sweep benchmark: the batch engine against a vectorised numpy closed form.

Solves N positions of sample_inputs/crank_rocker.toml (default 1,000,000, one full
crank turn) with linkage's batch engine, and the same positions with the four-bar's
closed form written directly in numpy (circle intersection), in the same run. Prints
the median of several timings for each, their ratio, and the largest difference
between the two answers.

    python benchmarks/sweep_batch.py            # 1,000,000 positions, 3 repeats
    python benchmarks/sweep_batch.py -n 100000 --repeats 5
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from linkage import load_mechanism
from linkage.bench import numpy_fourbar
from linkage.kinematics.batch import batch_sweep

SAMPLE = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def closed_form(theta2_deg: np.ndarray, r1: float, r2: float, r3: float, r4: float) -> np.ndarray:
    """Open-branch theta3, theta4 (deg) of a four-bar for every theta2, in numpy (the same
    baseline `linkage bench` uses)."""
    return numpy_fourbar(theta2_deg, r1, r2, r3, r4)


def timed(fn, repeats: int) -> tuple[float, list[float], object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", "--positions", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    m = load_mechanism(SAMPLE)
    v = {k: q.value for k, q in m.parameters.items()}
    theta2 = np.linspace(0.0, 360.0, args.positions)

    t_cf, cf_times, exact = timed(lambda: closed_form(theta2, v["r1"], v["r2"], v["r3"], v["r4"]),
                                  args.repeats)
    t_b, b_times, result = timed(lambda: batch_sweep(m, theta2), args.repeats)
    solved = result.solution  # type: ignore[attr-defined]
    wrap = (solved - exact + 180.0) % 360.0 - 180.0
    print(f"positions: {args.positions:,} of {SAMPLE.name} (one crank turn), {args.repeats} repeats")
    print(f"numpy closed form : median {t_cf:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in cf_times)})")
    print(f"linkage batch     : median {t_b:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in b_times)})")
    print(f"ratio batch / closed form: {t_b / t_cf:.2f}x   (target: within 2x)")
    print(f"all converged: {bool((result.status == 0).all())}; "  # type: ignore[attr-defined]
          f"largest difference from the closed form: {np.abs(wrap).max():.2e} deg; "
          f"positions sent to the one-at-a-time path: {result.fallback}")  # type: ignore[attr-defined]


if __name__ == "__main__":
    main()
