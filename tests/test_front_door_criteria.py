"""The front doors remember the criteria they checked last by the identity of the values
given (solve/criteria.py, RecentCriteria): only immutable values are remembered, so a
changed or mutable value is checked again, and a bad one is refused after good ones."""

from __future__ import annotations

import numpy as np
import pytest

from linkage import fourbar_equation, solve_scalar, solve_system
from linkage.errors import InputError


def _F(q: list[float]) -> list[float]:
    return [q[0] * q[0] + q[1] * q[1] - 4.0, q[0] - q[1]]


def _J(q: list[float]) -> list[list[float]]:
    return [[2.0 * q[0], 2.0 * q[1]], [1.0, -1.0]]


def test_a_bad_tolerance_after_good_ones_is_refused_at_both_front_doors():
    p = fourbar_equation(70.0)
    tol = 1e-12
    for _ in range(2):
        assert solve_scalar(p, method="newton", x0=50.0, tol=tol, record=False).meta["tol"] == tol
        assert solve_system(_F, (1.0, 2.0), jac=_J, tol=tol, record=False).meta["tol"] == tol
    for bad in (-1.0, 0.0, float("nan"), True):
        with pytest.raises(InputError, match="tol"):
            solve_scalar(p, method="newton", x0=50.0, tol=bad, record=False)
        with pytest.raises(InputError, match="tol"):
            solve_system(_F, (1.0, 2.0), jac=_J, tol=bad, record=False)
    assert solve_scalar(p, method="newton", x0=50.0, tol=1e-9, rtol=1e-10, record=False).meta["rtol"] == 1e-10
    assert solve_system(_F, (1.0, 2.0), jac=_J, tol=1e-9, max_iter=3, record=False).iterations <= 3


def test_a_mutable_tolerance_is_checked_on_every_call():
    p = fourbar_equation(70.0)
    tol = np.array(1e-10)
    assert solve_scalar(p, method="newton", x0=50.0, tol=tol, record=False).meta["tol"] == 1e-10
    tol[()] = 1e-4
    assert solve_scalar(p, method="newton", x0=50.0, tol=tol, record=False).meta["tol"] == 1e-4
    tol[()] = -1.0
    with pytest.raises(InputError, match="tol"):
        solve_scalar(p, method="newton", x0=50.0, tol=tol, record=False)
