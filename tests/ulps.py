"""Comparing a numpy twin with its plain-Python definition to a stated bound in ulps.

The twins run the same operations in the same order, but numpy's transcendental functions
are not the C library's: on a CPU with AVX-512 numpy's float64 ``arctan2`` is a SIMD
routine (Intel's SVML, vendored by numpy) whose result can differ from ``math.atan2``'s in
the last bit, and numpy may gain SIMD ``sin`` and ``cos`` on other CPUs. Each of these is
within an ulp or two of the exact value (numpy validates them against its own tables in
``numpy/_core/tests/test_umath_accuracy.py``; glibc's errors are listed in its manual,
"Errors in Math Functions"), so two of them differ by a few ulps. IEEE-exact operations
(+ - * / sqrt, comparisons) give the same bits everywhere; BLAS and LAPACK do not (their
kernels, picked by CPU or by ``OPENBLAS_CORETYPE``, sum in different orders).

So the tests hold twins to a bound, never to bit identity, with each bound stated where
it is used: ``scale`` is the quantity's own size (pi for an angle in radians, the
mechanism's size for a length) where an earlier step's difference is carried into a
later step, and the value itself (``scale=None``) where the differing function is the
last operation. NaN is equal to NaN (a position that does not assemble on both sides).
"""

from __future__ import annotations

from typing import Any

import numpy as np

EPS = float(np.finfo(float).eps)


def ulps_apart(got: Any, want: Any, scale: float | None = None) -> Any:
    """|got - want| in units of ``EPS * scale``, or of the larger value's spacing (its ulp)
    with no scale; 0 where both are NaN, inf where only one is."""
    a, b = np.asarray(got, float), np.asarray(want, float)
    both = np.isnan(a) & np.isnan(b)
    one = np.isnan(a) != np.isnan(b)
    unit = EPS * scale if scale is not None else np.spacing(np.maximum(np.abs(a), np.abs(b)))
    with np.errstate(invalid="ignore", divide="ignore"):
        far = np.where(a == b, 0.0, np.abs(a - b) / unit)
    return np.where(both, 0.0, np.where(one, np.inf, far))


def assert_ulps(got: Any, want: Any, n: float, scale: float | None = None, what: Any = "") -> None:
    """``got`` equals ``want`` within ``n`` ulps (see :func:`ulps_apart`), same shape."""
    a, b = np.asarray(got, float), np.asarray(want, float)
    assert a.shape == b.shape, (what, a.shape, b.shape)
    far = ulps_apart(a, b, scale)
    if far.size and not np.all(far <= n):
        i = int(np.argmax(far))
        raise AssertionError(f"{what}: {far.flat[i]:.3g} ulps apart (bound {n}) at {i}: "
                             f"{a.flat[i]!r} against {b.flat[i]!r}")
