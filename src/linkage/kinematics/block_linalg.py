"""Numpy twins of the scalar linear algebra the rates use (linkage.linalg's ``lu``
and ``lu_solve``, newton_system's ``equilibrate`` and ``newton_direction``), over a stack
of small matrices: the same operations in the same order for every matrix of the stack
(partial pivoting chosen per matrix), so a block of positions gets the bits one position
gets. Matrices are lists of rows of arrays (one entry per position), as the block rates
hold them (kinematics.rate_blocks).
"""

from __future__ import annotations

from typing import Any

Rows = list[list[Any]]


def lu_np(a: Rows) -> tuple[Rows, list[Any], Any]:
    """``lu`` of every matrix of the stack: (LU packed, each row's source row, usable);
    unusable where ``lu`` raises SingularMatrix (a zero pivot)."""
    import numpy as np

    n = len(a)
    shape = np.broadcast_shapes(*(np.shape(v) for row in a for v in row))
    m = np.stack([np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in row], axis=-1)
                  for row in a], axis=-2).copy()  # (..., n, n)
    perm = np.broadcast_to(np.arange(n), (*shape, n)).copy()
    ok = np.ones(shape, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for k in range(n):
            p = k + np.argmax(np.abs(m[..., k:, k]), axis=-1)  # the first largest, as max() picks
            pivot = np.take_along_axis(m[..., :, k], p[..., None], axis=-1)[..., 0]
            ok &= pivot != 0.0
            rows_p = np.take_along_axis(m, p[..., None, None], axis=-2)[..., 0, :].copy()
            rows_k = m[..., k, :].copy()
            swap = p != k
            m[..., k, :] = np.where(swap[..., None], rows_p, rows_k)
            np.put_along_axis(m, p[..., None, None],
                              np.where(swap[..., None], rows_k, rows_p)[..., None, :], axis=-2)
            pk = np.take_along_axis(perm, p[..., None], axis=-1)[..., 0]
            old = perm[..., k].copy()
            perm[..., k] = pk
            np.put_along_axis(perm, p[..., None], old[..., None], axis=-1)
            for i in range(k + 1, n):
                factor = m[..., i, k] / m[..., k, k]
                m[..., i, k] = np.where(factor != 0.0, factor, 0.0)
                for j in range(k + 1, n):
                    m[..., i, j] = m[..., i, j] - factor * m[..., k, j]
    return [[m[..., i, j] for j in range(n)] for i in range(n)], [perm[..., i] for i in range(n)], ok


def lu_solve_np(lu: Rows, perm: list[Any], b: list[Any]) -> list[Any]:
    """``lu_solve`` over the stack: forward then back substitution in its order."""
    import numpy as np

    n = len(lu)
    col = np.stack(np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in b], perm[0])[:n], axis=-1)
    y = [np.take_along_axis(col, perm[i][..., None], axis=-1)[..., 0] for i in range(n)]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for i in range(n):
            s = y[i]
            for j in range(i):
                s = s - lu[i][j] * y[j]
            y[i] = s
        for i in range(n - 1, -1, -1):
            s = y[i]
            for j in range(i + 1, n):
                s = s - lu[i][j] * y[j]
            y[i] = s / lu[i][i]
    return y


def equilibrate_np(jac: Rows) -> Rows:
    """``equilibrate``'s R J C over the stack (rows, then columns, scaled to a largest entry 1)."""
    import numpy as np

    n = len(jac)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        r = []
        for row in jac:
            big = np.maximum.reduce([np.abs(v) for v in row])
            r.append(np.where((big > 0.0) & np.isfinite(big), 1.0 / big, 1.0))
        c = []
        for j in range(n):
            big = np.maximum.reduce([np.abs(jac[i][j]) * r[i] for i in range(n)])
            c.append(np.where((big > 0.0) & np.isfinite(big), 1.0 / big, 1.0))
        return [[jac[i][j] * r[i] * c[j] for j in range(n)] for i in range(n)]


def direction_np(jac: Any, phi: Any) -> tuple[Any, Any]:
    """``newton_direction`` over a stack: (dq with J dq = -phi, usable) for ``jac``
    (..., rows, n) and ``phi`` (..., rows), usable where it gives a finite dq. Two unknowns:
    its closed form and singularity test; more: the pivot ratio of the equilibrated LU
    against SINGULAR_RATIO, then the LU of J as given."""
    import numpy as np

    from ..rules import SINGULAR_RATIO, invertible_array

    n = jac.shape[-1]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if n == 2:
            a, b, c, d = jac[..., 0, 0], jac[..., 0, 1], jac[..., 1, 0], jac[..., 1, 1]
            p0, p1 = phi[..., 0], phi[..., 1]
            det = a * d - b * c
            size = np.abs(a * d) + np.abs(b * c)
            ok = (size > 0.0) & invertible_array(det, size) & np.isfinite(det)
            dq = np.stack([(b * p1 - d * p0) / det, (c * p0 - a * p1) / det], axis=-1)
        else:
            rows = [[jac[..., i, j] for j in range(n)] for i in range(n)]
            scaled, _, ok = lu_np(equilibrate_np(rows))
            diag = [np.abs(scaled[i][i]) for i in range(n)]
            top = np.maximum.reduce(diag)
            ratio = np.where(top > 0.0, np.minimum.reduce(diag) / top, 0.0)
            ok &= ratio >= SINGULAR_RATIO
            f, perm, ok2 = lu_np(rows)
            dq = np.stack(lu_solve_np(f, perm, [-phi[..., i] for i in range(n)]), axis=-1)
            ok &= ok2
        ok &= np.isfinite(dq).all(axis=-1)
    return np.where(ok[..., None], dq, np.nan), ok
