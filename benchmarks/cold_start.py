"""Cold starts against the floor `python -c "import rich.table"`, interleaved and repeated
(medians of 9 by default), so that the machine's noise hits every command alike:

    python benchmarks/cold_start.py [REPEATS]
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

SAMPLE = Path(__file__).resolve().parent.parent / "sample_inputs" / "crank_rocker.toml"
COMMANDS = {
    "python -c 'import rich.table' (floor)": [sys.executable, "-c", "import rich.table"],
    "linkage solve": [sys.executable, "-m", "linkage", "solve"],
    "linkage solve FILE": [sys.executable, "-m", "linkage", "solve", str(SAMPLE)],
    "linkage sweep FILE": [sys.executable, "-m", "linkage", "sweep", str(SAMPLE)],
}


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    times: dict[str, list[float]] = {k: [] for k in COMMANDS}
    for _ in range(repeats):
        for name, cmd in COMMANDS.items():
            t = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=True)
            times[name].append(time.perf_counter() - t)
    floor = statistics.median(next(iter(times.values())))
    for name, ts in times.items():
        m = statistics.median(ts)
        print(f"{name:40s} {m * 1e3:7.1f} ms  {m / floor:5.2f}x")


if __name__ == "__main__":
    main()
