"""Wampler, Morgan and Sommese's Problem 3: every four-bar whose coupler point passes
through nine points, by parameter homotopy from the stored generic instance.

    python benchmarks/path_synthesis_problem3.py [--routes 4] [--seed 0]

Prints the time, the paths tracked per route, failures, the orbits found (four-bars up to
Roberts cognates and the order of the dyads) and the real ones. Published: 1,442 orbits
(8,652 nondegenerate solutions), 64 real (Hauenstein and Sottile certified them).
"""

from __future__ import annotations

import argparse

from linkage.homotopy import ninepoint_track as nt
from linkage.synthesis.path import PROBLEM_3


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--routes", type=int, default=nt.MAX_ROUTES)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    res = nt.solve_points([complex(x, y) for x, y in PROBLEM_3], seed=args.seed, max_routes=args.routes)
    print(f"{res.seconds:.1f} s, {res.routes} route(s) of {res.paths} paths; failed per route {res.failed}, "
          f"not settled {res.unrefined}; steps {res.steps}")
    print(f"orbits found: {len(res.solutions)} of {res.paths} (missing {res.missing}); "
          f"real: {int(res.real.sum())}")


if __name__ == "__main__":
    main()
