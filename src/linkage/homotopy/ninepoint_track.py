"""Tracking the nine-point problem's paths (:mod:`.ninepoint` has its equations and
symmetries): the parameter homotopy from the stored generic instance to the user's points,
segment by segment (Morgan and Sommese, "Coefficient-parameter polynomial continuation",
Appl. Math. Comput. 29, 1989), in chunks of paths that run here or as dask tasks, and the
monodromy loops that made the stored instance (:class:`NinePointLoops`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..records import frozen
from .ninepoint import (
    REFINED,
    RESIDUAL,
    SINGULAR,
    canonical,
    distinct,
    equations,
    is_real,
    load_start,
    owners,
    polish,
    polish_precisely,
    random_points,
    relative_residual,
)

if TYPE_CHECKING:
    from .tracker import PathLog


@frozen
class ParameterSegment:
    """The points moving on a straight line, delta(t) = (1 - t) start + t end, for all
    paths at once; an instance of the homotopy protocol of :func:`.tracker.track`
    (``residual_and_jacobians`` and ``velocity``). Points are projective, (z, w) with z/w
    the unknowns, on the random patch ``patch`` . (z, w) = 1, so that a solution that is
    large at an instance (a nearly degenerate four-bar: pivots far away) stays bounded."""

    d0: np.ndarray  # (8,) delta at t = 0
    db0: np.ndarray
    d1: np.ndarray  # (8,) at t = 1
    db1: np.ndarray
    patch: np.ndarray  # (9,)

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        t = np.asarray(t)[:, None]
        return (1 - t) * self.d0 + t * self.d1, (1 - t) * self.db0 + t * self.db1

    def residual_and_jacobians(self, Z: np.ndarray, t: np.ndarray
                               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        d, db = self.at(t)
        E, J, Ed, Edb = equations(Z[:, :8], d, db, Z[:, 8])
        Ht = Ed * (self.d1 - self.d0) + Edb * (self.db1 - self.db0)
        n = len(Z)
        patch = np.broadcast_to(self.patch, (n, 1, 9))
        return (np.concatenate([E, (Z @ self.patch - 1.0)[:, None]], axis=1),
                np.concatenate([J, patch], axis=1),
                np.concatenate([Ht, np.zeros((n, 1), dtype=complex)], axis=1))

    def velocity(self, Z: np.ndarray, t: np.ndarray, dt: np.ndarray) -> np.ndarray:
        from .tracker import velocity

        return velocity(self, Z, t, dt)


def random_patch(rng: np.random.Generator) -> np.ndarray:
    patch = rng.normal(size=9) + 1j * rng.normal(size=9)
    return patch / np.linalg.norm(patch)


def lift(z: np.ndarray, patch: np.ndarray) -> np.ndarray:
    """Affine solutions (paths, 8) to projective points on the patch."""
    Z = np.concatenate([z, np.ones((len(z), 1), dtype=complex)], axis=1)
    return Z / (Z @ patch)[:, None]


def affine(Z: np.ndarray) -> np.ndarray:
    """Projective points back to affine solutions (inf where w is 0)."""
    with np.errstate(all="ignore"):
        return Z[:, :8] / Z[:, 8:9]


MAX_STEP = 0.05
"""Largest step in t along a parameter segment."""
CORRECTOR_TOL = 1e-9
"""The tracker's corrector tolerance here (relative): the equations are of degree 8 and a
path's Jacobian has a condition number up to about 1e6 along the way, so Newton's method
in double precision stalls near 1e-11 (measured); the endpoints are refined at the end."""


def track_segment(segment: ParameterSegment, Z: np.ndarray, max_step: float = MAX_STEP
                  ) -> tuple[np.ndarray, np.ndarray, PathLog]:
    """Every row of ``Z`` (affine solutions at t = 0) tracked to t = 1 in projective
    coordinates: (affine Z at 1, ok, the log)."""
    from .tracker import PathLog, track

    n = len(Z)
    log = PathLog.empty(n)
    Z1, ok, _ = track(segment, lift(Z, segment.patch), np.zeros(n), np.ones(n), lambda t: t, np.ones_like,
                      log, np.arange(n), np.full(n, max_step / 4.0), max_step, CORRECTOR_TOL)
    z1 = affine(Z1)
    return z1, ok & np.all(np.isfinite(z1), axis=1), log


@frozen
class NinePointLoops:
    """The nine-point problem as :func:`.parameter.monodromy` loops it: the parameters are
    the points, (delta, deltabar) as one vector of 16; a corner of a loop is random complex
    points of unit size, as the stored instance's are; a leg is :func:`track_segment` on its
    own random patch; a root is one solution per orbit of six, in its canonical form
    (:func:`canonical`), polished at the instance (:func:`polish`; one that does not settle
    is dropped), so that an endpoint is new only as a new orbit (:func:`distinct`)."""

    max_step: float = MAX_STEP
    n: int = 8

    def turn(self, p: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.concatenate(random_points(rng))

    def leg(self, a: np.ndarray, b: np.ndarray, roots: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        segment = ParameterSegment(a[:8], a[8:], b[:8], b[8:], random_patch(rng))
        Z, ok, _log = track_segment(segment, roots, self.max_step)
        return Z[ok]

    def settle(self, roots: np.ndarray, p: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            Z, last, _ = polish(roots, p[:8], p[8:])
        return canonical(Z[last <= REFINED])

    def fresh(self, known: np.ndarray, roots: np.ndarray) -> list[int]:
        return [i - len(known) for i in distinct(np.vstack([known, roots])) if i >= len(known)]


@frozen
class NinePointSolutions:
    """The four-bars through nine points, one per orbit (cognates and dyad order), and how
    they were found."""

    points: tuple[complex, ...]  # P_0..P_8
    solutions: np.ndarray  # (orbits found, 8): a, x, b, y, bars; P_0 at the origin
    real: np.ndarray  # (orbits found,) bool
    condition: np.ndarray  # (orbits found,)
    paths: int  # tracked per route (the start instance's orbits)
    routes: int  # straight, then through random complex points, until every orbit is found
    failed: tuple[int, ...]  # per route
    unrefined: tuple[int, ...]  # per route: ended where Newton's method does not settle
    steps: tuple[int, ...]  # per route, total
    seconds: float
    record: PathRecord  # every path of every route (issue 34: every step on show)

    @property
    def missing(self) -> int:
        """Orbits of the start instance whose endpoint no route reached. With a subset of the
        orbits (``solve_points(orbits=k)``, a quick look) a later route, through a random
        instance, can reach four-bars outside the subset, so more can be found than were
        tracked: then none is missing, not a negative count."""
        return max(0, self.paths - len(self.solutions))


OUTCOMES = ("reached", "reached_again", "duplicate", "unsettled", "step_underflow", "too_many_steps",
            "infinite")
"""What a path of a route came to, one class each (:class:`PathRecord` codes them by
position): its endpoint settled at the points as a four-bar no path had reached
(reached), one an earlier route found (reached_again), or one another path of this route
reached first (duplicate: two paths met, a path jumped); or its endpoint did not settle
under Newton's method in double precision nor at PRECISE_DIGITS (unsettled); or the
tracker gave it up: its step size fell below the tracker's MIN_STEP (step_underflow), it
took the tracker's MAX_STEPS (too_many_steps), or its point went to infinity, w = 0 in
projective coordinates (infinite)."""
REACHED, AGAIN, DUPLICATE, UNSETTLED, UNDERFLOW, TOO_MANY_STEPS, INFINITE = range(len(OUTCOMES))


@frozen
class PathRecord:
    """Every path of every route, one entry each, as arrays (routes in order, each route's
    paths in start order): what the tracker counted (summed over the route's legs), what the
    path came to, and which found four-bar it gave."""

    route: np.ndarray  # 1-based
    path: np.ndarray  # the start instance's orbit, 0-based
    steps: np.ndarray  # steps taken, accepted and rejected, over the route's legs
    rejected: np.ndarray  # steps rejected (the step size halved)
    newton: np.ndarray  # corrector iterations (Newton's steps)
    smallest_step: np.ndarray  # smallest accepted step in t (inf: none accepted)
    outcome: np.ndarray  # index into OUTCOMES
    precise: np.ndarray  # settled only at PRECISE_DIGITS (bool)
    leg: np.ndarray  # the leg a path the tracker gave up stopped on, 1-based (0: none)
    four_bar: np.ndarray  # index into NinePointSolutions.solutions (-1: none)

    def counts(self, routes: int) -> np.ndarray:
        """Paths of each outcome class, (routes, len(OUTCOMES)): the summary of the record."""
        out = np.zeros((routes, len(OUTCOMES)), int)
        np.add.at(out, (self.route - 1, self.outcome), 1)
        return out


MAX_ROUTES = 4

@frozen
class Route:
    """One way from the stored instance to the target: its legs (points at each end) and
    each leg's projective patch. A value, so that a chunk of paths can be sent to a worker."""

    legs: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], ...]
    patches: tuple[np.ndarray, ...]
    target: tuple[np.ndarray, np.ndarray]


