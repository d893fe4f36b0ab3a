"""A display table's cells (linkage.render.report.fmt): each kind of value as the tables
print it, the finite floats (a table's usual cell, formatted first) included."""

import math

import numpy as np
import pytest

from linkage.render.report import fmt


@pytest.mark.parametrize("value, digits, text", [
    (None, 12, "—"), (True, 12, "yes"), (False, 12, "no"), (0, 12, "0"), (-7, 3, "-7"),
    (10**30, 4, str(10**30)), (np.int64(3), 12, "3"), ("open", 12, "open"),
    (0.0, 12, "0"), (-0.0, 12, "0"), (math.nan, 12, "NaN"), (math.inf, 12, "inf"), (-math.inf, 12, "-inf"),
    (np.float64(math.nan), 6, "NaN"), (np.float64(-math.inf), 6, "-inf"), (np.float64(0.0), 6, "0"),
    (1 / 3, 12, "0.333333333333"), (-2.5, 3, "-2.5"), (123456.789, 4, "1.235e+05"),
    (5e-324, 12, "4.94065645841e-324"), (1e300, 1, "1e+300"), (np.float64(54.8877631887791), 6, "54.8878"),
])
def test_a_table_cell_reads_the_same_for_every_kind_of_value(value, digits, text):
    assert fmt(value, digits) == text


def test_a_finite_float_cell_is_its_g_format_at_the_digits():
    rng = np.random.default_rng(7)
    for v in rng.standard_normal(200) * 10.0 ** rng.integers(-300, 300, 200):
        for digits in (1, 6, 12, 17):
            assert fmt(float(v), digits) == format(float(v), f".{digits}g")


def test_a_finite_float_cell_is_its_g_format_for_any_double():
    """fmt writes a finite float by printf's %g at the digits: the text of format(v,
    ".{digits}g") for any double (random bit patterns: subnormal, huge, every exponent)
    and digits, numpy's float64 included."""
    import random
    import struct

    rng = random.Random(13)
    checked = 0
    while checked < 20000:
        v = struct.unpack("d", struct.pack("Q", rng.getrandbits(64)))[0]
        if not math.isfinite(v) or v == 0.0:
            continue
        digits = rng.randint(1, 17)
        assert fmt(v, digits) == format(v, f".{digits}g")
        assert fmt(np.float64(v), digits) == format(v, f".{digits}g")
        checked += 1
