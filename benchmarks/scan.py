"""Scan throughput: `linkage scan` against a vectorised numpy closed form of the same
four-bar metrics, and the local scheduler against a two-worker dask LocalCluster.

    python benchmarks/scan.py                 # 2,000 designs x 360 positions
    python benchmarks/scan.py --designs 20000 --repeats 1 --no-cluster
    python benchmarks/scan.py --continuation  # six-bar designs: batch against one at a time
    python benchmarks/scan.py --sixbar        # Watt six-bar against crank-rocker, same scan
    python benchmarks/scan.py --writers       # 10^6 three-position designs to Parquet and CSV

Every figure is a median of repeats measured in this run (the machines are shared and
noisy): the CLI's wall time includes Python's start-up, as a user sees it, and the
closed form is timed in-process, so the ratio is conservative. The closed form computes
feasible fraction, rocker swing (theta4 range) and the minimum and maximum transmission
angle by the law of cosines; it is also the reference tests/test_scan.py checks against.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SAMPLE = ROOT / "sample_inputs" / "crank_rocker.toml"
VARY = ["--vary", "r2=20:60", "--vary", "r3=80:160", "--vary", "r4=50:120"]


def closed_form_metrics(r1: float, r2: np.ndarray, r3: np.ndarray, r4: np.ndarray,
                        theta2_deg: np.ndarray) -> dict[str, np.ndarray]:
    """Four-bar metrics on the open branch by the law of cosines (ground along x)."""
    t2 = np.radians(theta2_deg)[None, :]
    r2, r3, r4 = r2[:, None], r3[:, None], r4[:, None]
    ax, ay = r2 * np.cos(t2), r2 * np.sin(t2)
    d2 = (ax - r1) ** 2 + ay ** 2
    d = np.sqrt(d2)
    feasible = (d2 >= (r3 - r4) ** 2) & (d2 <= (r3 + r4) ** 2)
    with np.errstate(invalid="ignore"):
        mu = np.degrees(np.arccos(np.clip((r3 * r3 + r4 * r4 - d2) / (2 * r3 * r4), -1, 1)))
        psi = np.arccos(np.clip((r4 * r4 + d2 - r3 * r3) / (2 * r4 * d), -1, 1))
    theta4 = np.degrees(np.arctan2(ay, ax - r1) - psi)
    folded = np.where(feasible, np.minimum(mu, 180.0 - mu), np.nan)
    # theta4 continuous along the cycle, each value nearest the previous feasible one
    idx = np.where(feasible, np.arange(theta4.shape[1]), 0)
    np.maximum.accumulate(idx, axis=1, out=idx)
    smooth = np.unwrap(np.take_along_axis(theta4, idx, axis=1), period=360.0, axis=1)
    none = ~feasible.any(axis=1)
    lo = np.where(feasible, smooth, np.inf).min(axis=1)
    hi = np.where(feasible, smooth, -np.inf).max(axis=1)
    t_lo = np.where(feasible, folded, np.inf).min(axis=1)
    t_hi = np.where(feasible, folded, -np.inf).max(axis=1)
    return {"feasible_fraction": feasible.mean(axis=1),
            "theta4_range": np.where(none, np.nan, hi - lo),
            "min_transmission_deg": np.where(none, np.nan, t_lo),
            "max_transmission_deg": np.where(none, np.nan, t_hi)}


def designs(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(20, 60, n), rng.uniform(80, 160, n), rng.uniform(50, 120, n)])


def time_closed_form(n: int, repeats: int) -> float:
    d = designs(n)
    theta2 = np.arange(360.0)
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        closed_form_metrics(100.0, d[:, 0], d[:, 1], d[:, 2], theta2)
        out.append(time.perf_counter() - t)
    return statistics.median(out)


def time_cli(n: int, repeats: int, extra: list[str]) -> float:
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            cmd = [sys.executable, "-m", "linkage", "scan", str(SAMPLE), *VARY, "--samples", str(n),
                   "-o", str(Path(tmp) / "scan.csv"), *extra]
            t = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            out.append(time.perf_counter() - t)
    return statistics.median(out)


def time_cluster(n: int, repeats: int) -> tuple[float, float] | None:
    try:
        from distributed import LocalCluster
    except ImportError:
        return None
    with LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                      processes=True) as cluster:
        address = cluster.scheduler_address
        remote = time_cli(n, repeats, ["--scheduler", address])
    local = time_cli(n, repeats, [])
    return local, remote


def continuation(designs: int = 200, one_at_a_time: int = 20) -> None:
    """Six-bar designs (r5, r6 varied) over 0..359 deg: the vectorised continuation per
    design against the one-at-a-time sweep on the first few, and their agreement."""
    from linkage.kinematics.design_continuation import continuation_engine as _continuation_engine
    from linkage.kinematics.design_continuation import sweep_engine as _sweep_engine
    from linkage.kinematics.loading import load

    m = load(ROOT / "sample_inputs" / "watt_sixbar.toml")
    arrays = {"r5": np.linspace(60, 80, designs), "r6": np.linspace(100, 120, designs)}
    vals = np.arange(0.0, 360.0)
    t = time.perf_counter()
    q, status, _, engine = _continuation_engine(m, arrays, vals, 1e-12, designs)
    batch = (time.perf_counter() - t) / designs
    sub = {k: v[:one_at_a_time] for k, v in arrays.items()}
    t = time.perf_counter()
    q1, status1, _, _ = _sweep_engine(m, sub, vals, None, 1e-12, one_at_a_time)
    single = (time.perf_counter() - t) / one_at_a_time
    k = one_at_a_time * len(vals)
    worst = max(float(np.nanmax(np.abs(a[:k] - b))) for a, b in zip(q, q1))
    print(f"watt_sixbar.toml, {designs} designs x 360 positions ({engine})")
    print(f"  vectorised continuation   {batch * 1e3:7.2f} ms per design")
    print(f"  one at a time (first {one_at_a_time})  {single * 1e3:7.2f} ms per design")
    print(f"  same statuses: {bool((status[:k] == status1).all())}; largest difference {worst:.2g}")


def sixbar(n: int, repeats: int) -> tuple[float, float]:
    """The same scan (r2, r3, r4 sampled as VARY, n designs x 360 positions, in-process,
    synchronous) of watt_sixbar.toml and of crank_rocker.toml, interleaved run by run:
    (six-bar, four-bar) median seconds. Issue 19's target: the six-bar within 3x."""
    from linkage.scan import scan

    vary = {"r2": (20.0, 60.0), "r3": (80.0, 160.0), "r4": (50.0, 120.0)}
    times: dict[str, list[float]] = {"watt_sixbar": [], "crank_rocker": []}
    for name in times:  # warm: imports, the derivation, numpy's first calls
        scan(str(ROOT / "sample_inputs" / f"{name}.toml"), vary, samples=10, scheduler="synchronous")
    for _ in range(repeats):
        for name in times:
            t = time.perf_counter()
            scan(str(ROOT / "sample_inputs" / f"{name}.toml"), vary, samples=n, scheduler="synchronous")
            times[name].append(time.perf_counter() - t)
    six, four = (statistics.median(times[k]) for k in ("watt_sixbar", "crank_rocker"))
    print(f"{n:,} designs x 360 positions (r2, r3, r4 sampled), in-process, synchronous, "
          f"median of {repeats}")
    print(f"  crank_rocker.toml  {four * 1e3:8.1f} ms")
    print(f"  watt_sixbar.toml   {six * 1e3:8.1f} ms  {six / four:4.2f}x the four-bar (target: 3x)")
    return six, four


