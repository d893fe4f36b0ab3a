"""Small dense linear algebra in pure Python, for loop-closure systems of a few unknowns (layer 0:
every engine and the mechanism files share it).

Mechanism systems have 2 to ~8 unknowns; at that size a Python LU beats numpy's
per-call overhead, and a single solve keeps numpy out of the import graph.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

Matrix = list[list[float]]


class SingularMatrix(ArithmeticError):
    """Raised by :func:`lu` when a pivot is exactly zero."""


def lu(a: Sequence[Sequence[float]]) -> tuple[Matrix, list[int], int]:
    """LU factorisation with partial pivoting: returns (LU packed, row order, sign)."""
    n = len(a)
    m = [list(map(float, row)) for row in a]
    perm = list(range(n))
    sign = 1
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        if m[p][k] == 0.0:
            raise SingularMatrix(f"zero pivot in column {k + 1}")
        if p != k:
            m[k], m[p] = m[p], m[k]
            perm[k], perm[p] = perm[p], perm[k]
            sign = -sign
        pivot = m[k][k]
        row_k = m[k]
        for i in range(k + 1, n):
            row_i = m[i]
            factor = row_i[k] / pivot
            if factor != 0.0:
                row_i[k] = factor
                for j in range(k + 1, n):
                    row_i[j] -= factor * row_k[j]
            else:
                row_i[k] = 0.0
    return m, perm, sign


def lu_two(a: float, b: float, c: float, d: float) -> tuple[float, float, float, float, bool] | None:
    """:func:`lu` of [[a, b], [c, d]] on scalars, the same operations
    in the same order: (m00, m01, m10, m11, swapped), None for a zero pivot."""
    swapped = abs(c) > abs(a)  # max() keeps the first of equal candidates
    if swapped:
        a, b, c, d = c, d, a, b
    if a == 0.0:
        return None
    factor = c / a
    if factor != 0.0:
        d -= factor * b
    else:
        factor = 0.0
    if d == 0.0:
        return None
    return a, b, factor, d, swapped


def lu_solve(factors: tuple[Matrix, list[int], int], b: Sequence[float]) -> list[float]:
    m, perm, _ = factors
    n = len(m)
    y = [float(b[perm[i]]) for i in range(n)]
    for i in range(n):
        row = m[i]
        s = y[i]
        for j in range(i):
            s -= row[j] * y[j]
        y[i] = s
    for i in range(n - 1, -1, -1):
        row = m[i]
        s = y[i]
        for j in range(i + 1, n):
            s -= row[j] * y[j]
        y[i] = s / row[i]
    return y


def det_from_lu(factors: tuple[Matrix, list[int], int]) -> float:
    m, _, sign = factors
    d = float(sign)
    for i in range(len(m)):
        d *= m[i][i]
    return d


def norm1(a: Sequence[Sequence[float]]) -> float:
    n = len(a)
    return max(sum(abs(a[i][j]) for i in range(n)) for j in range(len(a[0])))


def norm1_np(a: Any) -> Any:
    """:func:`norm1` of each matrix of a stack (..., n, m): its largest column sum of
    absolute values (NaN where an entry is NaN), the column sums as one product with a
    row of ones (half the time of numpy's sum along the rows' axis)."""
    import numpy as np

    return (np.ones(a.shape[-2]) @ np.abs(a)).max(axis=-1, initial=0.0)


def cond1(a: Sequence[Sequence[float]], factors: tuple[Matrix, list[int], int] | None = None) -> float:
    """The 1-norm condition number ||A|| ||A^-1||, from n solves (exact for small n)."""
    n = len(a)
    try:
        f = factors or lu(a)
    except SingularMatrix:
        return float("inf")
    inv_cols = [lu_solve(f, [1.0 if i == j else 0.0 for i in range(n)]) for j in range(n)]
    inv_norm = max(sum(abs(v) for v in col) for col in inv_cols)
    return norm1(a) * inv_norm


def pivot_ratio(factors: tuple[Matrix, list[int], int]) -> float:
    """min |u_ii| / max |u_ii|: a cheap warning of near-singularity."""
    m = factors[0]
    diag = [abs(m[i][i]) for i in range(len(m))]
    top = max(diag)
    return min(diag) / top if top > 0.0 else 0.0


def hadamard_ratio(a: Sequence[Sequence[float]]) -> float:
    """|det A| / (product of its columns' Euclidean lengths), in [0, 1]: 0 where A is
    singular, 1 where its columns are orthogonal. Unlike |det| it does not depend on the
    columns' units, and unlike the pivot ratio of an equilibrated LU it is not fooled by a
    row that is small only because the matrix is near singular (a slider-crank's
    [[-r3 sin t3, -1], [r3 cos t3, 0]] at cos t3 -> 0)."""
    n = len(a)
    norms = 1.0
    for j in range(n):
        norms *= sum(a[i][j] * a[i][j] for i in range(n)) ** 0.5
    if not norms > 0.0:
        return 0.0
    try:
        return abs(det_from_lu(lu(a))) / norms
    except SingularMatrix:
        return 0.0
