"""What the alpha certificates cost: ``linkage.assemblies`` alone, and with its solutions'
certificates asked for (linkage.homotopy.alpha, 50 digits), in interleaved pairs, medians:

    python benchmarks/alpha_cost.py 21 sample_inputs/stephenson_sixbar.toml sample_inputs/watt_sixbar.toml
"""

from __future__ import annotations

import statistics
import sys
import time

import linkage


def main(repeats: int, files: list[str]) -> None:
    for f in files:
        m = linkage.load_mechanism(f)
        assert linkage.assemblies(m).solutions.certificates  # once untimed: imports, caches
        plain, both, alone = [], [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            linkage.assemblies(m)
            t1 = time.perf_counter()
            a = linkage.assemblies(m)
            t2 = time.perf_counter()
            assert a.solutions.certificates
            t3 = time.perf_counter()
            plain.append(t1 - t0)
            both.append(t3 - t1)
            alone.append(t3 - t2)
        roots = sum(e.kind == "finite" for e in a.solutions.endpoints)
        p, b, c = (statistics.median(v) * 1e3 for v in (plain, both, alone))
        print(f"{f}: assemblies {p:.1f} ms; with certificates {b:.1f} ms ({b / p:.2f}x); the certificates "
              f"{c:.1f} ms for {roots} roots ({c / roots:.1f} ms a root)")


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2:])
