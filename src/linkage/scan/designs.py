"""Which designs a scan visits: ``--vary NAME=LO:HI[:N]`` checked against the mechanism,
and the plan that gives any chunk of designs (a grid, the last parameter varying fastest,
or ``samples`` random or Latin-hypercube draws, reproducible from the seed: design i is the
same whatever the chunk size or the scheduler)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..errors import InputError, ParseError
from ..problems.loops import Mechanism
from ..records import frozen

MAX_DESIGNS = 10_000_000
MAX_SCAN_POSITIONS = 100_000
MAX_SAMPLE_VALUES = 20_000_000
"""--samples x varied parameters: the drawn designs are held in memory (160 MB)."""


@frozen
class Vary:
    """One ``--vary NAME=LO:HI[:N]``: file units, N points (None: sampled)."""

    name: str
    lo: float
    hi: float
    n: int | None


def parse_vary(text: str) -> Vary:
    name, eq, spec = text.partition("=")
    name = name.strip()
    parts = spec.split(":")
    if not eq or not name or len(parts) not in (2, 3):
        raise InputError(f"--vary {text!r}: write NAME=LO:HI (sampled) or NAME=LO:HI:N (a grid of N)")
    from ..numbers import parse_number

    lo, hi = (parse_number(f"--vary {name} bound", p) for p in parts[:2])
    n = None
    if len(parts) == 3:
        try:
            n = int(parts[2])
        except ValueError:
            raise InputError(f"--vary {name}: N must be a whole number of points, got {parts[2]!r}") from None
        if not 1 <= n <= MAX_DESIGNS:
            raise InputError(f"--vary {name}: N must be between 1 and {MAX_DESIGNS:,}, got {n}")
        if n == 1 and lo != hi:
            raise InputError(f"--vary {name}: one point needs LO = HI (or use --set)")
    if hi < lo:
        raise InputError(f"--vary {name}: HI ({hi:g}) is below LO ({lo:g})")
    return Vary(name, lo, hi, n)


def check_varies(m: Mechanism, varies: Sequence[Vary]) -> None:
    """Each name a parameter of ``m``, once; both bounds valid values for it."""
    seen: set[str] = set()
    for v in varies:
        if v.name in seen:
            raise InputError(f"--vary {v.name} is given twice")
        seen.add(v.name)
        if v.name not in m.parameters:
            what = ("the driver (use --from/--to)" if v.name == m.driver.name else
                    "an unknown" if v.name in {u.name for u in m.unknowns} else "not a parameter")
            raise InputError(f"--vary {v.name}: {what}; the parameters of {m.source} are "
                             f"{', '.join(m.parameters)}")
        for bound in (v.lo, v.hi):
            try:
                m.with_values({v.name: bound}, {})
            except ParseError as exc:
                raise InputError(f"--vary {v.name}: {str(exc).removeprefix('--set ')}") from None


class DesignPlan:
    """Which designs a scan visits: ``chunk(start, stop)`` gives their parameter values
    (file units) as an array of shape (stop - start, parameters)."""

    def __init__(self, varies: Sequence[Vary], samples: int | None, seed: int, method: str) -> None:
        self.names = tuple(v.name for v in varies)
        self.varies = tuple(varies)
        gridded = [v.n is not None for v in varies]
        if samples is None:
            if not all(gridded):
                missing = next(v.name for v in varies if v.n is None)
                raise InputError(f"--vary {missing}: give :N points for a grid, or --samples N "
                                 "for random designs")
            total = math.prod(v.n for v in varies if v.n is not None) if varies else 1
            self.axes = [np.linspace(v.lo, v.hi, v.n) if v.n and v.n > 1 else np.array([v.lo])
                         for v in varies]
            self.samples = None
        else:
            if any(gridded):
                raise InputError("--samples draws random designs: give --vary NAME=LO:HI without :N")
            if not 1 <= samples <= MAX_DESIGNS:
                raise InputError(f"--samples must be between 1 and {MAX_DESIGNS:,}, got {samples}")
            if method not in ("lhs", "random"):
                raise InputError(f"--sampling must be lhs or random, got {method!r}")
            if samples * len(varies) > MAX_SAMPLE_VALUES:
                raise InputError(f"--samples {samples:,} x {len(varies)} varied parameters is "
                                 f"{samples * len(varies):,} values, more than the "
                                 f"{MAX_SAMPLE_VALUES:,} a scan holds; use fewer samples")
            total = samples
            self.samples = draw_designs(varies, samples, seed, method)
        if total > MAX_DESIGNS:
            raise InputError(f"the grid has {total:,} designs, more than {MAX_DESIGNS:,}; use fewer "
                             "points or --samples")
        self.total = total

    def chunk(self, start: int, stop: int) -> np.ndarray:
        if self.samples is not None:
            return self.samples[start:stop]
        if not self.axes:
            return np.empty((stop - start, 0))
        idx = np.unravel_index(np.arange(start, stop), [len(a) for a in self.axes])
        return np.stack([a[i] for a, i in zip(self.axes, idx)], axis=1)



def draw_designs(varies: Sequence[Vary], n: int, seed: int, method: str) -> np.ndarray:
    rng = np.random.default_rng(seed)
    p = len(varies)
    u = rng.random((n, p))
    if method == "lhs":
        # one draw in each of n equal strata per parameter, strata shuffled independently
        for j in range(p):
            u[:, j] = (rng.permutation(n) + u[:, j]) / n
    lo = np.array([v.lo for v in varies])
    hi = np.array([v.hi for v in varies])
    # in place, the same operations as lo + u * (hi - lo): one array of the designs in memory
    u *= hi - lo
    u += lo
    return u

