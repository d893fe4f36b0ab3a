"""Remake the stored generic instance of the nine-point problem by monodromy.

    python benchmarks/nine_point_start.py [--seed 7] [--stable 3] [--max-loops 60] [-o FILE]

(default FILE: src/linkage/homotopy/data/nine_point_start.npz)

From one random complex four-bar and points made to fit it (linkage.homotopy.ninepoint.
seed_instance), the points are moved around random triangles back to themselves
(linkage.homotopy.parameter.monodromy, with the nine-point problem's loops:
ninepoint.NinePointLoops); each loop carries every known solution, and endpoints in new
orbits join. It stops when `--stable` loops in a row find nothing new, and prints each loop. On
this machine (seed 7): 1,442 orbits after 16 loops, about 5 minutes, the published count
(Wampler, Morgan and Sommese 1992: 8,652 = 1,442 x 6 nondegenerate solutions).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from linkage.homotopy import ninepoint as npt
from linkage.homotopy import ninepoint_track as nt
from linkage.homotopy.parameter import Loop, monodromy


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--stable", type=int, default=3)
    ap.add_argument("--max-loops", type=int, default=60)
    ap.add_argument("-o", "--output", default="src/linkage/homotopy/data/nine_point_start.npz")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    z, d, db = npt.seed_instance(rng)
    began = time.perf_counter()

    loops: list[Loop] = []

    def show(loop: Loop) -> None:
        loops.append(loop)
        print(f"loop {len(loops)}: {loop.count} orbits (+{loop.new}), {loop.dropped} paths failed or "
              f"unsettled, {loop.seconds:.1f} s", flush=True)

    found = monodromy(nt.NinePointLoops(), np.concatenate([d, db]), z[None, :], stable_loops=args.stable,
                      max_loops=args.max_loops, seed=rng, on_loop=show)
    Z, last, cond = npt.polish(found.roots, d, db)
    print(f"{len(Z)} orbits in {time.perf_counter() - began:.0f} s; largest last Newton step "
          f"{last.max():.1e}, largest condition {cond.max():.1e}")
    np.savez(args.output, d=d, db=db, z=npt.canonical(Z))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
