"""What pyarrow's CSV writer costs one core for a sweep file's doubles: 360,001 rows of 13
columns of doubles with 16 to 17 significant digits (random, as a sweep's positions are),
formatted into memory on one thread, the median of ``--repeats`` runs. The figure row 7's
note in docs/performance.md quotes:

    python benchmarks/csv_format_cost.py [--rows N] [--columns K] [--repeats R]
"""

from __future__ import annotations

import argparse
import statistics
import time


def main(rows: int, columns: int, repeats: int) -> None:
    import numpy as np
    import pyarrow as pa
    import pyarrow.csv as pcsv

    rng = np.random.default_rng(0)
    table = pa.Table.from_arrays([pa.array(rng.random(rows) * 100.0) for _ in range(columns)],
                                 names=[str(k) for k in range(columns)])
    options = pcsv.WriteOptions(include_header=False, quoting_style="none")
    times, size = [], 0
    for _ in range(repeats + 1):  # the first run untimed (pages, pyarrow's first use)
        out = pa.BufferOutputStream()
        started = time.perf_counter()
        pcsv.write_csv(table, out, options)
        times.append(time.perf_counter() - started)
        size = out.getvalue().size
    ms = statistics.median(times[1:]) * 1e3
    print(f"{rows:,} rows x {columns} doubles ({size / 1e6:.1f} MB of text): {ms:.0f} ms on one thread "
          f"(median of {repeats})")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=360_001)
    parser.add_argument("--columns", type=int, default=13)
    parser.add_argument("--repeats", type=int, default=5)
    a = parser.parse_args()
    main(a.rows, a.columns, a.repeats)
