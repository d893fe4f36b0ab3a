"""Cold starts against the floor `python -c "import rich.table"`, interleaved and repeated
(medians of 9 by default), with the package's bytecode cached as an installed package
has it (see :func:`linkage.measure.processes.cold_start`); beside them, Python alone and typer alone,
and what creating one class costs at import (a frozen dataclass, a NamedTuple):

    python benchmarks/cold_start.py [REPEATS]
"""

from __future__ import annotations

import statistics
import sys
import time
from dataclasses import make_dataclass
from typing import NamedTuple

from linkage.measure.processes import cold_start


def class_creation(repeats: int = 50) -> tuple[float, float]:
    """Median seconds to create a six-field frozen dataclass and a six-field NamedTuple."""
    fields = [(name, float) for name in "abcdef"]
    makers = (lambda: make_dataclass("Row", fields, frozen=True), lambda: NamedTuple("Row", fields))
    out = []
    for make in makers:
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            make()
            times.append(time.perf_counter() - t0)
        out.append(statistics.median(times))
    return out[0], out[1]


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    times = cold_start(repeats, {"python -c pass": [sys.executable, "-c", "pass"],
                                 "python -c 'import typer'": [sys.executable, "-c", "import typer"]})
    floor = next(iter(times.values()))
    for name, t in times.items():
        print(f"{name:40s} {t * 1e3:7.1f} ms  {t / floor:5.2f}x")
    frozen, named = class_creation()
    print(f"creating a class at import: frozen dataclass {frozen * 1e3:.2f} ms, "
          f"NamedTuple {named * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
