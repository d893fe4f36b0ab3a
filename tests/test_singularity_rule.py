"""The one singularity rule of a 2x2 Newton step (rules.invertible) and its source for the
generated loops (rules.invertible_source) give the same verdict on every value, the
special ones included."""

from __future__ import annotations

import math
import random
import sys

from linkage.rules import SINGULAR_RATIO, invertible, invertible_source

SPECIAL = (0.0, -0.0, 1.0, -1.0, math.inf, -math.inf, math.nan, -math.nan, sys.float_info.max,
           -sys.float_info.max, sys.float_info.min, -sys.float_info.min, 5e-324, -5e-324, SINGULAR_RATIO,
           -SINGULAR_RATIO, 1e300, 1e-300, 2, -3, True, False)


def inline(det, size):
    return eval(invertible_source("det", "size"), {}, {"det": det, "size": size})


def test_the_generated_test_is_the_rules_verdict_on_special_values():
    for det in SPECIAL:
        for size in SPECIAL:
            assert inline(det, size) is invertible(det, size), (det, size)


def test_the_generated_test_is_the_rules_verdict_at_the_boundary_and_at_random():
    rng = random.Random(33)
    for _ in range(20_000):
        size = math.ldexp(rng.random(), rng.randint(-1074, 1023))
        edge = SINGULAR_RATIO * size
        for det in (edge, -edge, math.nextafter(edge, math.inf), -math.nextafter(edge, math.inf),
                    math.nextafter(edge, 0.0), rng.uniform(-2, 2) * edge, rng.uniform(-1, 1) * size):
            assert inline(det, size) is invertible(det, size), (det, size)


def test_the_size_expression_is_evaluated_once():
    calls = []

    def seen(v):
        calls.append(v)
        return v

    assert eval(invertible_source("d(1.0)", "s(2.0)"), {}, {"d": seen, "s": seen}) is True
    assert calls.count(2.0) == 1  # det is a name in the generated loops
