"""Per-solve times of the lean loops, a 361-position sweep and a four-bar Newton with user
callables (best of 7, timeit). The README's "before -> after" figures are this script run
on the code before a change and after it, in one session:

    python benchmarks/lean_loops.py                      # this checkout
    git worktree add /tmp/before <commit>
    PYTHONPATH=/tmp/before/src python benchmarks/lean_loops.py

    python benchmarks/lean_loops.py --parts              # where a Newton solve's time goes
"""

from __future__ import annotations

import math
import timeit

from linkage import fourbar_equation, load_mechanism, solve_scalar, solve_system
from linkage.samples import sample_path


def best(fn, number: int) -> float:
    return min(timeit.repeat(fn, number=number, repeat=7)) / number


def main() -> None:
    p = fourbar_equation(70.0)
    for method, kw in (("newton", {"x0": 50.0}), ("secant", {"x0": 50.0, "x1": 60.0}),
                       ("bisection", {"bracket": (50.0, 60.0)}), ("fixed-point", {"x0": 50.0}),
                       ("hybrid", {"bracket": (50.0, 60.0)}), ("regula-falsi", {"bracket": (50.0, 60.0)})):
        t = best(lambda method=method, kw=kw: solve_scalar(p, method=method, tol=1e-12, record=False,
                                                           **kw), 2000)
        print(f"{method:13s} {t * 1e6:7.2f} us")
    r1, r2, r3, r4, t2 = 90.0, 30.0, 60.0, 45.0, math.radians(65)
    c2, s2 = r2 * math.cos(t2), r2 * math.sin(t2)

    def F(q):
        a, b = q
        return [c2 + r3 * math.cos(a) - r4 * math.cos(b) - r1, s2 + r3 * math.sin(a) - r4 * math.sin(b)]

    def J(q):
        a, b = q
        return [[-r3 * math.sin(a), r4 * math.sin(b)], [r3 * math.cos(a), -r4 * math.cos(b)]]

    t = best(lambda: solve_system(F, (0.0, math.pi / 2), jac=J, tol=1e-12, record=False), 1000)
    print(f"{'four-bar F,J':13s} {t * 1e6:7.2f} us")
    try:  # the same F and J by hand and by scipy, when this checkout has them
        from linkage.measure.hand import hand_newton_2x2

        hand = best(lambda: hand_newton_2x2(F, J, (0.0, math.pi / 2), 1e-12), 1000)
        print(f"{'  hand 2x2':13s} {hand * 1e6:7.2f} us  (linkage / hand {t / hand:.2f}x)")
        from scipy.optimize import root

        hybr = best(lambda: root(F, (0.0, math.pi / 2), jac=J, method="hybr", options={"xtol": 1e-12}), 200)
        print(f"{'  scipy hybr':13s} {hybr * 1e6:7.2f} us  (hybr / linkage {hybr / t:.2f}x)")
    except ImportError:
        pass
    m = load_mechanism(sample_path("crank_rocker.toml"))  # the measured code's own sample
    values = [float(k) for k in range(361)]
    try:
        from linkage import sweep
    except ImportError:  # before the public API: the continuation sweep itself
        from linkage.analysis.sweep import sweep
    sweep(m, values)
    t = best(lambda: sweep(m, values), 3)
    print(f"{'sweep 361':13s} {t * 1e3:7.2f} ms")


def parts() -> None:
    """A Newton solve split into its loop and what surrounds it (front door, checks of the
    input, the Result), beside the hand loops; for the README's account of targets 1-2."""
    from linkage.measure.hand import hand_newton, hand_newton_2x2
    from linkage.measure.precision import scalar_problem, system_problem
    from linkage.methods.newton import newton_quiet
    from linkage.methods.newton_system import newton_2x2
    from linkage.problems.system import LeanProblem
    from linkage.solve import certify_root

    spec = scalar_problem("freudenstein")
    p, x0 = spec["problem"], spec["x0"]
    r = solve_scalar(p, method="newton", x0=x0, tol=1e-12, record=False)

    whole = best(lambda: solve_scalar(p, method="newton", x0=x0, tol=1e-12, record=False), 20000)
    loop = best(lambda: newton_quiet(p, x0, 1e-12, 0.0, None, 100, certify_root), 20000)
    hand = best(lambda: hand_newton(p.f, p.fprime, x0, 1e-12), 20000)
    print(f"Freudenstein Newton ({r.iterations} iterations): solve {whole * 1e6:.2f} us = loop "
          f"{loop * 1e6:.2f} us + front door and Result {(whole - loop) * 1e6:.2f} us; hand loop "
          f"{hand * 1e6:.2f} us; the loop's checks {(loop - hand) / r.iterations * 1e6:.2f} us an iteration")
    q = system_problem("fourbar")["problem"]
    q0 = tuple(float(v) for v in q.x0)
    r = solve_system(q.F, q0, jac=q.J, tol=1e-12, record=False)
    light = LeanProblem(q.F, q.J, None, lambda: q)
    phi0 = q.F(list(q0))
    whole = best(lambda: solve_system(q.F, q0, jac=q.J, tol=1e-12, record=False), 5000)
    loop = best(lambda: newton_2x2(light, q0, phi0, 1e-12, 0.0, 1e-12, 50, True), 5000)
    hand = best(lambda: hand_newton_2x2(q.F, q.J, q0, 1e-12), 5000)
    print(f"four-bar Newton, F and J as callables ({r.iterations} iterations): solve {whole * 1e6:.2f} us = "
          f"newton_2x2 {loop * 1e6:.2f} us + front door and Result {(whole - loop) * 1e6:.2f} us; "
          f"hand loop {hand * 1e6:.2f} us")


if __name__ == "__main__":
    import sys

    parts() if "--parts" in sys.argv[1:] else main()
