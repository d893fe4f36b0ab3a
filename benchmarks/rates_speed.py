"""Rates and static loads at the speed of positions (issue 33): the wall time of a sweep
to CSV with ``--speed``, and of a loaded sweep without it, each as a ratio to the same
sweep without rates or loads, measured in the same run as interleaved pairs (baseline,
then the measured command, repeated), medians of the pairs' ratios.

The commands (one crank turn of the crank-rocker, --step 0.01: 36,001 positions):

    baseline  linkage sweep sample_inputs/crank_rocker_joints.toml --step 0.01 -f csv -o x.csv
    speed     linkage sweep sample_inputs/crank_rocker_joints.toml --step 0.01 --speed 10 -f csv -o x.csv
    static    linkage sweep docs/crank_rocker_loads.toml --step 0.01 -f csv -o x.csv

(docs/crank_rocker_loads.toml is the same drawing with [loads] and [mass]: without --speed
its loads are static.) Targets: speed / baseline <= 2, static / baseline <= 2.

    python benchmarks/rates_speed.py                    # 5 pairs each
    python benchmarks/rates_speed.py --repeats 9 --step 0.01
    python benchmarks/rates_speed.py --linkage "env PYTHONPATH=OLD/src python -m linkage"  # another version
"""

from __future__ import annotations

import argparse
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
UNLOADED = ROOT / "sample_inputs" / "crank_rocker_joints.toml"
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"


def wall(argv: list[str]) -> float:
    """Seconds from start to exit of one run; a failed run stops the script."""
    start = time.perf_counter()
    p = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, check=False)
    seconds = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(f"{shlex.join(argv)}: exit {p.returncode}: {p.stderr.decode().strip()}")
    return seconds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--step", type=float, default=0.01)
    ap.add_argument("--linkage", default=None, help="the command to run (default: linkage on PATH)")
    args = ap.parse_args()
    exe = shlex.split(args.linkage) if args.linkage else [shutil.which("linkage") or "linkage"]
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "x.csv")
        step = ["--step", f"{args.step:g}", "-f", "csv", "-o", out]
        commands = {
            "baseline": [*exe, "sweep", str(UNLOADED), *step],
            "speed": [*exe, "sweep", str(UNLOADED), "--speed", "10", *step],
            "static": [*exe, "sweep", str(LOADED), *step],
        }
        wall(commands["baseline"])  # warm the disk cache and the bytecode
        times: dict[str, list[float]] = {k: [] for k in commands}
        ratios: dict[str, list[float]] = {"speed": [], "static": []}
        for _ in range(args.repeats):
            for key in ratios:  # interleaved: a baseline right before each measured run
                base = wall(commands["baseline"])
                got = wall(commands[key])
                times["baseline"].append(base)
                times[key].append(got)
                ratios[key].append(got / base)
    positions = int(360.0 / args.step + 1e-9) + 1
    print(f"{positions:,} positions to CSV, {args.repeats} interleaved pairs each, medians")
    for key, argv in commands.items():
        print(f"  {key:8s} {statistics.median(times[key]):7.3f} s   {shlex.join(argv[1:])}")
    for key, r in ratios.items():
        print(f"  {key} / baseline: {statistics.median(r):.2f}x "
              f"(pairs {min(r):.2f}-{max(r):.2f}x; target <= 2x)")


if __name__ == "__main__":
    main()
