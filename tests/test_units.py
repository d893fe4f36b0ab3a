"""The one angle conversion gives the bits of math's and numpy's (linkage.units)."""

from __future__ import annotations

import math
import random

import numpy as np

from linkage.units import degrees, radians


def test_units_match_math_and_numpy_bit_for_bit():
    rng = random.Random(20261128)
    values = [rng.uniform(-1e6, 1e6) for _ in range(2000)] + [rng.uniform(-720, 720) for _ in range(2000)]
    values += [0.0, -0.0, 30.0, 90.0, 180.0, 360.0, 1e-300, 5e-324, 1e300]
    for v in values:
        assert radians(v) == math.radians(v)
        assert degrees(v) == math.degrees(v)
    arr = np.array(values)
    assert np.array_equal(radians(arr), np.radians(arr))
    assert np.array_equal(degrees(arr), np.degrees(arr))
    assert np.array_equal(radians(arr), np.array([math.radians(v) for v in values]))


def test_units_round_trip_is_not_assumed_exact():
    """30 deg there and back is 29.999999999999996: a reader shown a drawn value shows the
    value it read, not a round trip (why engines keep the degrees they were given)."""
    assert degrees(radians(30.0)) != 30.0
    assert abs(degrees(radians(30.0)) - 30.0) <= 4e-15
