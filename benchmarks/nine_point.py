"""How fast linkage.homotopy tracks the nine-point path synthesis problem (Wampler, Morgan
and Sommese 1992, Problem 3; linkage.homotopy.ninepoint): monodromy from one seed root of a
generic complex instance for a time budget, then a parameter homotopy of the roots found to
Problem 3's nine real points. Prints the counts it got and the paths per second; it claims
no count it did not get (a generic instance has 8652 roots, Problem 3 has 64 real four-bars
up to cognates and relabelling).

    python benchmarks/nine_point.py --seconds 600
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from linkage.homotopy.ninepoint import GENERIC_ROOTS, NinePointFamily, parameters, seed_instance
from linkage.homotopy.parameter import monodromy, track_parameters

PROBLEM_3 = [(0.25, 0.0), (0.52, 0.1), (0.8, 0.7), (1.2, 1.0), (1.4, 1.3), (1.1, 1.48), (0.7, 1.4),
             (0.2, 1.0), (0.02, 0.4)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=600.0, help="monodromy's time budget")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    family = NinePointFamily()
    p, v = seed_instance(np.random.default_rng(args.seed))
    cpu = time.process_time()
    found = monodromy(family, p, v[None], stable_loops=5, seed=args.seed, max_seconds=args.seconds)
    cpu = time.process_time() - cpu
    print(f"monodromy: {len(found.roots)} roots of a generic instance (of {GENERIC_ROOTS}) after "
          f"{len(found.counts)} loops, counts {list(found.counts)}; {found.paths} paths in "
          f"{found.seconds:.1f} s = {found.paths / found.seconds:.2f} paths/s ({cpu:.1f} s of CPU = "
          f"{found.paths / cpu:.2f} paths per CPU second); {found.dropped} paths lost on some leg")
    began, cpu = time.perf_counter(), time.process_time()
    ends = track_parameters(family, p, parameters(PROBLEM_3), found.roots, seed=args.seed)
    seconds, cpu = time.perf_counter() - began, time.process_time() - cpu
    kinds = {k: sum(e.kind == k for e in ends.endpoints)
             for k in ("finite", "singular", "infinite", "failed")}
    real = sum(e.kind == "finite" and e.real for e in ends.endpoints)
    paths = len(ends.endpoints)
    print(f"to Problem 3: {paths} paths in {seconds:.1f} s = {paths / seconds:.2f} paths/s ({cpu:.1f} s of "
          f"CPU = {paths / cpu:.2f} paths per CPU second); endpoints {kinds}, {real} real (finite and "
          "nonsingular)")
    print(f"at that rate all {GENERIC_ROOTS} tracked to a new instance would take "
          f"{GENERIC_ROOTS / (paths / cpu) / 60:.0f} CPU minutes")


if __name__ == "__main__":
    main()
