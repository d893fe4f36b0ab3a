"""Timing as every speed figure of ``linkage bench`` takes it: a ratio against a baseline
measured in the same run, as interleaved pairs (A, B, A, B, ...), the median of the
pairs' ratios (the machine's noise then hits both sides of a pair alike)."""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable
from typing import Any

from ..records import frozen

Clock = Callable[[], float]


@frozen
class Pairs:
    """Seconds of A and of B, taken in turn (``a[i]`` just before ``b[i]``), per call."""

    a: tuple[float, ...]
    b: tuple[float, ...]

    @property
    def ratio(self) -> float:
        """The median over the pairs of A / B."""
        return statistics.median(x / y for x, y in zip(self.a, self.b))

    @property
    def a_median(self) -> float:
        return statistics.median(self.a)

    @property
    def b_median(self) -> float:
        return statistics.median(self.b)


def calls_for(fn: Callable[[], Any], budget: float, clock: Clock = time.perf_counter) -> int:
    """How many calls of ``fn`` take about ``budget`` seconds (at least one): a short call is
    timed in batches, so that the clock's resolution and the loop's cost do not count."""
    n = 1
    while True:
        t0 = clock()
        for _ in range(n):
            fn()
        dt = clock() - t0
        if dt >= budget / 4 or n >= 1 << 20:
            return max(1, int(n * budget / max(dt, 1e-9)))
        n *= 4


def interleaved_pairs(a: Callable[[], Any], b: Callable[[], Any], repeats: int, budget: float = 0.0,
                      clock: Clock = time.perf_counter) -> Pairs:
    """``repeats`` pairs: a batch of A, then a batch of B, each batch of as many calls as take
    about ``budget`` seconds (one call when 0: a process, a big sweep), after one untimed
    call of each (a model compiles once, as in a session; numpy's first runs also pay for
    fresh pages). Times are per call. The garbage of what ran before is collected first:
    left behind, it made every later solve's collections slower (a scalar Newton solve
    measured 6x slower after the work-precision run than after ``gc.collect()``)."""
    gc.collect()
    a(), b()
    na = calls_for(a, budget, clock) if budget else 1
    nb = calls_for(b, budget, clock) if budget else 1
    ta, tb = [], []
    for _ in range(repeats):
        for fn, n, out in ((a, na, ta), (b, nb, tb)):
            t0 = clock()
            for _ in range(n):
                fn()
            out.append((clock() - t0) / n)
    return Pairs(tuple(ta), tuple(tb))


def time_per_call(fn: Callable[[], Any], repeats: int, budget: float) -> tuple[float, float, float]:
    """Median, min and max seconds per call over ``repeats`` batches of about ``budget`` s
    (the garbage of what ran before collected first, as in :func:`interleaved_pairs`)."""
    gc.collect()
    n = calls_for(fn, budget)
    per = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        per.append((time.perf_counter() - t0) / n)
    return statistics.median(per), min(per), max(per)


def interleaved(fns: dict[str, Callable[[], Any]], repeats: int) -> dict[str, tuple[float, list[float], Any]]:
    """(median seconds, the timings, the last result) of each function: one untimed run of
    each first, then the repeats taken in turn, so that the machine's noise hits all alike
    (the garbage of what ran before collected first, as in :func:`interleaved_pairs`)."""
    gc.collect()
    times: dict[str, list[float]] = {k: [] for k in fns}
    last: dict[str, Any] = {}
    for rep in range(repeats + 1):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            last[k] = fn()
            if rep:
                times[k].append(time.perf_counter() - t0)
    return {k: (statistics.median(ts), ts, last[k]) for k, ts in times.items()}


def time_per_solve(problem: Any, kwargs: dict[str, Any]) -> float:
    """Seconds per solve with recording off, the median of short timed batches."""
    from ..solve import solve_scalar

    kw = dict(kwargs, record=False)
    times = []
    for _ in range(5):
        n = 0
        t0 = time.perf_counter()
        while True:
            solve_scalar(problem, **kw)
            n += 1
            dt = time.perf_counter() - t0
            if dt > 0.002:
                break
        times.append(dt / n)
    times.sort()
    return times[len(times) // 2]