def track_route(route: Route, first: int, Z: np.ndarray) -> dict[str, np.ndarray]:
    """Paths ``Z`` (start solutions; ``first`` is the index of the first, for the caller's
    order) along every leg of ``route`` (a path the tracker gives up on a leg goes no
    further), polished at the target; endpoints that will not settle in double precision
    polished at PRECISE_DIGITS. A chunk's records, arrays all (cheap to send back from a
    worker): ``z`` (settled endpoints, canonical), ``failed``, ``unsettled``, ``steps``
    (the chunk's counts), and per path, in order, the fields of :class:`PathRecord` but
    route and four_bar, with ``outcome`` REACHED for each settled path and ``row`` its row
    of ``z`` (-1 for the others)."""
    from .tracker import PathLog

    n = len(Z)
    log = PathLog.empty(n)
    outcome = np.full(n, REACHED, np.int8)
    leg_of = np.zeros(n, np.int8)
    live = np.arange(n)
    # paths through near-degenerate points overflow on the way: the tracker judges each
    # path by its own finite checks, so numpy's warnings would only be noise on stderr
    with np.errstate(all="ignore"):
        for k, ((a, ab, b, bb), patch) in enumerate(zip(route.legs, route.patches)):
            Z, ok, leg = track_segment(ParameterSegment(a, ab, b, bb, patch), Z)
            add_log(log, leg, live)
            outcome[live[~ok]] = GIVEN_UP[leg.cause[~ok]]
            leg_of[live[~ok]] = k + 1
            Z, live = Z[ok], live[ok]
        d1, db1 = route.target
        Z, last, cond = polish(Z, d1, db1)
    good = (last <= REFINED) & (cond <= SINGULAR)
    outcome[live[~good]] = UNSETTLED
    row = np.full(n, -1)
    row[live[good]] = np.arange(int(good.sum()))
    precise = np.zeros(n, bool)
    settled = []
    for i in np.flatnonzero(~good):
        z = polish_precisely(Z[i], d1, db1) if np.all(np.isfinite(Z[i])) else None
        if z is not None:
            row[live[i]], outcome[live[i]], precise[live[i]] = int(good.sum()) + len(settled), REACHED, True
            settled.append(z)
    Z = canonical(np.vstack([Z[good], *[z[None, :] for z in settled]]))
    return {"z": Z, "failed": np.array([n - len(live)]), "steps": np.array([int(log.steps.sum())]),
            "unsettled": np.array([int((~good).sum()) - len(settled)]), "path": first + np.arange(n),
            "path_steps": log.steps, "rejected": log.rejected, "newton": log.newton,
            "smallest_step": log.smallest_step, "outcome": outcome, "precise": precise, "leg": leg_of,
            "row": row}


