"""Cosine and sine of an array of angles from one tangent of the half angle, for the batch
engine's blocks (:mod:`.batch`).

With t = tan(x / 2): cos x = (1 - t^2) / (1 + t^2) and sin x = 2 t / (1 + t^2) (the
tangent half-angle substitution; Abramowitz and Stegun, *Handbook of Mathematical
Functions*, 4.3.23). numpy's float64 ``tan`` runs on the processor's vector unit where
its ``cos`` and ``sin`` do not (numpy takes those from the C library, one value at a
time): here one ``tan`` and eight arithmetic passes cost a fifth of ``np.cos`` plus
``np.sin`` (measured in benchmarks/target_rows.py row 6's engine).

Accuracy: each result within ABS_ERROR of the true cosine and sine, absolutely (not
relative to the value: near a zero of the cosine its few correct digits are those of
1 - t^2). Loop equations add these values times lengths, so an absolute bound is the one
that matters there. tests/test_half_angle.py holds it against 40-digit mpmath and np.cos.
x / 2 is exact, so t is tan of the exact half angle; NaN and infinities give NaN, as
np.cos does."""

from __future__ import annotations

import numpy as np

ABS_ERROR = 2.0 * 2.0 ** -52
"""The bound on |cos_sin(x)[0] - cos x| and |cos_sin(x)[1] - sin x| (measured: one unit
in the last place of 1.0 at most)."""


def cos_sin(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos x and sin x (float64 arrays, within :data:`ABS_ERROR`) from t = tan(x / 2); of
    a single number (a fixed angle), np.cos and np.sin."""
    if np.ndim(x) == 0:
        return np.cos(x), np.sin(x)
    t = np.multiply(x, 0.5, dtype=float)
    with np.errstate(invalid="ignore"):  # an infinite x: NaN, as np.cos gives it
        np.tan(t, out=t)
    u = np.multiply(t, t)
    c = np.subtract(1.0, u)
    np.add(u, 1.0, out=u)
    np.divide(1.0, u, out=u)  # 1 / (1 + t^2)
    np.multiply(c, u, out=c)
    np.add(t, t, out=t)
    np.multiply(t, u, out=t)
    return c, t
