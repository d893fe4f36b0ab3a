"""The array engines' stopping order (linkage.rules.SystemStops) is the scalar loop's
(iterate.run, for Newton on a system) position by position. The reference is the scalar
loop itself, driven by a scripted method whose steps report given errors, residuals,
iterate sizes and singular Jacobians, and solve.system_verdict on its outcome; the twin is
driven by the same scripts, a block of positions at a time."""

from __future__ import annotations

import math
import random
from typing import Any, NamedTuple

import numpy as np
import pytest

from linkage import iterate, rules
from linkage.iterate import Criteria
from linkage.result import Status
from linkage.solve import system_verdict

TOL, GATE, MAX_ITER = 1e-10, 1e-9, 12


class Scripted(NamedTuple):
    x: float  # max|q| of the iterate
    fx: float | None  # max|Phi| where the step was taken from
    err: float
    stop: Any
    i: int


class ScriptedNewton:
    """A system method whose k-th step reports the script's k-th (err, resid, |q|, singular)."""

    needs_residual = True
    minimizes = False
    first_index = 1
    plausible = None

    def __init__(self, can_diverge: bool) -> None:
        self.can_diverge = can_diverge

    def initial_row(self, problem: Any, s: Any) -> None:
        return None

    def row(self, problem: Any, s: Any, i: int) -> tuple[Any, ...]:
        return (i,)

    def step(self, script: list[tuple[float, float, float, bool]], s: Scripted) -> Scripted:
        err, resid, size, singular = script[s.i]
        if singular:
            return Scripted(s.x, resid, math.nan, (Status.SINGULAR_JACOBIAN, ""), s.i + 1)
        return Scripted(size, resid, err, None, s.i + 1)


def _script(rng: random.Random) -> tuple[float, list[tuple[float, float, float, bool]]]:
    """A random run: max|q0| and MAX_ITER steps, biased to reach every test."""
    q0 = rng.choice([0.0, 1.0, 250.0, 1e3])
    size = q0 if q0 else 1.0
    err = rng.choice([1.0, 1e-3, 1e-8])
    out = []
    mode = rng.choice(["converge", "stall", "grow", "slow", "wild"])
    for _ in range(MAX_ITER):
        if mode == "converge":
            err = err * rng.choice([1e-3, 1e-2, 0.5, 2.0])
        elif mode == "stall":
            err = rng.choice([1e-13, 2e-13, 1e-13, 5e-14, 3e-13]) * size / 1e3
        elif mode == "slow":  # a linear rate: the cap ends it
            err = err * 0.9
        elif mode == "grow":
            err = err * rng.choice([3.0, 10.0, 10.0, 0.5])
            size = size * rng.choice([1.0, 1e4, 1e6])
        else:
            err = rng.choice([1e-12, 1e-9, 1e-11, math.nan, math.inf, 0.0, 1.0, err * 2.0])
        resid = rng.choice([0.0, 1e-12, 5e-10, 1e-9, 2e-9, 1e-6, 1.0, math.nan, math.inf]
                           if mode == "wild" else [1e-12, 5e-10, 2e-9, 1e-6, 0.0])
        out.append((err, resid, size * rng.choice([1.0, 1.0, 1.5]), rng.random() < 0.04))
    return q0, out


def _scalar(q0: float, script: list[tuple[float, float, float, bool]], can_diverge: bool) -> tuple[str, int]:
    state, status, detail, k, _ = iterate.run(ScriptedNewton(can_diverge), script,
                                              Scripted(q0, None, math.inf, None, 0),
                                              Criteria(TOL, 0.0, GATE, MAX_ITER), record=False)
    status, _ = system_verdict(status, detail, state.fx if state.fx is not None else math.nan, GATE)
    return status.value, k


def _array(q0s: list[float], scripts: list[list[tuple[float, float, float, bool]]],
           can_diverge: bool, whole: bool = False) -> list[tuple[str, int]]:
    """The twin on the scripts; ``whole``: a step at every position passes rows=None (the
    engines' first steps), else the rows always."""
    arr = np.array(scripts, dtype=float)  # (cases, steps, 4)
    stops = rules.SystemStops(TOL, GATE, np.array(q0s), can_diverge)
    out: list[tuple[str, int]] = [("max_iter", MAX_ITER)] * len(scripts)
    active = np.arange(len(scripts))
    for k in range(1, MAX_ITER + 1):
        if not active.size:
            break
        err, resid, size, singular = (arr[active, k - 1, j] for j in range(4))
        rows = None if whole and active.size == len(scripts) else active
        codes = stops.judge(err, resid, singular.astype(bool), size, rows=rows)
        for i, c in zip(active[codes != rules.GOING], codes[codes != rules.GOING]):
            out[i] = (rules.ARRAY_STATUS[c], k)
        active = active[codes == rules.GOING]
    return out


