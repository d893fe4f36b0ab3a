"""The loaded-scan row of ``linkage bench`` (issue 33: "loaded scan / a hand-written numpy
9x9 batched solve"), measured as the bench measures it and repeated, to see its spread.

The row (:func:`linkage.measure.targets.loaded_scan`): ``linkage.scan_designs`` of
sample_inputs/crank_rocker_joints.toml, O4.x sampled at 200 values in 90..110 mm, each design
over 0..359 deg with a 20 N weight at P and a -2 N m torque on the rocker (72,000 positions,
each a 9 x 9 force matrix), on the default scheduler (dask's threads), against
:func:`linkage.measure.hand.loaded_scan` of the same designs: the closed-form positions and
one ``numpy.linalg.solve`` of the 72,000 systems, one thread. Each round is the row's
interleaved pairs (a scan, then the hand-written solve); the figures are each round's median
ratio with its pairs' smallest and largest, and the median over every pair of every round.

    python benchmarks/loaded_scan.py [--repeats 7] [--rounds 3]

Target: loaded scan / hand-written solve <= 1.5x. The machine's load moves both sides of a
pair; the ratio of a pair moves less than either time.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path


def main() -> None:
    from linkage.measure.targets import Settings, loaded_scan

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=7, help="pairs per round")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    every: list[float] = []
    with tempfile.TemporaryDirectory() as work:
        for r in range(args.rounds):
            pairs = loaded_scan(Settings(args.repeats, 0.0, Path(work)))
            ratios = [a / b for a, b in zip(pairs.a, pairs.b)]
            every += ratios
            print(f"round {r + 1}: scan {pairs.a_median * 1e3:6.1f} ms, hand {pairs.b_median * 1e3:6.1f} ms, "
                  f"ratio {pairs.ratio:.2f}x (pairs {min(ratios):.2f}-{max(ratios):.2f}x)", flush=True)
    print(f"loaded scan / hand-written solve: {statistics.median(every):.2f}x, the median of "
          f"{len(every)} pairs (target <= 1.5x)")


if __name__ == "__main__":
    main()
