"""The one batched LU (linalg.lu_np, with back_substitute_np) against its scalar twin
(linalg.lu, lu_solve): the same pivots and numbers, bit for bit but for a zero's sign, on
dense, sparse, singular and tied stacks; and the loads' screen, which solves through it,
against an independent reference (numpy.linalg.solve, LAPACK) within the error LU with
partial pivoting allows (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed.,
theorem 9.4)."""

from __future__ import annotations

import numpy as np
import pytest

from linkage.kinematics.load_matrix import solve_bounded_np
from linkage.linalg import SingularMatrix, back_substitute_np, cond1, lu, lu_np, lu_solve, norm1

EPS = 2.0 ** -52


def stack(count: int, n: int, seed: int) -> np.ndarray:
    """(count, n, n): random matrices over six orders of magnitude per column; a few with a
    zero row (singular), a few sparse as force matrices are (zeros, -0.0 among them, and
    ones), a few of entries +-1 and +-2 only (pivots tied in magnitude)."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(count, n, n)) * rng.choice([1e-3, 1.0, 1e3], size=(count, 1, n))
    a[:4, 1, :] = 0.0
    q = count // 4
    sparse = rng.random(size=(q, n, n)) < 0.6
    a[4:4 + q][sparse] = rng.choice([0.0, -0.0], size=int(sparse.sum()))
    a[4:4 + q] += np.eye(n)
    a[4 + q:4 + 2 * q] = rng.choice([1.0, -1.0, 2.0, -2.0], size=(q, n, n))
    return a


def same_numbers(got: np.ndarray, want: np.ndarray) -> bool:
    """Equal as numbers (so +0.0 == -0.0) and bit for bit wherever not zero."""
    nonzero = want != 0.0
    return got.tolist() == want.tolist() and \
        np.array_equal(got[nonzero].view(np.int64), want[nonzero].view(np.int64))


@pytest.mark.parametrize("n", [3, 5, 9])
def test_the_batched_lu_is_the_scalar_lu_and_lu_solve_bit_for_bit(n: int) -> None:
    a = stack(120, n, n)
    b = np.random.default_rng(n + 1).normal(size=(120, n, 3))
    t = np.ascontiguousarray(a.transpose(1, 2, 0))
    y = np.ascontiguousarray(b.transpose(1, 2, 0))  # (n, 3, N): three right-hand sides
    one = np.ascontiguousarray(b[:, :, 0].T)  # (n, N): one
    t1 = t.copy()
    usable = lu_np(t, y)
    assert np.array_equal(lu_np(t1, one), usable)
    x, x1 = back_substitute_np(t, y), back_substitute_np(t1, one)
    singular = 0
    for k in range(len(a)):
        try:
            factors = lu(a[k].tolist())
        except SingularMatrix:
            assert not usable[k]
            singular += 1
            continue
        assert usable[k], k
        assert same_numbers(t[:, :, k], np.array(factors[0])), k
        assert same_numbers(t1[:, :, k], np.array(factors[0])), k
        for j in range(3):
            assert same_numbers(x[:, j, k], np.array(lu_solve(factors, b[k, :, j].tolist()))), (k, j)
        assert same_numbers(x1[:, k], x[:, 0, k]), k
    assert 4 <= singular < 40


def test_the_screen_s_solution_is_numpy_solve_s_within_the_lu_error_bound() -> None:
    """solve_bounded_np (the loaded scans' and kinetostatics' solve) against LAPACK's solve:
    each LU solution x' satisfies (A + E) x' = b with ||E||_1 <= gamma_3n || |L| |U| ||_1
    (theorem 9.4), so ||x' - x||_1 / ||x||_1 <= cond_1(A) gamma_3n || |L| |U| ||_1 / ||A||_1
    to first order; two such solutions differ by at most twice that (doubled again for the
    second order and LAPACK's own factors, which may pivot otherwise on a tie)."""
    n = 9
    a = stack(200, n, 4)[4:]  # the usable ones
    b = np.random.default_rng(6).normal(size=(len(a), n))
    x, _ = solve_bounded_np(np.ascontiguousarray(a.transpose(1, 2, 0)), np.ascontiguousarray(b.T))
    ref = np.linalg.solve(a, b[..., None])[..., 0]
    gamma = 3 * n * EPS / (1.0 - 3 * n * EPS)
    checked = 0
    for k in range(len(a)):
        try:
            m, _, _ = lu(a[k].tolist())
        except SingularMatrix:
            continue
        lower = np.tril(np.array(m), -1) + np.eye(n)
        upper = np.triu(np.array(m))
        growth = norm1((np.abs(lower) @ np.abs(upper)).tolist()) / norm1(a[k].tolist())
        cond = cond1(a[k].tolist())
        if not cond * gamma * growth < 1e-3:
            continue  # too near singular for a first-order bound
        err = np.abs(x[k] - ref[k]).sum() / np.abs(ref[k]).sum()
        assert err <= 4.0 * cond * gamma * growth, (k, err, cond, growth)
        checked += 1
    assert checked >= 150
