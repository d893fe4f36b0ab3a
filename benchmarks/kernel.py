"""Issue 33's kernel rows (1-4): linkage's Newton against a hand-written loop, and scipy's
hybr against linkage, as ratios measured in one run by interleaved pairs.

    python benchmarks/kernel.py              # the four ratios, medians of interleaved pairs
    python benchmarks/kernel.py --against /tmp/before/src   # and the same rows on another copy
    python benchmarks/kernel.py --profile    # cProfile of the scalar and the system solve

``--against SRC`` imports the ``linkage`` package under SRC (for instance ``git archive REV src
sample_inputs | tar -x -C /tmp/before``) beside this one and times its calls in the same
rounds (this, that, the denominator, in turn), so that a before/after comparison is made in
one run, with the same hand loops as the reference.

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


def contenders(lib: Any) -> dict[str, tuple[Callable[[], Any], Callable[[], Any], str]]:
    """The rows' (numerator, denominator) calls, the library's calls made on ``lib`` (this
    linkage, or a copy imported by ``--against``); the hand loops are always this checkout's."""
    p = lib.fourbar_equation(70.0)
    f, fp = p.f, p.fprime
    m = lib.load_mechanism(sample_path("fourbar_me581.toml")).problem()
    F, J, q0 = m.F, m.J, tuple(m.x0)
    scalar, system = lib.solve_scalar, lib.solve_system
    rows = {
        "1. scalar Newton, history off / hand loop (target <= 2)": (
            lambda: scalar(p, method="newton", x0=50.0, tol=TOL, record=False),
            lambda: hand_newton(f, fp, 50.0, TOL), "linkage / hand"),
        "2. scalar Newton, history on / hand loop (target <= 3)": (
            lambda: scalar(p, method="newton", x0=50.0, tol=TOL, record=True),
            lambda: hand_newton(f, fp, 50.0, TOL), "linkage / hand"),
        "3. system Newton (user F, J), history off / hand 2x2 (target <= 2)": (
            lambda: system(F, q0, jac=J, tol=TOL, max_iter=100, record=False),
            lambda: hand_newton_2x2(F, J, q0, TOL), "linkage / hand"),
    }
    try:
        from scipy.optimize import root
    except ImportError:
        return rows
    rows["4. scipy root hybr / system Newton (target >= 3)"] = (
        lambda: root(F, q0, jac=J, method="hybr", options={"xtol": TOL}),
        lambda: system(F, q0, jac=J, tol=TOL, max_iter=100, record=False), "scipy / linkage")
    return rows


def load_copy(src: str) -> Any:
    """The ``linkage`` package under ``src``, imported as ``linkage_against`` (its imports
    are relative, so it runs as it is, beside this one)."""
    import importlib.util
    from pathlib import Path

    init = Path(src) / "linkage" / "__init__.py"
    spec = importlib.util.spec_from_file_location("linkage_against", init,
                                                  submodule_search_locations=[str(init.parent)])
    if spec is None or spec.loader is None:
        raise SystemExit(f"no linkage package under {src}")
    module = importlib.util.module_from_spec(spec)
    sys.modules["linkage_against"] = module
    spec.loader.exec_module(module)
    return module


def against(src: str, n_pairs: int, batch: int) -> None:
    """Each row on this linkage and on the copy under ``src``, in the same rounds."""
    import linkage

    here, there = contenders(linkage), contenders(load_copy(src))
    print(f"{'row':<70} {'this':>5} {'that':>5} {'this/that':>9}  (medians; quartiles of this/that)")
    for name, (num, den, _) in here.items():
        other = there[name]
        scipy_row = name.startswith("4.")
        # the rows' ratios: linkage / hand, or (row 4) scipy / linkage
        calls = (num, den, other[1]) if scipy_row else (num, other[0], den)
        for call in calls * 3:
            call()
        this, that, both = [], [], []
        for _ in range(n_pairs):
            t = []
            for call in calls:
                t0 = time.perf_counter()
                for _ in range(batch):
                    call()
                t.append(time.perf_counter() - t0)
            if scipy_row:
                this.append(t[0] / t[1]), that.append(t[0] / t[2]), both.append(t[1] / t[2])
            else:
                this.append(t[0] / t[2]), that.append(t[1] / t[2]), both.append(t[0] / t[1])
        q1, _, q3 = statistics.quantiles(both, n=4)
        print(f"{name:<70} {statistics.median(this):5.2f} {statistics.median(that):5.2f} "
              f"{statistics.median(both):9.2f}  ({q1:.2f}-{q3:.2f})")


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
    ap.add_argument("--against", metavar="SRC", help="also time the linkage package under SRC")
    args = ap.parse_args()
    if args.profile:
        profile()
        return
    if args.against:
        against(args.against, args.pairs, args.batch)
        return
    print(f"{'row':<70} {'ratio':>7} {'quartiles':>11}  per call (us)")
    import linkage

    for name, (num, den, label) in contenders(linkage).items():
        ratio, tn, td, q1, q3 = pairs(num, den, args.pairs, args.batch)
        print(f"{name:<70} {ratio:7.2f} {q1:5.2f}-{q3:<5.2f}  {label}: {tn * 1e6:.2f} / {td * 1e6:.2f}")


if __name__ == "__main__":
    main()
