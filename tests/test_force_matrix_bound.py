"""The loads' certified screen (kinematics.load_matrix.solve_bounded_np): its LU is the
scalar ``linalg.lu`` bit for bit (a zero's sign aside), its solution is ``lu_solve``'s,
its bound is never below the exact 1-norm condition number (``linalg.cond1``), and a scan
computes the exact number (one inverse per matrix) only where the bound does not pass the
near-toggle limit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkage.kinematics import load_matrix
from linkage.kinematics.force_sweeps import batch_forces
from linkage.kinematics.forces import TOGGLE_COND
from linkage.kinematics.load_matrix import solve_bounded_np
from linkage.kinematics.loading import load
from linkage.kinematics.sweep import sweep_mechanism
from linkage.linalg import cond1, first_largest, lu, lu_np, lu_solve
from linkage.problems.loads import Loads

ROOT = Path(__file__).resolve().parents[1]


def stack(count: int, n: int, seed: int) -> np.ndarray:
    """Random matrices over six orders of magnitude per column, a few singular (a zero
    row), a few near singular (two columns a hair apart) and a few sparse as force
    matrices are (ones and zeros, a moment row)."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(count, n, n)) * rng.choice([1e-3, 1.0, 1e3], size=(count, 1, n))
    a[:4, 1, :] = 0.0
    a[4:8, :, 0] = a[4:8, :, 1] * (1.0 + 1e-9)
    sparse = rng.random(size=(count // 4, n, n)) < 0.6
    a[8:8 + count // 4][sparse] = 0.0
    a[8:8 + count // 4] += np.eye(n)
    return a


@pytest.mark.parametrize("n", [3, 9, 15])
def test_the_bound_is_never_below_the_exact_condition_number(n: int) -> None:
    a = stack(200, n, n)
    b = np.random.default_rng(1).normal(size=(200, n))
    x, upper = solve_bounded_np(np.ascontiguousarray(a.transpose(1, 2, 0)), np.ascontiguousarray(b.T))
    passed = 0
    for k in range(len(a)):
        exact = cond1(a[k].tolist())
        if not math.isfinite(exact):
            assert not upper[k] < math.inf  # no bound for a singular matrix
            continue
        if not math.isfinite(upper[k]):
            continue  # no bound found: the exact path decides
        assert upper[k] >= exact, (k, upper[k], exact)
        passed += 1
        if exact * 2.0 ** -52 < 1e-6:
            sol = lu_solve(lu(a[k].tolist()), b[k].tolist())
            scale = exact * 2.0 ** -52 * 1e2 * max(map(abs, sol))
            np.testing.assert_allclose(x[k], sol, rtol=0.0, atol=scale)
    assert passed >= 150


def test_the_elimination_is_the_scalar_lu_bit_for_bit() -> None:
    """Every non-zero entry bit for bit; a zero may differ in sign only (a multiplier zero in
    one system and not in all is 0 / pivot there: -0.0 under a negative pivot, where lu
    writes +0.0), which |L| and |U|, all the bound reads, do not see."""
    a = stack(60, 9, 2)[8:]
    t = np.ascontiguousarray(a.transpose(1, 2, 0))
    y = np.zeros(t.shape[1:])
    lu_np(t, y)
    for k in range(len(a)):
        packed = np.array(lu(a[k].tolist())[0])
        got = t[:, :, k]
        assert got.tolist() == packed.tolist()
        nonzero = packed != 0.0
        assert np.array_equal(got[nonzero].view(np.int64), packed[nonzero].view(np.int64))


def test_the_pivot_is_the_scalar_lu_s_first_largest_with_ties_and_nan() -> None:
    """The pivot rule without argmax (its transposed copy held the GIL): the row
    ``max(rows, key=abs)`` picks, as linalg.lu does, where values tie in magnitude, where
    one is NaN, and where all are zero."""
    rng = np.random.default_rng(5)
    column = rng.choice([0.0, 1.0, -1.0, 2.0, -2.0, np.nan], size=(6, 4000))
    for rows in (np.array([0, 1, 2, 3, 4, 5]), np.array([1, 3, 4]), np.array([2, 5])):
        got = first_largest(column, rows)
        want = [max(rows.tolist(), key=lambda i: abs(column[i, s])) for s in range(column.shape[1])]
        assert got.tolist() == want


def test_a_scan_inverts_only_the_matrices_the_bound_does_not_pass(monkeypatch) -> None:
    """Crank-rocker designs whose couplers pass limit positions: the exact condition number
    (one inverse per matrix) only at the positions whose bound reaches TOGGLE_COND (every
    flagged one among them), none elsewhere; the verdicts are those of the exact numbers."""
    m = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    loads = Loads({}, {"rocker": -2.0}, {}, None)
    values = np.arange(0.0, 360.0, 0.5)
    exact_rows = []
    real = load_matrix.condition_np

    def counting(a, rhs):
        exact_rows.append(len(a))
        return real(a, rhs)

    monkeypatch.setattr(load_matrix, "condition_np", counting)
    near_toggles = 0
    for coupler in (60.0, 100.0, 140.0):
        mm = m.with_values({"coupler": coupler}, {})
        r = sweep_mechanism(mm, [float(v) for v in values], loads=loads)
        q = [np.array([math.radians(p.solution[u.name]) if p.solution else np.nan for p in r.positions])
             for u in mm.unknowns]
        exact_rows.clear()
        batch = batch_forces(mm, q, np.radians(values), loads)
        cond = batch.arrays.condition  # the solved positions'
        beyond = int((~(cond < TOGGLE_COND)).sum())  # near a toggle, or singular: exact numbers
        near_toggles += beyond
        assert beyond <= sum(exact_rows) < len(cond) // 4  # the ordinary positions need no inverse
        statuses = r.force_columns()["status"]
        for s_one, code in zip(statuses, batch.status):
            if s_one != "unsolved":
                assert (s_one == "ok") == (code == 0)
    assert near_toggles > 0


def test_the_screen_eliminating_in_place_gives_the_numbers_of_a_copy(monkeypatch) -> None:
    """The screen eliminates in the force matrices themselves and builds those it does not
    pass anew (load_matrix.force_matrix) for their exact numbers: the same unknowns and
    condition numbers, bit for bit, as eliminating a copy, near toggles included."""
    m = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    loads = Loads({"P": (0.0, -20.0)}, {"rocker": -2.0}, {}, None)
    values = np.arange(0.0, 360.0, 0.5)
    real = load_matrix.solve_scaled
    rebuilt = []

    def both(frame, a, rhs, cols, screen_below=None, again=None):
        if screen_below is None:  # the sweep's own loads: exact numbers, nothing spent
            return real(frame, a, rhs, cols, screen_below, again)
        assert again is not None
        a0, rhs0 = a.copy(), rhs.copy()
        x, cond = real(frame, a, rhs, cols, screen_below, again)
        x0, cond0 = real(frame, a0, rhs0, cols, screen_below)
        np.testing.assert_array_equal(x.view(np.int64), x0.view(np.int64))
        np.testing.assert_array_equal(cond.view(np.int64), cond0.view(np.int64))
        rebuilt.append(int((~(cond < screen_below)).sum()))
        return x, cond

    monkeypatch.setattr(load_matrix, "solve_scaled", both)
    for coupler in (60.0, 100.0):
        mm = m.with_values({"coupler": coupler}, {})
        r = sweep_mechanism(mm, [float(v) for v in values], loads=loads)
        q = [np.array([math.radians(p.solution[u.name]) if p.solution else np.nan for p in r.positions])
             for u in mm.unknowns]
        batch_forces(mm, q, np.radians(values), loads)
    assert sum(rebuilt) > 0  # positions the screen did not pass were built again


def test_the_bound_is_the_exact_number_for_a_diagonal_matrix_up_to_its_rounding_margin() -> None:
    """Where g is exact (L = I, U diagonal: g = max 1/|d|), the bound is at least the
    condition number the scalar cond1 finds, and more by no more than what it adds: the
    factors' own error, 1 / (1 - cond gamma_9), and its rounding margin 1 + 2 (9 + 2)^2 eps."""
    rng = np.random.default_rng(3)
    d = 10.0 ** rng.uniform(-3, 3, size=(50, 9)) * rng.choice([-1.0, 1.0], size=(50, 9))
    a = np.zeros((50, 9, 9))
    a[:, range(9), range(9)] = d
    _, upper = solve_bounded_np(np.ascontiguousarray(a.transpose(1, 2, 0)), np.ones((9, 50)))
    for k in range(50):
        exact = cond1(a[k].tolist())
        eps = 2.0 ** -52
        added = 1.0 / (1.0 - exact * 9 * eps * 1.001) * (1.0 + 2.0 * 11 ** 2 * eps) * (1.0 + 8 * eps)
        assert exact <= upper[k] <= exact * added
