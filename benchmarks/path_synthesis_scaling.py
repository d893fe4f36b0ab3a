"""Nine-point path tracking as dask tasks: one worker against two on a loopback cluster
(Problem 3's points, the first ORBITS orbits of the stored instance, one route),
interleaved, medians.

    python benchmarks/path_synthesis_scaling.py [--orbits 600] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

from linkage.homotopy import ninepoint_track as nt
from linkage.synthesis import path
from linkage.synthesis.path import chunk_runner

PROBLEM_3 = [complex(x, y) for x, y in path.PROBLEM_3]


def main() -> None:
    import distributed

    ap = argparse.ArgumentParser()
    ap.add_argument("--orbits", type=int, default=600)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    times: dict[int, list[float]] = {1: [], 2: []}
    clusters = {n: distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                            host="127.0.0.1", dashboard_address=None) for n in (1, 2)}
    try:
        for _ in range(args.repeats):
            for n, cluster in clusters.items():
                began = time.perf_counter()
                res = nt.solve_points(PROBLEM_3, max_routes=1, orbits=args.orbits,
                                       run=chunk_runner(cluster.scheduler_address, None))
                times[n].append(time.perf_counter() - began)
        one, two = statistics.median(times[1]), statistics.median(times[2])
        print(f"{args.orbits} paths, one route: 1 worker {one:.1f} s, 2 workers {two:.1f} s: "
              f"{one / two:.2f}x ({len(res.solutions)} orbits reached)")
    finally:
        for cluster in clusters.values():
            cluster.close()


if __name__ == "__main__":
    main()
