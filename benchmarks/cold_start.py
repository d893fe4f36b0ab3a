"""Cold starts against the floor `python -c "import rich.table"`, interleaved and repeated
(medians of 9 by default), with the package's bytecode cached as an installed package
has it (see :func:`linkage.bench.cold_start`):

    python benchmarks/cold_start.py [REPEATS]
"""

from __future__ import annotations

import sys

from linkage.bench import cold_start


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    times = cold_start(repeats)
    floor = next(iter(times.values()))
    for name, t in times.items():
        print(f"{name:40s} {t * 1e3:7.1f} ms  {t / floor:5.2f}x")


if __name__ == "__main__":
    main()
