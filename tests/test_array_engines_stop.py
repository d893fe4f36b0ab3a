"""The array engines' Newton stops every position where the single solve's loop stops it:
kinematics.design_loops.newton_block (the scan's engines) against solve_system's textbook
Newton (damped=False), one position at a time, on random driver values and random
guesses (near the assembly, a radian off, on the line of centres where J is singular): the
same convergence and the same iteration count, and the same root where both converge.
(From wild guesses Newton wanders for tens of steps, and the two arithmetic orders, numpy's
and the scalar loop's, can part by rounding on the way: a difference of path, not of the
stopping rule, which tests/test_array_stops.py holds exactly.)"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from linkage.kinematics.design_loops import newton_block
from linkage.kinematics.loading import load
from linkage.kinematics.vector_loops import VectorLoops
from linkage.solve import solve_system

SAMPLES = Path(__file__).resolve().parent.parent / "sample_inputs"


def test_newton_block_stops_as_the_single_solve_on_random_positions():
    rng = np.random.default_rng(33)
    m = load(SAMPLES / "crank_rocker.toml")
    k, tol = 300, 1e-12
    drivers = rng.uniform(0.0, 2.0 * math.pi, k)
    spread = rng.choice([0.05, 0.3, 1.0], k)
    guesses = [rng.uniform(-1.0, 1.0, k) * spread + c for c in (0.5, 1.5)]
    guesses[0][:10] = guesses[1][:10]  # theta3 = theta4: J singular on the first step
    size = np.full(k, m.length_scale)
    q = [g.copy() for g in guesses]
    done, _, iters = newton_block(VectorLoops(m.model, drivers), q, np.arange(k), tol, size,
                                  [False, False], 50, count=True)
    statuses = set()
    for i in range(k):
        r = solve_system(m.model.problem_at(float(drivers[i])), (guesses[0][i], guesses[1][i]),
                         tol=tol, damped=False, record=False, max_iter=50)
        statuses.add(r.status.value)
        assert (bool(done[i]), int(iters[i])) == (r.converged, r.iterations), (i, r.status)
        if r.converged:
            assert max(abs(a[i] - b) for a, b in zip(q, r.x)) <= 1e-9
    assert {"converged_step", "converged_exact", "singular_jacobian"} <= statuses