@pytest.mark.parametrize("can_diverge", [True, False])
def test_the_array_stops_are_the_scalar_loops_on_random_runs(can_diverge):
    rng = random.Random(33 + can_diverge)
    cases = [_script(rng) for _ in range(1500)]
    got = _array([q for q, _ in cases], [s for _, s in cases], can_diverge)
    want = [_scalar(q, s, can_diverge) for q, s in cases]
    assert got == want
    # a first step of every position judged as a whole (rows=None: what is kept is made
    # only when a later step needs it) is the same
    assert _array([q for q, _ in cases], [s for _, s in cases], can_diverge, whole=True) == want
    seen = {status for status, _ in want}
    # every verdict the twin knows was met (the undamped run's divergence included)
    expected = set(rules.ARRAY_STATUS[1:]) | {"max_iter"}
    assert seen == (expected if can_diverge else expected - {"diverged"})


def test_a_first_step_at_rounding_level_counts_toward_the_precision_limit():
    """Six shrinking steps at rounding level with the residual above the gate: the sixth
    is the precision limit only if the first counted, on every way of judging it."""
    shrinking = [(e, 1e-6, 1e3, False) for e in (4e-13, 3e-13, 2e-13, 1e-13, 5e-14, 2e-14)]
    script = shrinking + [(1e-14, 1e-6, 1e3, False)] * (MAX_ITER - len(shrinking))
    loose = [(1e-3, 1e-6, 1e3, False)] * MAX_ITER  # a second position that goes on
    want = [_scalar(1e3, script, True), _scalar(1e3, loose, True)]
    assert want[0] == ("precision_limit", 6)
    for whole in (False, True):
        assert _array([1e3, 1e3], [script, loose], True, whole) == want


def test_the_twins_constants_are_the_scalar_loops():
    assert rules.SYSTEM_DIVERGE_STREAK == iterate.DIVERGE_STREAK
    assert rules.SYSTEM_RUNAWAY == iterate.RUNAWAY
    assert rules.SYSTEM_ROUNDING == iterate.ROUNDING


def test_the_codes_name_the_scalar_statuses():
    for code, name in enumerate(rules.ARRAY_STATUS[1:], start=1):
        assert Status(name).converged == bool(rules.converged_codes(np.array([code]))[0])


def test_the_short_way_of_a_block_that_stops_at_once_is_the_ordered_tests():
    """judge's short way (a block whose every step and residual is within the limits: one
    full pass instead of the ordered tests) gives the ordered tests' codes, exact zeros
    included; a block with one position outside, a NaN, an inf or a singular J takes the
    ordered tests. The reference is the same judge with the short way turned off."""
    rng = np.random.default_rng(5)
    seen = set()
    for case in range(400):
        k = int(rng.integers(1, 40))
        err = rng.choice([0.0, 1e-13, TOL, TOL / 2, 2 * TOL, math.nan, math.inf], k,
                         p=[0.2, 0.3, 0.2, 0.26, 0.02, 0.01, 0.01])
        resid = rng.choice([0.0, 1e-12, GATE, 2 * GATE, math.inf], k, p=[0.3, 0.4, 0.27, 0.02, 0.01])
        singular = rng.random(k) < 0.01 if case % 2 else None
        q0 = rng.uniform(0.0, 10.0, k)
        got = rules.SystemStops(TOL, GATE, q0).judge(err, resid, singular, q0)
        ordered = rules.SystemStops(TOL, GATE, q0)
        ordered.bounded = False
        want = ordered.judge(err, resid, singular, q0)
        assert got.dtype == want.dtype and np.array_equal(got, want), (err, resid, singular)
        seen.add(bool(rules.converged_codes(want).all()))
    assert seen == {True, False}  # both ways were taken
    assert not rules.SystemStops(TOL, math.inf, np.zeros(1)).bounded  # an inf limit: the ordered tests
