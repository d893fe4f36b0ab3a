"""The batch engine's warm starts (linkage.kinematics.warm_starts): the quintic Hermite
interpolation reproduces a polynomial of degree 5 from its values and first and second
derivatives at the grid points, and on crank_rocker.toml it lands within the stopping
rule of the closed form (Norton's open four-bar, measure/hand.py), so one Newton step
settles nearly every position."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from linkage.kinematics.batch import batch_sweep
from linkage.kinematics.loading import load
from linkage.kinematics.warm_starts import coarse_intervals, grid_left, warm_starts
from linkage.measure.hand import fourbar_open
from linkage.units import radians

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def test_quintic_warm_start_reproduces_a_polynomial_of_degree_five():
    poly = np.polynomial.Polynomial([0.3, -1.2, 0.5, 0.25, -0.04, 0.003])
    grid = np.linspace(-2.0, 3.0, 11)
    sol = poly(grid)[:, None]
    slopes = poly.deriv(1)(grid)[:, None]
    bends = poly.deriv(2)(grid)[:, None]
    coarse = coarse_intervals(grid, np.ones(len(grid), dtype=bool), sol, slopes, bends, ["length"])
    vals = np.linspace(-2.0, 3.0, 2001)
    (guess,), left, usable = warm_starts(coarse, vals)
    assert usable.all() and np.array_equal(left, grid_left(grid, vals))
    assert np.max(np.abs(guess - poly(vals))) <= 1e-12 * np.max(np.abs(poly(vals)))


def test_crank_rocker_warm_start_settles_in_one_newton_step():
    m = load(SAMPLES / "crank_rocker.toml")
    grid = np.linspace(0.0, 360.0, 100_001)
    got = batch_sweep(m, grid)
    assert (got.status == 0).all() and got.fallback == 0
    assert np.mean(got.iterations == 1) >= 0.99  # the quintic's error is below tol
    p = {k: q.value for k, q in m.parameters.items()}
    t3, t4 = fourbar_open(radians(grid), p["r1"], p["r2"], p["r3"], p["r4"])
    for j, want in enumerate((t3, t4)):
        gap = np.abs((got.solution[:, j] - want + 180.0) % 360.0 - 180.0)
        assert np.max(radians(gap)) <= 1e-12


def test_batch_coarse_pass_by_the_closed_form_is_the_one_at_a_time_sweeps():
    """The front door passes the closed form (kinematics/closed.py) for the coarse pass:
    where it applies, the batch's statuses, branch and ranges are those of the coarse pass
    by the one-at-a-time sweep, and its solutions agree to the stopping rule."""
    from linkage.kinematics.closed import closed_sweep
    from linkage.kinematics.positions import driver_values

    tried = 0
    for path in sorted(SAMPLES.glob("*.toml")):
        name = path.stem
        m = load(path)
        values = np.array(driver_values(0.0, 360.0, None, 5001))
        by_closed = batch_sweep(m, values, coarse_engine=closed_sweep)
        by_steps = batch_sweep(m, values)
        tried += closed_sweep(m, values[::10]) is not None
        assert np.array_equal(by_closed.status, by_steps.status), name
        assert by_closed.branch == by_steps.branch, name
        assert by_closed.to_sweep().feasible_ranges == by_steps.to_sweep().feasible_ranges, name
        ok = by_steps.status == 0
        assert np.max(np.abs(by_closed.solution[ok] - by_steps.solution[ok]), initial=0.0) <= 1e-9, name
    assert tried >= 5