def writers(n_r2: int = 1000, n_r4: int = 1000) -> None:
    """A grid of n_r2 x n_r4 designs at 3 positions each to Parquet and to CSV: the
    time is mostly writing."""
    with tempfile.TemporaryDirectory() as tmp:
        for suffix in ("parquet", "csv"):
            cmd = [sys.executable, "-m", "linkage", "scan", str(SAMPLE), "--vary", f"r2=20:60:{n_r2}",
                   "--vary", f"r4=50:120:{n_r4}", "--from", "0", "--to", "240", "--step", "120",
                   "-o", str(Path(tmp) / f"scan.{suffix}")]
            t = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            took = time.perf_counter() - t
            print(f"  {n_r2 * n_r4:,} designs to {suffix:8s} {took:6.1f} s  "
                  f"({n_r2 * n_r4 / took:,.0f} records/s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--no-cluster", action="store_true")
    ap.add_argument("--continuation", action="store_true", help="only the six-bar comparison")
    ap.add_argument("--writers", action="store_true", help="only the Parquet and CSV writing rates")
    ap.add_argument("--sixbar", action="store_true", help="only the Watt six-bar against the crank-rocker")
    args = ap.parse_args()
    if args.sixbar:
        sixbar(args.designs, args.repeats)
        return
    if args.continuation:
        continuation()
        return
    if args.writers:
        writers()
        return
    n = args.designs
    base = time_closed_form(n, args.repeats)
    threads = time_cli(n, args.repeats, [])
    single = time_cli(n, args.repeats, ["--scheduler", "synchronous"])
    procs = time_cli(n, args.repeats, ["--scheduler", "processes"])
    startup = time_cli(1, args.repeats, [])
    print(f"{n:,} designs x 360 positions (crank_rocker.toml, r2, r3, r4 varied), median of {args.repeats}")
    print(f"  numpy closed form (in-process)         {base * 1e3:8.1f} ms")
    print(f"  linkage scan, threads (default)        {threads * 1e3:8.1f} ms  {threads / base:5.1f}x  "
          f"{n / threads:,.0f} designs/s")
    print(f"  linkage scan, synchronous              {single * 1e3:8.1f} ms  {single / base:5.1f}x")
    print(f"  linkage scan, processes                {procs * 1e3:8.1f} ms  {procs / base:5.1f}x")
    print(f"  linkage scan of 1 design (start-up)    {startup * 1e3:8.1f} ms")
    if not args.no_cluster:
        got = time_cluster(n, args.repeats)
        if got is None:
            print("  dask.distributed not installed: cluster comparison skipped")
        else:
            local, remote = got
            print(f"  2-worker LocalCluster via --scheduler  {remote * 1e3:8.1f} ms  "
                  f"{n / remote:,.0f} designs/s (local in the same run: {n / local:,.0f} designs/s)")


if __name__ == "__main__":
    main()
