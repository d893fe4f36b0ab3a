"""The speed work of issue 18 (h2-perf): what a command loads, and the front door's fast
paths giving what the general check gives. No timings here: times are measured by
benchmarks/ and reported in the README, never asserted."""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from linkage.arguments import check_reals
from linkage.errors import InputError
from linkage.samples import sample_path


def _loaded_after(code: str) -> set[str]:
    """The linkage modules a fresh interpreter has loaded after running ``code``."""
    probe = code + "\nimport sys\nprint(' '.join(m for m in sys.modules if m.startswith('linkage')))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    return set(out.stdout.split())


def test_a_sweep_without_rates_does_not_load_the_rate_engine():
    path = str(sample_path("crank_rocker.toml"))
    plain = _loaded_after(f"import linkage\nlinkage.sweep(linkage.load_mechanism({path!r}), range(5))")
    assert "linkage.kinematics.sweep" in plain
    assert "linkage.kinematics.rates" not in plain
    # (a position's rates are computed when it is read: the closed-form engine's positions
    # are built lazily, as the batch engine's)
    moving = _loaded_after(f"import linkage\nlinkage.sweep(linkage.load_mechanism({path!r}), range(5), "
                           "speed=1.0).positions[0].rates")
    assert "linkage.kinematics.rates" in moving


def test_a_sweep_table_without_rates_does_not_load_the_rate_engine():
    loaded = _loaded_after("import linkage.render.sweep")
    assert "linkage.kinematics.sweep" in loaded
    # the rate cells are imported only by a table that has rates (a cold sweep's start)
    assert "linkage.render.rates" not in loaded
    assert "linkage.kinematics.rates" not in loaded
    with_cells = _loaded_after("import linkage.render.sweep, linkage.render.rates")
    assert "linkage.kinematics.labels" in with_cells
    assert "linkage.kinematics.rates" not in with_cells


def test_a_solves_rates_do_not_load_the_sweep_result_types():
    loaded = _loaded_after("import linkage.kinematics.rates")
    assert "linkage.kinematics.positions" not in loaded


def test_with_rates_is_still_importable_from_the_sweep_module():
    from linkage.kinematics import rate_blocks, sweep

    assert sweep.with_rates is rate_blocks.with_rates
    with pytest.raises(AttributeError):
        sweep.no_such_name  # noqa: B018


@pytest.mark.parametrize("values", [
    [1.0, 2.5, -3.0], (0.0, 1e300), [1, 2, 3], (1, 2.0), [10**300, -7], [2**1023, 0.5], [],
    list(range(361)),
])
def test_the_front_doors_fast_paths_give_the_values_as_floats(values):
    got = check_reals("values", values)
    assert type(got) is list
    assert got == [float(v) for v in values]
    assert all(type(v) is float for v in got)


@pytest.mark.parametrize("values, where", [
    ([1.0, math.nan], "values[1]"), ((math.inf, 1.0), "values[0]"), ([1, -math.inf], "values[1]"),
    ([1.0, True], "values[1]"), ([2**1024, 1.0], "values[0]"), ([1.0, "2"], "values[1]"),
])
def test_the_front_doors_fast_paths_still_refuse_bad_entries(values, where):
    with pytest.raises(InputError, match="^" + re.escape(where) + " "):
        check_reals("values", values)


def test_the_fast_path_keeps_the_length_and_size_checks():
    with pytest.raises(InputError, match="needs 3 values"):
        check_reals("q", [1.0, 2.0], length=3)
    with pytest.raises(InputError, match="more than 2"):
        check_reals("values", (1.0, 2.0, 3.0), most=2)


def test_keep_array_gives_the_batch_engine_an_array_with_the_same_values():
    values = np.linspace(0.0, 360.0, 2001)
    kept = check_reals("values", values, keep_array=True)
    assert isinstance(kept, np.ndarray) and kept.dtype == np.float64
    assert kept.tolist() == values.tolist()
    assert check_reals("values", values) == values.tolist()
    with pytest.raises(InputError, match=r"values\[3\] must be finite"):
        check_reals("values", np.array([0.0, 1.0, 2.0, np.nan]), keep_array=True)


def test_a_scan_does_not_load_the_rate_engine():
    """batch.py imported the rates at its top, so every scan (designs imports batch) loaded
    the rate engine it never uses."""
    code = ("import sys, linkage.scan; "
            "print('linkage.kinematics.rates' in sys.modules)")
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_driver_values_as_an_array_are_the_lists_values_bit_for_bit():
    """A sweep of more positions than ``array_above`` gets its driver values as a numpy
    array (no list of 360,001 floats to build and convert): the same values, bit for bit,
    as the list, for steps and for points, across signs, scales and the grid's end."""
    import random

    import numpy as np

    from linkage.kinematics.positions import driver_values

    rng = random.Random(39)
    cases = [(0.0, 360.0, 0.001, None), (-0.0, 1.0, 0.1, None), (-180.0, 180.0, None, 7919),
             (1e-6, 2e-6, 1e-9, None), (-1e5, 1e5, None, 20001), (0.1, 0.7, 0.1, None)]
    for _ in range(200):
        a = rng.uniform(-1e3, 1e3) * 10.0 ** rng.randint(-6, 3)
        b = a + abs(a or 1.0) * rng.uniform(0.001, 10.0)
        cases.append((a, b, (b - a) / rng.uniform(2.0, 3000.0), None))
        cases.append((a, b, None, rng.randint(2, 3000)))
    for a, b, step, points in cases:
        listed = driver_values(a, b, step, points)
        arrayed = driver_values(a, b, step, points, array_above=1)
        assert isinstance(arrayed, np.ndarray) and arrayed.dtype == np.float64
        assert np.array_equal(np.array(listed).view(np.int64), arrayed.view(np.int64)), (a, b, step, points)
    assert driver_values(0.0, 1.0, 0.5, None, array_above=3) == [0.0, 0.5, 1.0]  # not above: a list
