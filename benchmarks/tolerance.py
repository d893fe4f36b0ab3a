"""A tolerance study's Monte Carlo against a scan of as many designs (issue 31's target:
10^4 samples within 2x of a 10^4-design scan).

    python benchmarks/tolerance.py                     # 10,000 samples x 360 positions, 3 repeats
    python benchmarks/tolerance.py --samples 2000 --repeats 1
    python benchmarks/tolerance.py --cli               # both as commands (Python's start-up in each)

Both solve the same crank-rocker (sample_inputs/crank_rocker.toml) at the same 360 driver
values on the same engine and scheduler (dask threads): the scan over sampled r2, r3, r4,
the tolerance study with ±0.1 mm on r1..r4 (its linear study, 9 more designs, included).
Each figure is the median of repeats measured in this run (the machine is shared)."""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SAMPLE = ROOT / "sample_inputs" / "crank_rocker.toml"
VALUES = [float(v) for v in range(360)]


def in_process(samples: int, workers: int | None) -> tuple[float, float]:
    import linkage

    t = time.perf_counter()
    linkage.scan_designs(SAMPLE, {"r2": (39.9, 40.1), "r3": (119.9, 120.1), "r4": (79.9, 80.1)},
                         samples=samples, values=VALUES, workers=workers)
    scan = time.perf_counter() - t
    t = time.perf_counter()
    linkage.tolerance(SAMPLE, {"r1": 0.1, "r2": 0.1, "r3": 0.1, "r4": 0.1}, VALUES, samples=samples,
                      workers=workers)
    return scan, time.perf_counter() - t


def as_commands(samples: int) -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as tmp:
        runs = {
            "scan": ["scan", str(SAMPLE), "--vary", "r2=39.9:40.1", "--vary", "r3=119.9:120.1", "--vary",
                     "r4=79.9:80.1", "--samples", str(samples), "-o", f"{tmp}/scan.csv"],
            "tolerance": ["tolerance", str(SAMPLE), "--tol", "r1=0.1", "--tol", "r2=0.1", "--tol", "r3=0.1",
                          "--tol", "r4=0.1", "--samples", str(samples), "-o", f"{tmp}/tolerance.csv"],
        }
        times = []
        for args in runs.values():
            t = time.perf_counter()
            subprocess.run([sys.executable, "-m", "linkage", *args], check=True, capture_output=True)
            times.append(time.perf_counter() - t)
    return times[0], times[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--cli", action="store_true", help="time the two commands instead (CSV output)")
    a = ap.parse_args()
    if not a.cli:
        in_process(200, a.workers)  # imports and compiled models warm, as in a session
    scans, tols = [], []
    for _ in range(a.repeats):
        s, t = as_commands(a.samples) if a.cli else in_process(a.samples, a.workers)
        scans.append(s)
        tols.append(t)
    s, t = statistics.median(scans), statistics.median(tols)
    print(f"{a.samples:,} designs x {len(VALUES)} positions ({'commands' if a.cli else 'in process'}, "
          f"median of {a.repeats}):")
    print(f"  scan of {a.samples:,} designs:            {s:8.3f} s")
    print(f"  tolerance Monte Carlo of {a.samples:,}:    {t:8.3f} s")
    print(f"  ratio (tolerance / scan):            {t / s:8.2f}  (target: <= 2)")


if __name__ == "__main__":
    main()