GIVEN_UP = np.array([INFINITE, UNDERFLOW, TOO_MANY_STEPS], np.int8)
"""The outcome of a path a leg did not carry, by the tracker's cause (.tracker.PathLog.cause:
none, so the point went to infinity; UNDERFLOW; TOO_MANY_STEPS)."""


def add_log(total: PathLog, leg: PathLog, rows: np.ndarray) -> None:
    """A leg's log (of paths ``rows`` of ``total``) added to the route's."""
    total.steps[rows] += leg.steps
    total.rejected[rows] += leg.rejected
    total.newton[rows] += leg.newton
    total.smallest_step[rows] = np.minimum(total.smallest_step[rows], leg.smallest_step)


class StartRows:
    """The stored instance's solutions as a plan of chunks (``total``, ``chunk(a, b)``),
    the shape the scan's chunk runner takes."""

    def __init__(self, solutions: np.ndarray) -> None:
        self.solutions = solutions
        self.total = len(solutions)

    def chunk(self, a: int, b: int) -> np.ndarray:
        return self.solutions[a:b]


def _here(task, job, plan, size):  # type: ignore[no-untyped-def]
    """Chunks one after another, in this process (the default runner)."""
    for a in range(0, plan.total, size):
        yield task(job, a, plan.chunk(a, min(a + size, plan.total)))


PATHS = 1442
"""The stored instance's orbits: the paths of a route (WMS 1992's count, 8,652 / 6)."""
CHUNK = 256
"""Paths per task: numpy blocks big enough to amortise the interpreter, small enough that
two workers share Problem 3's 1,442 paths evenly."""


