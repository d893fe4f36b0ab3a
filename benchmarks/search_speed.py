"""`linkage synthesize --search` against a hand-written numpy search of the same candidates,
one thread (issue 33's row: target <= 1.2x, using every core).

    python benchmarks/search_speed.py                  # 25,920 candidates (docs/synthesis.md's grid)
    python benchmarks/search_speed.py --repeats 5 --small
    python benchmarks/search_speed.py --chunks         # in-process search: workers 1 against every core
    python benchmarks/search_speed.py --gil            # how much of a chunk's time holds the GIL

The CLI is timed as a user sees it (a fresh process, its start-up included, its default
threads, `-f csv` to /dev/null); the hand search in-process, on one thread (the BLAS pool
pinned to one thread before numpy loads), over the same grid: Freudenstein's three-point
system, the link lengths, the branch through point 1 in closed form on the 2001-point grid,
the largest error, the transmission angle by the law of cosines, the assembly, branch and
order defects, then the best kept. Pairs are interleaved (hand, CLI, hand, CLI, ...) and
the figures are medians of the pairs' times and of their ratios, measured in this run (the
machine is shared and noisy). Also printed: CPU seconds of the CLI's process (children
included) over its wall time, which is how many cores it kept busy.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

FULL = ["alpha0=0:350:36", "alpha_span=40:120:5", "phi0=0:350:36", "phi_span=60:120:4"]
SMALL = ["alpha0=0:350:12", "alpha_span=40:120:5", "phi0=0:350:12", "phi_span=60:120:4"]
MIN_MU = 40.0
GRID = 2001
CHUNK = 500


def axis(text: str) -> np.ndarray:
    lo, hi, n = text.split("=")[1].split(":")
    return np.linspace(float(lo), float(hi), int(n))


def candidates(vary: list[str]) -> np.ndarray:
    """The grid of (alpha0, alpha_span, phi0, phi_span), the first name slowest (as scan's plan)."""
    mesh = np.meshgrid(*(axis(v) for v in vary), indexing="ij")
    return np.column_stack([m.ravel() for m in mesh])


def turns(v: np.ndarray) -> np.ndarray:
    """How many times each row changes direction (steps below 1e-9 of its size ignored)."""
    step = np.diff(v, axis=1)
    scale = np.maximum(np.abs(v).max(axis=1, keepdims=True), 1.0)
    s = np.where(np.abs(step) <= 1e-9 * scale, 0.0, np.sign(step))
    idx = np.where(s != 0.0, np.arange(s.shape[1]), 0)
    np.maximum.accumulate(idx, axis=1, out=idx)
    s = np.take_along_axis(s, idx, axis=1)
    return ((s[:, 1:] != s[:, :-1]) & (s[:, 1:] != 0) & (s[:, :-1] != 0)).sum(axis=1)


def hand_chunk(c: np.ndarray, lo: float = 1.0, hi: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """(max error deg, defect-free mask) of candidates ``c`` for y = log10(x) on [lo, hi]."""
    a0, da, p0, dp = c.T
    xs = 1.5 - 0.5 * np.cos((2 * np.arange(1, 4) - 1) * np.pi / 6)
    y0, y1 = np.log10(lo), np.log10(hi)
    t, u = (xs - lo) / (hi - lo), (np.log10(xs) - y0) / (y1 - y0)
    al = np.radians(a0[:, None] + t * da[:, None])
    ph = np.radians(p0[:, None] + u * dp[:, None])
    m = np.stack([np.cos(al), -np.cos(ph), np.ones_like(al)], axis=-1)
    r = np.linalg.solve(m, np.cos(al - ph)[..., None])[..., 0]
    with np.errstate(all="ignore"):
        a, cc = 1.0 / r[:, 1], 1.0 / r[:, 0]
        b2 = a * a + cc * cc + 1.0 - 2.0 * a * cc * r[:, 2]
        ok = (b2 > 0) & np.isfinite(a) & np.isfinite(cc)
        b, a, cc = np.sqrt(b2), np.abs(a), np.abs(cc)
        r1, r2, r3 = 1.0 / cc, 1.0 / a, (a * a - b2 + cc * cc + 1.0) / (2 * a * cc)
        sa, sp = np.where(r[:, 1] < 0, np.pi, 0.0), np.where(r[:, 0] < 0, np.pi, 0.0)
        # branch sign at point 1, and every point's own root on that branch
        alr, phr = al + sa[:, None], ph + sp[:, None]
        cos_a, sin_a = np.cos(alr), np.sin(alr)
        base = np.arctan2(sin_a, r2[:, None] + cos_a)
        side = np.remainder(phr - base + np.pi, 2 * np.pi) - np.pi
        sign = np.where(side[:, 0] >= 0, 1.0, -1.0)
        branch = ((np.where(side >= 0, 1.0, -1.0) != sign[:, None])
                  & (np.abs(side) < np.pi - 1e-8) & (np.abs(side) > 1e-8)).any(axis=1)
        # the grid
        g = np.linspace(lo, hi, GRID)
        gt, gu = (g - lo) / (hi - lo), (np.log10(g) - y0) / (y1 - y0)
        ag = np.radians(a0[:, None] + gt * da[:, None]) + sa[:, None]
        ca, sn = np.cos(ag), np.sin(ag)
        p, q = r2[:, None] + ca, sn
        size = np.hypot(p, q)
        ratio = (r1[:, None] * ca + r3[:, None]) / size
        phi = np.arctan2(q, p) + sign[:, None] * np.arccos(ratio) - sp[:, None]
        want = np.radians(p0[:, None] + gu * dp[:, None])
        err = np.degrees(np.remainder(phi - want + np.pi, 2 * np.pi) - np.pi)
        assembles = ok & np.isfinite(err).all(axis=1)
        max_err = np.abs(err).max(axis=1)
        o4a2 = a[:, None] ** 2 + 1.0 + 2.0 * a[:, None] * ca
        mu = np.degrees(np.arccos((b2[:, None] + cc[:, None] ** 2 - o4a2) / (2 * b[:, None] * cc[:, None])))
        low = np.minimum(mu, 180.0 - mu).min(axis=1) < MIN_MU
        order = turns(np.degrees(want) + err) > turns(np.degrees(want))
    return max_err, assembles & ~branch & ~low & ~order


def hand_search(c: np.ndarray, top: int = 5) -> tuple[int, np.ndarray]:
    errs, keep = [], []
    for i in range(0, len(c), CHUNK):
        e, k = hand_chunk(c[i:i + CHUNK])
        errs.append(e)
        keep.append(k)
    e, k = np.concatenate(errs), np.concatenate(keep)
    idx = np.flatnonzero(k)
    return int(k.sum()), idx[np.argsort(e[idx], kind="stable")[:top]]


def cli(vary: list[str]) -> tuple[float, float]:
    """(wall s, CPU s) of one `linkage synthesize --search` run."""
    cmd = [sys.executable, "-m", "linkage", "synthesize", "--search", "--function", "log10(x)", "--x", "1:2",
           *[w for v in vary for w in ("--vary", v)], "--min-transmission", str(MIN_MU), "--top", "5",
           "-f", "csv"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, check=False)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def in_process(vary: list[str], repeats: int) -> None:
    """search() with --workers 1 against every core, and its CPU against the hand search's,
    interleaved, in this process (no start-up)."""
    from linkage.synthesis import search

    c = candidates(vary)

    def run(workers: int | None) -> tuple[float, float]:
        t, t_cpu = time.perf_counter(), time.process_time()
        search("log10(x)", (1, 2), None, None, vary, min_transmission=MIN_MU, top=5, workers=workers)
        return time.perf_counter() - t, time.process_time() - t_cpu

    one, every, hand = [], [], []
    for _ in range(repeats):
        t_cpu = time.process_time()
        hand_search(c)
        hand.append(time.process_time() - t_cpu)
        one.append(run(1))
        every.append(run(None))
    ratios = [a[0] / b[0] for a, b in zip(one, every)]
    busy = [b[1] / b[0] for b in every]
    print(f"in-process search, workers 1: {statistics.median(w for w, _ in one):.2f} s, every core "
          f"({os.cpu_count()}): {statistics.median(w for w, _ in every):.2f} s, speed-up "
          f"{statistics.median(ratios):.2f}x, {statistics.median(busy):.2f} cores busy "
          f"(medians of {repeats})")
    print(f"CPU, search with workers 1 / hand search: "
          f"{statistics.median(s[1] / h for s, h in zip(one, hand)):.2f}x "
          f"({statistics.median(s for _, s in one):.2f} s / {statistics.median(hand):.2f} s)")


def gil_probe() -> None:
    """How much of a chunk's time holds the GIL: a pure-Python counting thread (it needs the
    GIL for every loop) runs beside 20 search chunks, and beside a sleep (which holds none);
    its loop rate beside the chunks over its rate beside the sleep is the share of time the
    GIL was free. Machine load slows both alike."""
    import threading

    from linkage.scan import DesignPlan, parse_vary
    from linkage.synthesis.search import SearchJob, search_chunk

    plan = DesignPlan([parse_vary(v) for v in FULL], None, 0, "lhs")
    job = SearchJob("log10(x)", (1.0, 2.0), (0.0, 40.0), (0.0, 60.0), plan.names, 3, "chebyshev", None, 1.0,
                    MIN_MU)
    chunks = [(i * 200, plan.chunk(i * 200, (i + 1) * 200)) for i in range(20)]
    search_chunk(job, *chunks[0])

    def rate(work: object) -> float:
        stop, count = threading.Event(), [0]

        def probe() -> None:
            n = 0
            while not stop.is_set():
                n += 1
            count[0] = n

        th = threading.Thread(target=probe)
        th.start()
        t = time.perf_counter()
        work()  # type: ignore[operator]
        wall = time.perf_counter() - t
        stop.set()
        th.join()
        return count[0] / wall

    idle = rate(lambda: time.sleep(3.0))
    busy = rate(lambda: [search_chunk(job, *c) for c in chunks])
    print(f"GIL probe: a Python thread beside the search's chunks runs at {busy / idle:.2f} of its rate "
          f"beside a sleep ({busy / 1e6:.2f} vs {idle / 1e6:.2f} M loops a second)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--small", action="store_true", help="2,880 candidates instead of 25,920")
    ap.add_argument("--chunks", action="store_true", help="also time search() in-process by worker count")
    ap.add_argument("--gil", action="store_true", help="only the GIL probe")
    args = ap.parse_args()
    if args.gil:
        gil_probe()
        return
    vary = SMALL if args.small else FULL
    c = candidates(vary)
    kept, _ = hand_search(c)
    print(f"{len(c):,} candidates, hand search keeps {kept:,} (the CLI's report says its own count)")
    hand, hand_cpu, walls, cpus = [], [], [], []
    for _ in range(args.repeats):
        t, t_cpu = time.perf_counter(), time.process_time()
        hand_search(c)
        hand.append(time.perf_counter() - t)
        hand_cpu.append(time.process_time() - t_cpu)
        wall, cpu = cli(vary)
        walls.append(wall)
        cpus.append(cpu)
    ratios = [w / h for w, h in zip(walls, hand)]
    cpu_ratios = [c / h for c, h in zip(cpus, hand_cpu)]
    print(f"hand numpy, one thread: {statistics.median(hand):.2f} s "
          f"(CPU {statistics.median(hand_cpu):.2f} s); "
          f"CLI: {statistics.median(walls):.2f} s (CPU {statistics.median(cpus):.2f} s, "
          f"{statistics.median(c / w for c, w in zip(cpus, walls)):.2f} cores busy)")
    print(f"CLI / hand: wall {statistics.median(ratios):.2f}x, CPU {statistics.median(cpu_ratios):.2f}x "
          f"(medians of {args.repeats} interleaved pairs; the load average was {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} cores)")
    if args.chunks:
        in_process(vary, args.repeats)


if __name__ == "__main__":
    main()
