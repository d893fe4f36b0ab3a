"""steps.coefficients, one generated function per step, against the definition it replaced:
each step's sums taken term by term over ref_value (held here as it was written), equal bit
for bit on the scalar path (math) and its numpy twin, for every case and every kind of
reference (the driver, an unknown, a parameter, a number), offsets or none, and on the
derived steps of every sample mechanism."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest

from linkage.problems import steps
from linkage.problems.derive import GivenTrig
from linkage.problems.steps import (
    DRIVER,
    ITS_LENGTH,
    OTHER_LENGTH,
    TWO_ANGLES,
    TWO_LENGTHS,
    Step,
    coefficients,
    ref_value,
)


def _known_sum(terms, params, d, q, xp):
    x = y = 0.0
    for sign, lr, ar, off in terms:
        r = sign * ref_value(lr, params, d, q)
        t = ref_value(ar, params, d, q) + off if off else ref_value(ar, params, d, q)
        x = x + r * xp.cos(t)
        y = y + r * xp.sin(t)
    return x, y


def _angle_coefficient(terms, params, d, q, xp):
    x = y = 0.0
    for sign, lr, _, off in terms:
        r = sign * ref_value(lr, params, d, q)
        if off:
            x = x + r * math.cos(off)
            y = y + r * math.sin(off)
        else:
            x = x + r
    return x, y


def _length_coefficient(terms, params, d, q, xp, with_angle):
    x = y = 0.0
    for sign, _, ar, off in terms:
        if with_angle:
            t = ref_value(ar, params, d, q) + off if off else ref_value(ar, params, d, q)
            x = x + sign * xp.cos(t)
            y = y + sign * xp.sin(t)
        elif off:
            x = x + sign * math.cos(off)
            y = y + sign * math.sin(off)
        else:
            x = x + sign
    return x, y


def reference(step, params, d, q, xp):
    """coefficients as it was written: the sums term by term."""
    k = _known_sum(step.known, params, d, q, xp)
    case = step.case
    if case == TWO_ANGLES:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _angle_coefficient(step.second, params, d, q, xp), k)
    if case == ITS_LENGTH:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _length_coefficient(step.second, params, d, q, xp, False), k)
    if case == OTHER_LENGTH:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _length_coefficient(step.second, params, d, q, xp, True), k)
    return (_length_coefficient(step.first, params, d, q, xp, True),
            _length_coefficient(step.second, params, d, q, xp, True), k)


def _bits(v):
    """Every bit of a number or an array (the sign of a zero and a NaN's included)."""
    return np.asarray(v, dtype=float).tobytes()


def _same(a, b):
    return [[_bits(v) for v in pair] for pair in a] == [[_bits(v) for v in pair] for pair in b]


def _random_ref(rng, n_q):
    kind = rng.randrange(4)
    if kind == 0:
        return DRIVER
    if kind == 1:
        return rng.randrange(n_q)
    if kind == 2:
        return rng.choice(["a", "b", "th"])
    return rng.choice([0.0, -0.0, 1.5, -2.25, rng.uniform(-10, 10)])


def _random_term(rng, n_q):
    sign = rng.choice([1.0, -1.0, 0.5, -0.75, rng.uniform(-3, 3)])
    off = rng.choice([0.0, 0.0, -0.0, math.pi / 6, rng.uniform(-4, 4)])
    return (sign, _random_ref(rng, n_q), _random_ref(rng, n_q), off)


def _random_step(rng, n_q=4):
    def terms(lo):
        return tuple(_random_term(rng, n_q) for _ in range(rng.randint(lo, 3)))

    case = rng.choice([TWO_ANGLES, ITS_LENGTH, OTHER_LENGTH, TWO_LENGTHS, "a case not named"])
    return Step(case, (0,), (1.0,), (0, 1), terms(0), terms(1), terms(1))


def test_generated_coefficients_are_the_term_by_term_sums_scalar_and_numpy():
    rng = random.Random(5)
    nrng = np.random.default_rng(5)
    for _ in range(1500):
        step = _random_step(rng)
        params = {"a": rng.uniform(-5, 5), "b": rng.uniform(0.1, 9), "th": rng.uniform(-7, 7)}
        d = rng.choice([0.0, -0.0, rng.uniform(-7, 7), 1e-300])
        q = [rng.choice([rng.uniform(-7, 7), math.nan, 0.0]) for _ in range(4)]
        assert _same(coefficients(step, params, d, q, math), reference(step, params, d, q, math))
        # the numpy twin: driver and unknowns as arrays (NaN where a step was not solved),
        # a parameter as an array (a scan's designs)
        da = nrng.uniform(-7, 7, 5)
        qa = [np.where(nrng.random(5) < 0.2, np.nan, nrng.uniform(-7, 7, 5)) for _ in range(4)]
        pa = {**params, "b": nrng.uniform(0.1, 9, 5)}
        with np.errstate(invalid="ignore"):
            assert _same(coefficients(step, pa, da, qa, np), reference(step, pa, da, qa, np))
            trig = GivenTrig(da, np.cos(da), np.sin(da))
            assert _same(coefficients(step, pa, da, qa, trig), reference(step, pa, da, qa, trig))


def test_generated_coefficients_read_what_the_sums_read():
    """A parameter missing is the same KeyError, an unknown out of range the same IndexError."""
    step = Step(TWO_ANGLES, (0,), (1.0,), (0, 1), ((1.0, "missing", DRIVER, 0.0),), ((1.0, 3.0, 0, 0.0),),
                ((1.0, 7, 1, 0.0),))
    for args in (({}, 0.1, [0.0, 0.0]), ({"missing": 1.0}, 0.1, [0.0, 0.0])):
        errors = []
        for fn in (coefficients, reference):
            with pytest.raises((KeyError, IndexError)) as info:
                fn(step, *args, math)
            errors.append((info.type, str(info.value)))
        assert errors[0] == errors[1]


def test_generated_coefficients_of_every_sample_are_the_sums():
    from linkage.kinematics.loading import load

    rng = random.Random(9)
    samples = sorted((Path(__file__).resolve().parents[1] / "sample_inputs").glob("*.toml"))
    checked = 0
    for path in samples:
        try:
            d = load(path).derivation
        except Exception:  # a file the loader refuses is another test's business
            continue
        for step in d.steps:
            for _ in range(20):
                drv = rng.uniform(-7, 7)
                q = [rng.uniform(-7, 7) for _ in range(d.n)]
                got = coefficients(step, d.params, drv, q, math)
                assert _same(got, reference(step, d.params, drv, q, math))
                checked += 1
    assert checked >= 200


def test_a_step_is_generated_once_and_never_mistaken_for_another():
    rng = random.Random(3)
    step = _random_step(rng)
    coefficients(step, {"a": 1.0, "b": 2.0, "th": 0.5}, 0.3, [0.1] * 4, math)
    fn = steps._GENERATED[id(step)][1]
    coefficients(step, {"a": 1.0, "b": 2.0, "th": 0.5}, 0.4, [0.2] * 4, math)
    assert steps._GENERATED[id(step)][1] is fn
    other = _random_step(rng)
    steps._GENERATED[id(other)] = (step, fn)  # as if another step had had this id
    params = {"a": 1.0, "b": 2.0, "th": 0.5}
    q = [0.1] * 4
    assert _same(coefficients(other, params, 0.3, q, math), reference(other, params, 0.3, q, math))
    assert steps._GENERATED[id(other)][0] is other
