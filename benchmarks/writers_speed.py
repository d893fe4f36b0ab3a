"""The writers at the speed of the disk (issue 33): ``linkage sweep crank_rocker.toml --step
0.001 --to 360 -o FILE`` (360,001 positions) as a process, against a process that runs the
same sweep through the API (``linkage.kinematics.sweep.sweep_mechanism``) and writes
nothing. Each repeat runs the API process and each format's command one after another
(interleaved, so the shared machine's load falls on both alike); the figures are the
medians of the repeats and of the per-repeat ratios, of wall-clock time (the target) and
of CPU time (user + system over every thread: what the machine's other load cannot hide).

    python benchmarks/writers_speed.py [--repeats 7] [--formats csv,parquet]
    python benchmarks/writers_speed.py --before OLD/src   # also another version's commands, interleaved

Targets: CSV within 2x of the API process, parquet within 1.5x.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SAMPLE = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"
API = ("from linkage.kinematics.sweep import sweep_mechanism\n"
       "from linkage.kinematics.loading import load\n"
       f"sweep_mechanism(load({str(SAMPLE)!r}), [k * 0.001 for k in range(360_001)])\n")
TARGETS = {"csv": 2.0, "parquet": 1.5, "json": None, "xlsx": None}


def timed(cmd: list[str], src: str | None = None) -> tuple[float, float]:
    """The command's wall-clock seconds and its CPU seconds (user + system, every thread);
    ``src``: run another version's source tree (PYTHONPATH)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if src is not None:
        env["PYTHONPATH"] = src
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--formats", default="csv,parquet")
    ap.add_argument("--before", metavar="SRC", help="another version's src/ directory, timed in the same "
                    "repeats (e.g. a checkout of main)")
    args = ap.parse_args()
    formats = args.formats.split(",")
    versions = [("", None)] + ([(" (before)", args.before)] if args.before else [])
    formats = [f + tag for f in formats for tag, _ in versions]
    source = {f + tag: src for f in args.formats.split(",") for tag, src in versions}
    api: list[float] = []
    cli: dict[str, list[float]] = {f: [] for f in formats}
    ratios: dict[str, list[float]] = {f: [] for f in formats}
    cpu_ratios: dict[str, list[float]] = {f: [] for f in formats}
    with tempfile.TemporaryDirectory() as tmp:
        timed([sys.executable, "-c", API])  # warm the caches (bytecode, files) once
        for _ in range(args.repeats):
            a, a_cpu = timed([sys.executable, "-c", API])
            api.append(a)
            for f in formats:
                out = os.path.join(tmp, f"sweep.{f.split()[0]}")
                c, c_cpu = timed([sys.executable, "-m", "linkage", "sweep", str(SAMPLE), "--step", "0.001",
                                  "--to", "360", "-o", out], source[f])
                cli[f].append(c)
                ratios[f].append(c / a)
                cpu_ratios[f].append(c_cpu / a_cpu)
    print(f"360,001 positions, medians of {args.repeats} interleaved repeats")
    print(f"  API process (sweep, no output)   {statistics.median(api) * 1e3:8.0f} ms")
    for f in formats:
        r = statistics.median(ratios[f])
        target = TARGETS.get(f) if " " not in f else None
        verdict = "" if target is None else f"  (target <= {target}x: {'met' if r <= target else 'NOT met'})"
        print(f"  CLI to {f:<17}         {statistics.median(cli[f]) * 1e3:8.0f} ms  "
              f"{r:5.2f}x{verdict}; CPU seconds {statistics.median(cpu_ratios[f]):5.2f}x")


if __name__ == "__main__":
    main()
