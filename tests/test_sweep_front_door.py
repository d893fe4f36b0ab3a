"""The sweep's front door and the closed-form engine's display step, held to the
definitions their faster forms replace: linkage.arguments.check_reals's per-entry rule,
and the angle rule of linkage.kinematics.angles (scalar function and numpy twin)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from linkage.arguments import check_reals
from linkage.errors import InputError
from linkage.kinematics.angles import (
    anchor_index,
    anchor_index_array,
    unwrap_turns,
    unwrap_turns_array,
)


def entry_by_entry(values: list) -> list[float] | str:
    """check_reals's rule for a short list, one entry at a time: every entry a float (or
    an int, or a real numpy scalar) and finite; else the message of the first bad one."""
    try:
        return check_reals("v", values)
    except InputError as e:
        return str(e)


def reference(values: list) -> list[float] | str:
    for k, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return f"v[{k}] must be a real number, got {v!r}"
        if not math.isfinite(float(v)):
            return f"v[{k}] must be finite, got {float(v)!r}"
    return [float(v) for v in values]


@pytest.mark.parametrize("seed", range(40))
def test_check_reals_fast_list_path_is_the_entry_rule(seed):
    """The fast path for a short list (types counted, the sum finite) accepts exactly what
    the entry-by-entry rule accepts, with the same list, and leaves every refusal (a NaN,
    an infinity, a bool, an int, a string) to it: same message. A sum that overflows
    (1e308 + 1e308) is not an infinite entry."""
    rng = np.random.default_rng(seed)
    size = int(rng.integers(0, 400))
    values: list = [float(x) for x in rng.uniform(-1e3, 1e3, size)]
    odd = [math.nan, math.inf, -math.inf, True, 3, "1.5", 1e308, -1e308, np.float64(2.5)]
    for _ in range(int(rng.integers(0, 3))):
        if values:
            values[int(rng.integers(0, len(values)))] = odd[int(rng.integers(0, len(odd)))]
    got = entry_by_entry(values)
    want = reference(values)
    if isinstance(want, list):
        assert got == want and all(type(v) is float for v in got)
    else:
        assert isinstance(got, str) and got.startswith(want.split(" got ")[0])


def test_check_reals_sum_overflow_is_not_a_refusal():
    big = [1e308, 1e308, -1e308, 1e308]
    assert check_reals("v", big) == big
    with pytest.raises(InputError, match=r"v\[2\] must be finite"):
        check_reals("v", [1.0, 2.0, math.inf, -math.inf])
    with pytest.raises(InputError, match=r"v\[1\] must be a real number"):
        check_reals("v", [1.0, True, 2.0])
    assert check_reals("v", [1.0, 2, 3.5]) == [1.0, 2.0, 3.5]


@pytest.mark.parametrize("seed", range(12))
def test_anchor_index_array_is_the_scalar_rule(seed):
    """anchor_index_array (its circular distance by fmod, the same as % for d >= 0) picks
    the scalar rule's index, ties to the first, on grids of every span and driver values
    far outside them."""
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 800))
    start = float(rng.uniform(-720.0, 720.0))
    grid = start + np.sort(rng.uniform(0.0, 400.0, n))
    turn = 360.0 if seed % 2 else 2 * math.pi
    for v0 in (*rng.uniform(-2000.0, 2000.0, 20), start, float(grid[-1]), 1e17, -1e17):
        for closes in (True, False):
            got = anchor_index_array(grid, True, float(v0), closes, turn)
            masked = anchor_index_array(grid, np.ones((1, n), bool), float(v0), closes, turn)
            want = anchor_index(list(grid), [True] * n, float(v0), closes, turn)
            assert got.shape == (1,) and got[0] == masked[0] == want


@pytest.mark.parametrize("seed", range(8))
def test_unwrap_turns_array_fast_path_is_the_scalar_rule_far_out(seed):
    """The every-position-solved path of unwrap_turns_array gives the scalar rule's turns
    bit for bit, for angles as solved (-180..180], far from them, and many turns round."""
    rng = np.random.default_rng(200 + seed)
    scale = (180.0, 1e4, 1e9)[seed % 3]
    rows = np.cumsum(rng.uniform(-170.0, 170.0, size=(3, 361)), axis=1) + rng.uniform(-scale, scale, (3, 1))
    for closes in (True, False):
        got = unwrap_turns_array(rows, closes)
        for row, turns in zip(rows, got):
            assert list(turns) == unwrap_turns(list(row), closes)
        # told every value is finite (the closed-form engine), the same turns, bit for bit
        assert np.array_equal(unwrap_turns_array(rows, closes, all_solved=True), got)
        assert not np.signbit(got[got == 0.0]).any()  # no -0.0: _display adds no zero shift


def test_a_cold_sweep_does_not_load_the_scalar_solve():
    """A command-line sweep reads the system solve and the criteria: the scalar solve, its
    root certificate and its problem type are not loaded (linkage.solve's names are
    imported on first use), and every name is still importable from linkage.solve."""
    import os
    import subprocess
    import sys

    from linkage.samples import sample_path

    probe = ("import sys, runpy\n"
             f"sys.argv = ['linkage', 'sweep', {str(sample_path('crank_rocker.toml'))!r}]\n"
             "try:\n    runpy.run_module('linkage', run_name='__main__')\nexcept SystemExit:\n    pass\n"
             "print(' '.join(m for m in sys.modules if m.startswith('linkage')), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    loaded = set(out.stderr.split())
    assert {"linkage.solve.system", "linkage.solve.criteria", "linkage.kinematics.stepwise"} <= loaded
    assert not loaded & {"linkage.solve.scalar", "linkage.solve.certificate", "linkage.problems.scalar"}
    import linkage.solve as solve

    for name in solve.__all__:
        assert getattr(solve, name) is not None
    from linkage.solve import certify_root, solve_scalar

    assert solve_scalar.__module__ == "linkage.solve.scalar"
    assert certify_root.__module__ == "linkage.solve.certificate"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        solve.nothing  # noqa: B018
