"""Time path synthesis with prescribed timing (docs/path_synthesis.md, "Prescribed timing"):
one Burmester problem, the five of the worked example (linkage.synthesis.timed_path), and
the whole synthesis with the four-bars moved and judged; interleaved, median of repeats.

    python benchmarks/timed_path.py [REPEATS]
"""

from __future__ import annotations

import statistics
import sys
import time

import linkage
from linkage.synthesis.burmester import burmester_points
from linkage.synthesis.timed_path import timed_four_bars

POINTS = [(0.1579, 2.4375, 20), (0.3675, 3.0987, 60), (-0.1131, 3.2206, 100), (-0.7817, 2.8793, 140),
          (-1.3129, 2.2146, 180)]


def main(repeats: int) -> None:
    steps = {
        "one Burmester problem": lambda: burmester_points([(x, y, d - POINTS[0][2]) for x, y, d in POINTS]),
        "timed_four_bars (five Burmester problems)": lambda: timed_four_bars(POINTS),
        "synthesize_path (and the four-bars judged)": lambda: linkage.synthesize_path(POINTS),
    }
    for run in steps.values():  # warm: imports and first calls
        run()
    times: dict[str, list[float]] = {name: [] for name in steps}
    for _ in range(repeats):
        for name, run in steps.items():
            start = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - start)
    base = statistics.median(times["one Burmester problem"])
    for name, values in times.items():
        median = statistics.median(values)
        print(f"{name}: {median:.3f} s (median of {repeats}), {median / base:.1f} x one Burmester problem")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
