"""Loaded sweep benchmark: peak memory and wall time of `linkage sweep` with loads against
the same sweep without them (docs/performance_loads.md).

Runs, as separate processes, the loaded crank-rocker (docs/crank_rocker_loads.toml) and
its unloaded twin (sample_inputs/crank_rocker_joints.toml: the same drawing, no [loads]
or [mass]) over one crank turn at each --step, at --speed 10, written to CSV:

    linkage sweep docs/crank_rocker_loads.toml --step S --speed 10 -f csv -o loaded.csv
    linkage sweep sample_inputs/crank_rocker_joints.toml --step S --speed 10 -f csv -o unloaded.csv

Each command runs --repeats times, loaded and unloaded in turn; the figures are the
medians: wall time (from start to exit) and peak resident memory (the child's ru_maxrss,
from os.wait4), with the loaded sweep's extra memory per position
((loaded - unloaded peak) / positions) beside them.

    python benchmarks/sweep_loads.py                        # steps 0.01, 0.0036, 0.001, 3 repeats
    python benchmarks/sweep_loads.py --steps 0.01 --repeats 5
    python benchmarks/sweep_loads.py --static               # without --speed (static loads)
    python benchmarks/sweep_loads.py --linkage "env PYTHONPATH=OLD/src python -m linkage"  # another version
"""

from __future__ import annotations

import argparse
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"
UNLOADED = ROOT / "sample_inputs" / "crank_rocker_joints.toml"


def command(exe: list[str], path: Path, step: float, speed: bool, out: Path) -> list[str]:
    motion = ["--speed", "10"] if speed else []
    return [*exe, "sweep", str(path), "--step", f"{step:g}", *motion, "-f", "csv", "-o", str(out)]


def run(argv: list[str]) -> tuple[float, int]:
    """(wall seconds, peak RSS in bytes) of one run of ``argv``; a failed run stops the script."""
    start = time.perf_counter()
    p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - start
    err = p.stderr.read().decode() if p.stderr else ""
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit(f"{' '.join(argv)}: exit {p.returncode}: {err.strip()}")
    return wall, usage.ru_maxrss * 1024  # Linux: kilobytes


def positions(step: float) -> int:
    return int(360.0 / step + 1e-9) + 1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=float, nargs="+", default=[0.01, 0.0036, 0.001],
                    help="driver steps (deg): 36,001, 100,001 and 360,001 positions")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--static", action="store_true", help="without --speed: static loads")
    ap.add_argument("--linkage", default=shutil.which("linkage") or "linkage",
                    help="the command to time (another checkout: 'env PYTHONPATH=DIR/src python -m linkage')")
    args = ap.parse_args()
    exe = shlex.split(args.linkage)
    speed = not args.static
    print(f"linkage sweep, one crank turn, {'--speed 10' if speed else 'static'}, -f csv; "
          f"medians of {args.repeats} (loaded and unloaded in turn)")
    print(f"{'positions':>10} {'unloaded s':>11} {'loaded s':>9} {'ratio':>6} "
          f"{'unloaded MB':>12} {'loaded MB':>10} {'extra B/pos':>12}")
    with tempfile.TemporaryDirectory() as tmp:
        for step in args.steps:
            times: dict[str, list[float]] = {"loaded": [], "unloaded": []}
            peaks: dict[str, list[int]] = {"loaded": [], "unloaded": []}
            for _ in range(args.repeats):
                for kind, path in (("unloaded", UNLOADED), ("loaded", LOADED)):
                    wall, rss = run(command(exe, path, step, speed, Path(tmp) / f"{kind}.csv"))
                    times[kind].append(wall)
                    peaks[kind].append(rss)
            n = positions(step)
            tu, tl = statistics.median(times["unloaded"]), statistics.median(times["loaded"])
            mu, ml = statistics.median(peaks["unloaded"]), statistics.median(peaks["loaded"])
            print(f"{n:>10,} {tu:>11.2f} {tl:>9.2f} {tl / tu:>5.2f}x {mu / 1e6:>12.0f} {ml / 1e6:>10.0f} "
                  f"{(ml - mu) / n:>12.0f}")
            print(f"{'':>10} runs: unloaded {', '.join(f'{t:.2f}' for t in times['unloaded'])} s, "
                  f"{', '.join(f'{p / 1e6:.0f}' for p in peaks['unloaded'])} MB; loaded "
                  f"{', '.join(f'{t:.2f}' for t in times['loaded'])} s, "
                  f"{', '.join(f'{p / 1e6:.0f}' for p in peaks['loaded'])} MB", flush=True)


if __name__ == "__main__":
    main()
