"""The synthesis search (docs/synthesis.md, "Searching the free choices"): its result is the
same whatever runs its chunks, and judging only the rows still without a defect keeps
exactly the rows that judging every row keeps."""

from __future__ import annotations

import numpy as np
import pytest

from linkage.synthesis import search
from linkage.synthesis.request import make_request
from linkage.synthesis.search import SEARCH_CHUNK, evaluate_candidates

VARY = ["alpha0=0:350:8", "alpha_span=40:120:3", "phi0=0:350:8", "phi_span=60:120:3"]
"""576 candidates: three chunks of SEARCH_CHUNK, the last one short."""


def same_columns(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for name in a:
        x, y = np.asarray(a[name]), np.asarray(b[name])
        assert x.shape == y.shape, name
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), name
        else:
            assert list(x) == list(y), name


def test_search_results_do_not_depend_on_the_worker_count() -> None:
    assert 2 * SEARCH_CHUNK < 576 < 3 * SEARCH_CHUNK
    runs = [
        search("log10(x)", (1, 2), None, None, VARY, min_transmission=40, top=1000, **how)
        for how in ({"workers": 1}, {"workers": 2}, {"workers": 3}, {"scheduler": "synchronous"},
                    {"scheduler": "threads"})
    ]
    first = runs[0]
    assert first.scanned == 576 and 0 < first.without_defects < 576
    for other in runs[1:]:
        assert (other.scanned, other.without_defects) == (first.scanned, first.without_defects)
        same_columns(first.rows, other.rows)


@pytest.mark.parametrize("task", [("log10(x)", (1, 2)), ("x**2", (0, 1)), ("sin(x)", (0, 1.5))])
def test_judging_only_rows_without_a_defect_keeps_the_same_rows(task) -> None:
    f, x = task
    req = make_request(f, x, (0, 60), (0, 90))
    rng = np.random.default_rng(5)
    n = 400
    a0, p0 = rng.uniform(0, 360, n), rng.uniform(0, 360, n)
    da, dp = rng.uniform(30, 120, n), rng.uniform(40, 120, n) * rng.choice([-1, 1], n)
    every = evaluate_candidates(req, a0, da, p0, dp)
    lazy = evaluate_candidates(req, a0, da, p0, dp, judge_all=False)
    assert np.array_equal(every["ok"], lazy["ok"])
    assert every["ok"].any() and not every["ok"].all()
    keep = np.flatnonzero(every["ok"])
    same_columns({k: np.asarray(v)[keep] for k, v in every.items()},
                 {k: np.asarray(v)[keep] for k, v in lazy.items()})
