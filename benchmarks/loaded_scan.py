"""A loaded scan against the work at its heart written by hand: issue 33's "loaded scan / a
hand-written numpy 9x9 batched solve".

The scan: ``linkage.scan_designs("docs/crank_rocker_loads.toml", {"O4.x": (95, 105, 30),
"O4.y": (-5, 5, 30)}, speed=31.4159)``, 900 designs x 360 positions (324,000 positions, each
a 9 x 9 force matrix: three moving links, three equations each), on the default scheduler
(dask's threads) and on one worker. The baseline: ``numpy.linalg.solve`` of 324,000 random
well-conditioned 9 x 9 systems with one right-hand side, in chunks of the scan's size
(numpy's batched LAPACK, one thread), timed in the same process. Each repeat times both,
one after the other (interleaved); the figures are medians, with the CPU seconds (every thread) beside the
wall-clock ones: CPU / wall is the cores a run kept busy.

    python benchmarks/loaded_scan.py [--repeats 5]

Target: loaded scan / hand-written solve <= 1.5x.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"
VARY = {"O4.x": (95.0, 105.0, 30), "O4.y": (-5.0, 5.0, 30)}
POSITIONS = 900 * 360


def hand_solve(a: np.ndarray, b: np.ndarray, chunk: int) -> None:
    for k in range(0, len(a), chunk):
        np.linalg.solve(a[k:k + chunk], b[k:k + chunk])


def main() -> None:
    import linkage

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    a = rng.standard_normal((POSITIONS, 9, 9)) + 9.0 * np.eye(9)
    b = rng.standard_normal((POSITIONS, 9, 1))

    def scan(workers: int | None) -> None:
        linkage.scan_designs(str(LOADED), VARY, speed=31.4159, workers=workers)

    scan(None)  # warm: imports, the derivation's caches
    times: dict[str, list[float]] = {"threads": [], "one worker": [], "hand": []}
    cpu: dict[str, list[float]] = {k: [] for k in times}
    for _ in range(args.repeats):
        for label, run in (("threads", lambda: scan(None)), ("one worker", lambda: scan(1)),
                           ("hand", lambda: hand_solve(a, b, 20_000))):
            t0, c0 = time.perf_counter(), time.process_time()
            run()
            times[label].append(time.perf_counter() - t0)
            cpu[label].append(time.process_time() - c0)
    hand, hand_cpu = statistics.median(times["hand"]), statistics.median(cpu["hand"])
    print(f"900 designs x 360 positions with loads, medians of {args.repeats} interleaved repeats")
    print(f"  hand-written numpy 9x9 batched solve  {hand * 1e3:8.0f} ms  (CPU {hand_cpu * 1e3:.0f} ms)")
    for label in ("threads", "one worker"):
        t, c = statistics.median(times[label]), statistics.median(cpu[label])
        print(f"  loaded scan, {label:<12}            {t * 1e3:8.0f} ms  {t / hand:5.2f}x  "
              f"(CPU {c * 1e3:.0f} ms, {c / hand_cpu:.2f}x the hand solve's; {c / t:.2f} cores busy)")


if __name__ == "__main__":
    main()
