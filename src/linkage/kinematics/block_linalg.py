"""Numpy twins of the scalar linear algebra the rates use (newton_system's ``equilibrate``
and ``newton_direction``) over a stack of small matrices, on linalg's LU twin
(:func:`~linkage.linalg.lu_np`, ``lu``'s numbers for every matrix of the stack, partial
pivoting chosen per matrix), so a block of positions gets the bits one position gets.
"""

from __future__ import annotations

from typing import Any


def equilibrate_np(jac: Any) -> Any:
    """``equilibrate``'s R J C over a stack ``jac`` (n, n, N) (rows, then columns, scaled to a
    largest entry 1), a new stack."""
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        big = np.maximum.reduce(np.abs(jac), axis=1)  # (n, N): each row's largest
        r = np.where((big > 0.0) & np.isfinite(big), 1.0 / big, 1.0)
        rows = jac * r[:, None, :]
        big = np.maximum.reduce(np.abs(rows), axis=0)  # each column's largest after R
        c = np.where((big > 0.0) & np.isfinite(big), 1.0 / big, 1.0)
        return rows * c[None, :, :]


def direction_np(jac: Any, phi: Any) -> tuple[Any, Any]:
    """``newton_direction`` over a stack: (dq with J dq = -phi, usable) for ``jac``
    (..., rows, n) and ``phi`` (..., rows), usable where it gives a finite dq. Two unknowns:
    its closed form and singularity test; more: the pivot ratio of the equilibrated LU
    (``pivots_invertible``), then the LU of J as given."""
    import numpy as np

    from ..linalg import back_substitute_np, lu_np, pivot_ratio_np
    from ..rules import invertible_array, pivots_invertible

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
            shape = jac.shape[:-2]
            # (n, n, N), a copy: the stack last and contiguous, as lu_np runs fastest on it
            t = np.ascontiguousarray(np.moveaxis(jac.reshape(-1, n, n), 0, -1))
            scaled = equilibrate_np(t)
            ok = lu_np(scaled)
            ok &= pivots_invertible(pivot_ratio_np(scaled))
            y = np.ascontiguousarray(np.moveaxis(-phi.reshape(-1, n), 0, -1))
            ok &= lu_np(t, y)
            dq = np.moveaxis(back_substitute_np(t, y), 0, -1).reshape(*shape, n)
            ok = ok.reshape(shape)
        ok &= np.isfinite(dq).all(axis=-1)
    return np.where(ok[..., None], dq, np.nan), ok
