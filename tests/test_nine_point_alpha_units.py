"""Smale's alpha test of nine-point solutions (linkage.homotopy.ninepoint_alpha) gives the
same verdict at any unit of length: the equations are homogeneous in length (the roots of
points s times as large are s times as large), and the test is made in the unit of the
points' spread (ninepoint_alpha.unit_of_length). The problem: Problem 3's first 60 orbits
(Wampler, Morgan and Sommese 1992; two of them real), tracked at each size in a second or
two, the same problem the scaled solves of tests/test_nine_point.py use."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from linkage.homotopy import ninepoint_alpha as na
from linkage.homotopy import ninepoint_track as nt
from linkage.synthesis.path import PROBLEM_3

ORBITS = 60


def _solved(scale: float):  # type: ignore[no-untyped-def]
    pts = [complex(x, y) * scale + (5.0 - 2.0j) * scale for x, y in PROBLEM_3]
    return nt.solve_points(pts, max_routes=1, orbits=ORBITS)


@pytest.fixture(scope="module")
def unit_size():
    return _solved(1.0)


@pytest.mark.parametrize("scale", [1e-9, 1e3])
def test_the_alpha_test_certifies_the_same_real_four_bars_at_any_unit_of_length(scale, unit_size):
    """Found: docs/path_synthesis.md's points scaled by 1e-9 gave the same 43 real
    four-bars (lengths times 1e-9), and the report said '0 of the 43 real four-bars
    certified real' where the points at their size certify 43 of 43 (alpha near 1e32 at
    1e-9: the test's bound on gamma is taken in the affine chart, not in the points' unit)."""
    from linkage.render.path_synthesis import certified_line
    from linkage.synthesis.path import real_certificates

    moved = _solved(scale)
    assert int(moved.real.sum()) == int(unit_size.real.sum()) == 2
    lines = [certified_line(SimpleNamespace(certificates=real_certificates(s))) for s in (unit_size, moved)]
    assert lines[0] == lines[1] == (
        "alpha test (Smale; 50 digits): 2 of the 2 real four-bars certified real, all distinct")
    # the radius is in the points' own lengths: the tracked root lies within it, at either size
    certs, _ = real_certificates(moved)
    unit_rows = unit_size.solutions[unit_size.real]
    for z, c in zip(moved.solutions[moved.real], certs):
        assert np.min(np.linalg.norm(unit_rows * scale - z, axis=1)) <= c.radius + 1e-8 * scale


def test_points_a_power_of_two_apart_in_size_get_the_same_certificate_bit_for_bit(unit_size):
    """Division by a power of two is exact: the certificate of points 2^-30 times as large
    (their roots scaled exactly) is the same, its radius 2^-30 times as large."""
    rows = unit_size.solutions[unit_size.real]
    points = np.array(unit_size.points)
    here = na.certify_rows(rows, points)
    small = na.certify_rows(rows * 2.0 ** -30, points * 2.0 ** -30)
    for a, b in zip(here, small):
        fields = ("alpha", "beta", "gamma", "certified", "real", "not_real")
        assert [getattr(a, f) for f in fields] == [getattr(b, f) for f in fields]
        assert b.radius == a.radius * 2.0 ** -30
