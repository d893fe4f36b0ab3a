"""Issue 33's kernel rows (1-4): linkage's Newton against a hand-written loop, and scipy's
hybr against linkage, as ratios measured in one run by interleaved pairs.

    python benchmarks/kernel.py              # the four ratios, medians of interleaved pairs
    python benchmarks/kernel.py --profile    # cProfile of the scalar and the system solve

Each sample times a batch of calls (``--batch``) of one contender, then of the other,
alternately (``--pairs`` pairs), so that the shared machine's noise hits both alike; a
ratio is the median over pairs of (numerator batch / denominator batch). The problems are
``linkage bench``'s: the Freudenstein four-bar equation at alpha = 70 deg from x0 = 50 deg
(scalar) and the sample four-bar's loop equations with the user's F and J (system), at
tol = 1e-12 (the bench's middle tolerance).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from typing import Any

from linkage import fourbar_equation, load_mechanism, solve_scalar, solve_system
from linkage.measure.hand import hand_newton, hand_newton_2x2
from linkage.samples import sample_path

TOL = 1e-12


def pairs(num: Callable[[], Any], den: Callable[[], Any], n_pairs: int,
          batch: int) -> tuple[float, float, float, float, float]:
    """(median ratio num/den over interleaved pairs, median seconds per call of each, and
    the ratio's quartiles over the pairs: the spread the shared machine put on it)."""
    for _ in range(3):  # warm: a model compiles once, as in a session
        num(), den()
    ratios, tn, td = [], [], []
    for _ in range(n_pairs):
        t0 = time.perf_counter()
        for _ in range(batch):
            num()
        t1 = time.perf_counter()
        for _ in range(batch):
            den()
        t2 = time.perf_counter()
        ratios.append((t1 - t0) / (t2 - t1))
        tn.append((t1 - t0) / batch)
        td.append((t2 - t1) / batch)
    q1, _, q3 = statistics.quantiles(ratios, n=4)
    return statistics.median(ratios), statistics.median(tn), statistics.median(td), q1, q3


def contenders() -> dict[str, tuple[Callable[[], Any], Callable[[], Any], str]]:
    p = fourbar_equation(70.0)
    f, fp = p.f, p.fprime
    m = load_mechanism(sample_path("fourbar_me581.toml")).problem()
    F, J, q0 = m.F, m.J, tuple(m.x0)
    rows = {
        "1. scalar Newton, history off / hand loop (target <= 2)": (
            lambda: solve_scalar(p, method="newton", x0=50.0, tol=TOL, record=False),
            lambda: hand_newton(f, fp, 50.0, TOL), "linkage / hand"),
        "2. scalar Newton, history on / hand loop (target <= 3)": (
            lambda: solve_scalar(p, method="newton", x0=50.0, tol=TOL, record=True),
            lambda: hand_newton(f, fp, 50.0, TOL), "linkage / hand"),
        "3. system Newton (user F, J), history off / hand 2x2 (target <= 2)": (
            lambda: solve_system(F, q0, jac=J, tol=TOL, max_iter=100, record=False),
            lambda: hand_newton_2x2(F, J, q0, TOL), "linkage / hand"),
    }
    try:
        from scipy.optimize import root
    except ImportError:
        return rows
    rows["4. scipy root hybr / system Newton (target >= 3)"] = (
        lambda: root(F, q0, jac=J, method="hybr", options={"xtol": TOL}),
        lambda: solve_system(F, q0, jac=J, tol=TOL, max_iter=100, record=False), "scipy / linkage")
    return rows


def profile() -> None:
    import cProfile
    import pstats

    p = fourbar_equation(70.0)
    m = load_mechanism(sample_path("fourbar_me581.toml")).problem()
    F, J, q0 = m.F, m.J, tuple(m.x0)
    for label, call in (("scalar Newton, history off", lambda: solve_scalar(p, method="newton", x0=50.0,
                                                                              tol=TOL, record=False)),
                        ("scalar Newton, history on", lambda: solve_scalar(p, method="newton", x0=50.0,
                                                                             tol=TOL, record=True)),
                        ("system Newton, history off", lambda: solve_system(F, q0, jac=J, tol=TOL,
                                                                              record=False))):
        call()
        prof = cProfile.Profile()
        prof.enable()
        for _ in range(20_000):
            call()
        prof.disable()
        print(f"--- {label}: 20,000 solves")
        pstats.Stats(prof, stream=sys.stdout).sort_stats("tottime").print_stats(12)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=41)
    ap.add_argument("--batch", type=int, default=300)
    ap.add_argument("--profile", action="store_true")
    args = ap.parse_args()
    if args.profile:
        profile()
        return
    print(f"{'row':<70} {'ratio':>7} {'quartiles':>11}  per call (us)")
    for name, (num, den, label) in contenders().items():
        ratio, tn, td, q1, q3 = pairs(num, den, args.pairs, args.batch)
        print(f"{name:<70} {ratio:7.2f} {q1:5.2f}-{q3:<5.2f}  {label}: {tn * 1e6:.2f} / {td * 1e6:.2f}")


if __name__ == "__main__":
    main()