def solve_points(points: list[complex] | tuple[complex, ...], seed: int = 0,
                 max_routes: int = MAX_ROUTES, run=None, orbits: int | None = None,  # type: ignore[no-untyped-def]
                 progress=None, chunk: int = CHUNK) -> NinePointSolutions:  # type: ignore[no-untyped-def]
    """Every four-bar whose coupler point passes through nine points (complex numbers
    x + iy), by parameter homotopy from the stored generic instance (:func:`load_start`).
    The first route is the straight segment; a path that fails, or ends where Newton's
    method does not settle, leaves its endpoint to another route, through a random complex
    instance, which carries every path again (a route permutes the endpoints, so the union
    over routes is what is counted); routes stop when every orbit is found or at
    ``max_routes``. ``run(task, job, plan, size)`` runs the chunks of paths (default: here,
    one after another; the scan's runner sends them to dask). ``orbits``: track only the
    first so many of the stored orbits (a quick look; the counts are then of those).
    ``progress(done, label)``: called as each chunk of paths ends; ``chunk``: paths per
    chunk. Every path's record is kept (:class:`PathRecord`)."""
    import time

    began = time.perf_counter()
    start = load_start()
    rows = start.solutions if orbits is None else start.solutions[:orbits]
    p = np.asarray(points, dtype=complex)
    # the problem is the same at every scale (the pivots scale with the points): solve it
    # for points of size 1, as the stored instance is, and scale the four-bars back
    size = float(np.max(np.abs(p[1:] - p[0])))
    d1 = (p[1:] - p[0]) / size
    db1 = np.conj(d1)
    rng = np.random.default_rng(seed)
    found = np.zeros((0, 8), dtype=complex)
    failed: list[int] = []
    unrefined: list[int] = []
    steps: list[int] = []
    records: list[dict[str, np.ndarray]] = []
    for route in range(max_routes):
        if route == 0:
            legs = ((start.delta, start.deltabar, d1, db1),)
        else:
            m, mb = random_points(rng)
            legs = ((start.delta, start.deltabar, m, mb), (m, mb, d1, db1))
        job = Route(legs, tuple(random_patch(rng) for _ in legs), (d1, db1))
        parts = []
        for part in (run or _here)(track_route, job, StartRows(rows), chunk):
            parts.append(part)
            if progress is not None:
                progress(min(len(parts) * chunk, len(rows)), f"tracking paths, route {route + 1}")
        failed.append(sum(int(c["failed"][0]) for c in parts))
        unrefined.append(sum(int(c["unsettled"][0]) for c in parts))
        steps.append(sum(int(c["steps"][0]) for c in parts))
        found, record = merge_route(route + 1, parts, found)
        records.append(record)
        if len(found) >= len(rows):
            break
    Z = found
    with np.errstate(all="ignore"):
        real = is_real(Z)
        Z[real, 4:] = np.conj(Z[real, :4])
        rough = np.flatnonzero(real | (relative_residual(Z, d1, db1) > RESIDUAL)) if len(Z) else []
        for i in rough:
            better = polish_precisely(Z[i], d1, db1)
            if better is not None:
                Z[i] = better
        real = is_real(Z)
        Z[real, 4:] = np.conj(Z[real, :4])
        _, J, _, _ = equations(Z, d1, db1)
        cond = np.linalg.cond(J) if len(Z) else np.zeros(0)  # at the points' unit size
    Z = Z * size
    return NinePointSolutions(tuple(complex(v) for v in p), Z, real, cond, len(rows),
                              len(failed), tuple(failed), tuple(unrefined), tuple(steps),
                              time.perf_counter() - began,
                              PathRecord(**{k: np.concatenate([r[k] for r in records]) for k in records[0]}))


def merge_route(route: int, parts: list[dict[str, np.ndarray]], found: np.ndarray
                ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A route's chunks (:func:`track_route`) joined: the four-bars found so far and the
    route's new ones (the earlier first, in their order, so that their indices stand), and
    the route's part of the record (:class:`PathRecord`'s fields), each settled path told
    REACHED, AGAIN or DUPLICATE by the first endpoint of its four-bar
    (:func:`.ninepoint.owners`)."""
    both = np.vstack([found, *[c["z"] for c in parts]])
    owner = owners(both)
    kept = np.flatnonzero(owner == np.arange(len(both)))
    number = np.full(len(both), -1)
    number[kept] = np.arange(len(kept))
    offsets = len(found) + np.cumsum([0, *[len(c["z"]) for c in parts[:-1]]])
    row = np.concatenate([np.where(c["row"] >= 0, c["row"] + o, -1) for c, o in zip(parts, offsets)])
    outcome = np.concatenate([c["outcome"] for c in parts])
    settled = row >= 0
    first = owner[row[settled]]
    outcome[settled] = np.where(first < len(found), AGAIN,
                                np.where(first != row[settled], DUPLICATE, REACHED))
    four_bar = np.full(len(row), -1)
    four_bar[settled] = number[first]
    same = {k: np.concatenate([c[k] for c in parts])
            for k in ("path", "rejected", "newton", "smallest_step", "precise", "leg")}
    steps = np.concatenate([c["path_steps"] for c in parts])
    return both[kept], {"route": np.full(len(row), route), "steps": steps, "outcome": outcome,
                        "four_bar": four_bar, **same}
