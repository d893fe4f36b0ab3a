"""Small dense linear algebra in pure Python, for loop-closure systems of a few unknowns (layer 0:
every engine and the mechanism files share it).

Mechanism systems have 2 to ~8 unknowns; at that size a Python LU beats numpy's
per-call overhead, and a single solve keeps numpy out of the import graph. The numpy twins
(:func:`lu_np`, :func:`back_substitute_np`, :func:`pivot_ratio_np`), for stacks of such
systems (a block of positions, a scan's designs), import it when called.
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


def lu_np(t: Any, y: Any = None) -> Any:
    """:func:`lu` of every matrix of a stack ``t`` (n, n, N), the N systems last, in place:
    U on and above the diagonal, L's multipliers below; its row swaps and forward
    elimination applied alongside to ``y`` (n, N) or (n, m, N), m right-hand sides, where
    given (so :func:`back_substitute_np` then finishes :func:`lu_solve`). Returns where each
    matrix is usable (N,): no zero pivot, where ``lu`` raises SingularMatrix.

    ``lu``'s pivots (the first largest, :func:`first_largest`) and numbers bit for bit, and
    ``lu_solve``'s forward substitution, but for a zero's sign (and NaN for inf): the
    multiplier is the quotient as divided (0 / pivot: -0.0 under a negative pivot, where
    ``lu`` writes +0.0 and skips the row), and a row or column zero in every system is not
    updated (``lu`` subtracts 0 times it). Neither changes a non-zero number.

    One pivot step at a time over all N systems: a step's row swap is a whole-row copy
    where every system swaps the same rows, a masked one where some do; its update covers
    the rows and columns that are non-zero in some system (a force matrix is mostly zeros
    and ones), row by row through one scratch row (no fresh (n, n, N) temporary per step):
    numpy's LAPACK calls cost more per 9 x 9 system than its arithmetic."""
    import numpy as np

    n, _, count = t.shape
    with np.errstate(all="ignore"):  # a zero pivot: inf and NaN in its system, usable False
        return _eliminate(t, y, n, count)


def _eliminate(t: Any, y: Any, n: int, count: int) -> Any:
    """:func:`lu_np`'s steps."""
    import numpy as np

    usable = np.ones(count, dtype=bool)
    pairs = [(t, np.empty((n, count)))]
    if y is not None:
        pairs.append((y, np.empty(y.shape[1:])))
    scratch = pairs[0][1]
    for k in range(n):
        # the candidate rows: those non-zero in some system (the first largest wins, as in lu)
        rows = np.flatnonzero(t[k:, k].any(axis=1)) + k
        if rows.size == 0:
            usable[:] = False  # zero in every system: singular, and nothing to eliminate
            continue
        p = first_largest(t[:, k], rows)
        chosen = np.bincount(p - k, minlength=n - k)
        for r in np.flatnonzero(chosen[1:]) + 1:
            other = k + r
            swap = None if chosen[r] == count else p == other
            for m, spare in pairs:
                if swap is None:
                    m[[k, other]] = m[[other, k]]
                    continue
                np.copyto(spare, m[k])
                np.copyto(m[k], m[other], where=swap)
                np.copyto(m[other], spare, where=swap)
        usable &= t[k, k] != 0.0
        cols = np.flatnonzero(t[k, k + 1:].any(axis=1)) + k + 1
        c0, c1 = (cols[0], cols[-1] + 1) if cols.size else (k + 1, k + 1)
        for i in np.flatnonzero(t[k + 1:, k].any(axis=1)) + k + 1:
            mult = t[i, k]
            np.divide(mult, t[k, k], out=mult)
            np.multiply(mult, t[k, c0:c1], out=scratch[:c1 - c0])
            t[i, c0:c1] -= scratch[:c1 - c0]
            if y is not None:
                y[i] -= mult * y[k]
    return usable


def first_largest(column: Any, rows: Any) -> Any:
    """Each system's pivot row among ``rows`` of ``column`` (n, N): the first of the largest
    in magnitude, as :func:`lu`'s ``max`` picks it (a later row wins only where it is
    strictly larger, so a NaN never wins nor loses its place). Row by row, element-wise:
    an ``argmax`` across rows makes a transposed copy of its rows and runs a short loop
    per system, about five times the time of this, all of it holding the GIL."""
    import numpy as np

    p = np.full(column.shape[1], rows[0])
    best = np.abs(column[rows[0]])
    for r in rows[1:]:
        size = np.abs(column[r])
        larger = size > best
        np.copyto(p, r, where=larger)
        np.copyto(best, size, where=larger)
    return p


def back_substitute_np(t: Any, y: Any) -> Any:
    """:func:`lu_solve`'s back substitution over a stack, its operations in its order: the
    solutions (n, N) or (n, m, N) of U x = y, ``t`` and ``y`` as :func:`lu_np` leaves them
    (``y`` is overwritten). NaN or inf where U has a zero pivot."""
    import numpy as np

    n = t.shape[0]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for i in range(n - 1, -1, -1):
            s = y[i]
            for j in range(i + 1, n):
                s -= t[i, j] * y[j]
            s /= t[i, i]
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


def pivot_ratio_np(t: Any) -> Any:
    """:func:`pivot_ratio` of each matrix of a stack as :func:`lu_np` leaves it, (n, n, N)."""
    import numpy as np

    n = t.shape[0]
    diag = np.abs(t[range(n), range(n)])
    top = np.maximum.reduce(diag)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(top > 0.0, np.minimum.reduce(diag) / top, 0.0)


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
