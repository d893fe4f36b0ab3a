"""The batch engine's cosine and sine from the half-angle tangent
(linkage.kinematics.half_angle): within its stated absolute bound of the 40-digit values
(mpmath) and of np.cos/np.sin, over small, large and awkward angles."""

from __future__ import annotations

import mpmath
import numpy as np

from linkage.kinematics.half_angle import ABS_ERROR, cos_sin


def awkward_angles() -> np.ndarray:
    """Random angles at several magnitudes, and angles at and next to multiples of pi/2
    (where 1 + t^2 is huge or the cosine vanishes)."""
    rng = np.random.default_rng(33)
    parts = [rng.uniform(-r, r, 400) for r in (1e-8, 1.0, 4.0, 40.0, 1e4, 1e7)]
    k = np.arange(-12, 13) * (np.pi / 2)
    parts += [k, np.nextafter(k, np.inf), np.nextafter(k, -np.inf), k + rng.normal(0, 1e-9, k.size)]
    return np.concatenate([*parts, np.array([0.0, -0.0, 5e-324])])


def test_half_angle_cos_sin_within_its_bound_of_40_digits():
    mpmath.mp.dps = 40
    x = awkward_angles()
    c, s = cos_sin(x)
    want_c = np.array([float(mpmath.cos(mpmath.mpf(float(v)))) for v in x])
    want_s = np.array([float(mpmath.sin(mpmath.mpf(float(v)))) for v in x])
    assert np.max(np.abs(c - want_c)) <= ABS_ERROR
    assert np.max(np.abs(s - want_s)) <= ABS_ERROR


def test_half_angle_cos_sin_within_its_bound_of_numpy_on_a_million_angles():
    x = np.random.default_rng(7).uniform(-20.0, 20.0, 1_000_000)
    c, s = cos_sin(x)
    # np.cos and np.sin are within half an ulp of 1.0 of the true values (glibc)
    assert np.max(np.abs(c - np.cos(x))) <= ABS_ERROR + 2.0 ** -53
    assert np.max(np.abs(s - np.sin(x))) <= ABS_ERROR + 2.0 ** -53


def test_half_angle_cos_sin_of_no_number_is_nan_and_of_one_number_is_numpy():
    with np.errstate(invalid="ignore"):
        c, s = cos_sin(np.array([np.nan, np.inf, -np.inf]))
    assert np.isnan(c).all() and np.isnan(s).all()
    assert cos_sin(0.3) == (np.cos(0.3), np.sin(0.3))
    c, s = cos_sin(np.array([-0.0]))
    assert c[0] == 1.0 and s[0] == 0.0 and np.signbit(s[0])
