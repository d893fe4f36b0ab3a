"""Batch sweep benchmark: the batch engine against a vectorised numpy closed form.

Solves N positions of sample_inputs/crank_rocker.toml (default 1,000,000, one full
crank turn) with ``linkage.sweep`` on its batch engine (its default above 20,000
positions; asked for with ``batch=True`` so that a small N measures it too), and the
same positions with the four-bar's closed form written directly in numpy (circle
intersection), in the same run. Prints the median of the timings for
each (one untimed run of each first, then the repeats in turn), their ratio, and the
largest difference between the two answers.

    python benchmarks/sweep_batch.py            # 1,000,000 positions, 5 repeats
    python benchmarks/sweep_batch.py -n 100000 --repeats 9
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import linkage
from linkage import load_mechanism
from linkage.measure.hand import fourbar_open
from linkage.measure.timing import interleaved

SAMPLE = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def closed_form(theta2_deg: np.ndarray, r1: float, r2: float, r3: float, r4: float) -> np.ndarray:
    """Open-branch theta3, theta4 (deg) of a four-bar for every theta2, in numpy (the same
    baseline `linkage bench` uses)."""
    return np.stack(fourbar_open(np.radians(theta2_deg), r1, r2, r3, r4), axis=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", "--positions", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    m = load_mechanism(SAMPLE)
    v = {k: q.value for k, q in m.parameters.items()}
    theta2 = np.linspace(0.0, 360.0, args.positions)

    got = interleaved({"closed form": lambda: closed_form(theta2, v["r1"], v["r2"], v["r3"], v["r4"]),
                       "sweep": lambda: linkage.sweep(m, theta2, batch=True)}, args.repeats)
    t_cf, cf_times, exact = got["closed form"]
    t_b, b_times, swept = got["sweep"]
    result = swept.positions.batch  # the batch engine's arrays behind linkage.sweep's result
    solved = result.solution  # type: ignore[attr-defined]
    wrap = (solved - exact + 180.0) % 360.0 - 180.0
    print(f"positions: {args.positions:,} of {SAMPLE.name} (one crank turn), {args.repeats} repeats "
          "after one untimed run of each, interleaved")
    print(f"numpy closed form : median {t_cf:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in cf_times)})")
    print(f"linkage.sweep     : median {t_b:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in b_times)})")
    print(f"ratio sweep / closed form: {t_b / t_cf:.2f}x   (target: within 2x)")
    print(f"all converged: {bool((result.status == 0).all())}; "  # type: ignore[attr-defined]
          f"largest difference from the closed form: {np.abs(wrap).max():.2e} deg; "
          f"positions sent to the one-at-a-time path: {result.fallback}")  # type: ignore[attr-defined]


if __name__ == "__main__":
    main()
