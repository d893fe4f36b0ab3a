"""Path generation: every four-bar whose coupler point passes through nine points, each
real one checked by the mechanism engine.

The four-bars come from :mod:`linkage.homotopy.ninepoint` (Wampler, Morgan and Sommese
1992). Each real solution is one group of Roberts cognates; each member becomes a
mechanism (a vector loop A-M-N-B, driven by the crank at A, the coupler point P on the
coupler) and is checked as a designer would check it, by moving it:

- ``positions``: at each point's crank angle the loops close and the engine places P on
  the point (to 1e-9 of the linkage's size);
- ``branch`` defect: the points are not all on the circuit through the first one (the
  circuit is followed by arc length through limit positions, :mod:`linkage.kinematics.
  circuits`): the mechanism would have to be taken apart between them;
- ``order`` defect: moving along that circuit, the points are not met in their order
  (either way round);
- ``transmission`` defect: the least transmission angle (folded 0..90, the one rule) over
  the motion from the first point to the last is below ``min_transmission`` (function
  generation's default, 30 deg);
- its Grashof class.

With prescribed timing (five points with the crank's angle at each, :mod:`.timed_path`),
the crank is the input, and two more defects: ``timing``, the crank's turn from the first
point to a point is not the prescribed one; ``grashof``, the crank cannot turn one way
from the first point to the last (a limit position between: motion generation's name).
"""

from __future__ import annotations

import cmath
import math
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import InputError
from ..homotopy import ninepoint, ninepoint_track
from ..records import frozen
from ..units import degrees, radians
from .request import MIN_TRANSMISSION_DEG
from .timed_path import TimedSolutions, check_timed_points, is_timed, timed_four_bars

POINTS = 9
PROBLEM_3 = ((0.25, 0.0), (0.52, 0.1), (0.8, 0.7), (1.2, 1.0), (1.4, 1.3), (1.1, 1.48), (0.7, 1.4),
             (0.2, 1.0), (0.02, 0.4))
"""Wampler, Morgan and Sommese's Problem 3 (J. Mech. Des. 114(1), 1992): nine points (x, y),
1,442 four-bars up to cognates, 64 of them real (docs/path_synthesis.md)."""
ON_POINT = 1e-9
"""A position reaches its point when P is within this of it, relative to the linkage's size."""


@frozen
class PathFourBar:
    """One four-bar through the points, in the plane of the points (first position)."""

    ground_a: complex
    ground_b: complex
    pin_m: complex  # the coupler's pin on the crank at A
    pin_n: complex  # the coupler's pin on the crank at B
    coupler_point: complex  # P, at the first point
    grashof: str
    defects: tuple[str, ...]
    max_point_error: float  # max |P - point| over the points, engine-placed, in lengths
    transmission_min_deg: float
    crank_deg: tuple[float, ...]  # the crank at A's angle at each point
    timing_error_deg: float | None = None
    """Prescribed timing: the largest gap between the crank's turn from the first point to
    another and the prescribed one (deg); None without timing."""

    @property
    def lengths(self) -> tuple[float, float, float, float]:
        """Ground |AB|, crank |AM|, coupler |MN|, rocker |BN|."""
        return (abs(self.ground_b - self.ground_a), abs(self.pin_m - self.ground_a),
                abs(self.pin_n - self.pin_m), abs(self.pin_n - self.ground_b))


@frozen
class PathSynthesis:
    points: tuple[complex, ...]
    designs: tuple[tuple[PathFourBar, ...], ...]  # per real orbit: its three cognates
    found: int  # orbits (complex and real)
    missing: int
    solutions: ninepoint_track.NinePointSolutions
    extra: tuple[int, ...] = ()  # which of the points are extra ones (path_points), not given

    @cached_property
    def certificates(self) -> tuple[tuple[Any, ...], list[tuple[int, int]]]:
        """:func:`real_certificates` of the solutions, computed when first read (tens of
        milliseconds a real four-bar)."""
        return real_certificates(self.solutions)


def real_certificates(solutions: ninepoint_track.NinePointSolutions
                      ) -> tuple[tuple[Any, ...], list[tuple[int, int]]]:
    """Smale's alpha test at each real four-bar (:mod:`linkage.homotopy.ninepoint_alpha`, 50
    digits): the certificates, and the pairs of them not told apart (empty: all distinct)."""
    from ..homotopy.alpha import undistinguished
    from ..homotopy.ninepoint_alpha import certify_rows

    rows = solutions.solutions[solutions.real]
    certs = certify_rows(rows, solutions.points)
    return certs, undistinguished(list(rows), certs)


@frozen
class TimedPathSynthesis:
    """Five points with the crank's angle at each: every four-bar through them with that
    timing (:mod:`.timed_path`), each judged (:func:`judge_four_bar`)."""

    points: tuple[complex, ...]
    crank_deg: tuple[float, ...]
    designs: tuple[PathFourBar, ...]
    """One per four-bar of ``solutions.four_bars``, in its order."""
    groups: tuple[tuple[int, ...], ...]
    """The designs (indices) grouped by Roberts cognates (:func:`cognate_groups`)."""
    solutions: TimedSolutions


def chunk_runner(scheduler: str | None, workers: int | None):  # type: ignore[no-untyped-def]
    """The scan's chunk runner (one home for sending chunks to dask) in the form
    :func:`linkage.homotopy.ninepoint_track.solve_points` calls."""
    from ..scan import run_chunks

    def run(task, job, plan, size):  # type: ignore[no-untyped-def]
        return run_chunks(job, plan, size, scheduler=scheduler, workers=workers, task=task)

    return run


def check_points(points: object) -> list[complex]:
    """Five to nine finite, distinct points (pairs x, y), or InputError naming what is wrong."""
    from .path_points import FEWEST, as_points, check_distinct

    pts = as_points("points", points)
    if not FEWEST <= len(pts) <= POINTS:
        raise InputError(f"path synthesis takes {FEWEST} to {POINTS} points (the four-bar has 9 dimensions "
                         f"of design), got {len(pts)}")
    check_distinct("points", pts, [f"point {k + 1}" for k in range(len(pts))])
    return pts


def mechanism_text(fb: PathFourBar, name: str = "path four-bar",
                   span: tuple[float, float] | None = None) -> str:
    """The four-bar as a mechanism file (loops form): driver theta2 (the crank at A), unknowns
    theta3 (the coupler MN) and theta4 (the rocker BN), the coupler point P; ``span``: the
    driver's range (deg), if any."""
    r1, r2, r3, r4 = fb.lengths
    ground = degrees(cmath.phase(fb.ground_b - fb.ground_a))
    theta2 = degrees(cmath.phase(fb.pin_m - fb.ground_a))
    theta3 = degrees(cmath.phase(fb.pin_n - fb.pin_m))
    theta4 = degrees(cmath.phase(fb.pin_n - fb.ground_b))
    offset = degrees(cmath.phase((fb.coupler_point - fb.pin_m) / (fb.pin_n - fb.pin_m)))
    reach = abs(fb.coupler_point - fb.pin_m)
    span_line = "" if span is None else f"\nrange = [{min(span)!r}, {max(span)!r}]"
    return f"""name = {name!r}
length_unit = "m"
origin = [{fb.ground_a.real!r}, {fb.ground_a.imag!r}]

[parameters]
r1 = {{ value = {r1!r}, unit = "m" }}
r2 = {{ value = {r2!r}, unit = "m" }}
r3 = {{ value = {r3!r}, unit = "m" }}
r4 = {{ value = {r4!r}, unit = "m" }}
theta1 = {{ value = {ground!r}, unit = "deg" }}

[driver]
name = "theta2"
value = {theta2!r}
unit = "deg"{span_line}

[unknowns]
theta3 = {{ guess = {theta3!r}, unit = "deg" }}
theta4 = {{ guess = {theta4!r}, unit = "deg" }}

[[loops]]
name = "A-M-N-B"
joints = ["A", "M", "N", "B"]
vectors = [
  {{ length = "r2", angle = "theta2" }},
  {{ length = "r3", angle = "theta3" }},
  {{ length = "r4", angle = "theta4", sign = -1 }},
  {{ length = "r1", angle = "theta1", sign = -1 }},
]

[points.P]
from = "M"
vectors = [ {{ length = {reach!r}, angle = "theta3", offset = {offset!r} }} ]
"""


def _positions(z: np.ndarray, points: list[complex]) -> list[tuple[float, float, float]]:
    """(crank angle at A, coupler angle, rocker angle) in radians at each point, from the
    solution's rotations: M_j = P_j + Theta_j x, N_j = P_j + Theta_j y."""
    d = np.array(points[1:]) - points[0]
    theta, _ = ninepoint.rotations(z[None, :], d, np.conj(d))
    rot = [1.0 + 0j, *theta[0]]
    a, x, b, y = (z[k] for k in (ninepoint.A, ninepoint.X, ninepoint.B, ninepoint.Y))
    out = []
    for p, r in zip(points, rot):
        r = r / abs(r)
        m, n = p + r * x, p + r * y
        A, B = points[0] + a, points[0] + b
        out.append((cmath.phase(m - A), cmath.phase(n - m), cmath.phase(n - B)))
    return out


def _transmission(t3: float, t4: float) -> float:
    """The folded transmission angle (deg) of a configuration: the one rule
    (problems.steps.folded_transmission) on theta4 - theta3 taken into [0, 180)."""
    from ..problems.steps import folded_transmission

    return folded_transmission(degrees(t4 - t3) % 360.0 % 180.0)


def _along(circ, at: list[int]) -> list[int]:  # type: ignore[no-untyped-def]
    """The traced samples (indices) from the first point's arc position to the last's, the
    way round that meets the points in order."""
    n = len(circ.configurations)
    forward = [(k - at[0]) % n for k in at]
    step = 1 if forward == sorted(forward) else -1
    span = ((at[-1] - at[0]) * step) % n
    return [(at[0] + step * i) % n for i in range(span + 1)]


def one_way(angles: list[float]) -> bool:
    """Whether an angle (rad, sampled along a motion) turns one way only: no limit position
    of that link on the way (a reversal beyond rounding)."""
    turns = np.diff(np.unwrap(np.asarray(angles, dtype=float)))
    return bool(np.all(turns >= -1e-9) or np.all(turns <= 1e-9))


def judge(z: np.ndarray, points: list[complex],
          min_transmission: float = MIN_TRANSMISSION_DEG) -> PathFourBar:
    """One real nine-point solution as a four-bar, moved through the points by the engine
    (:func:`judge_four_bar`)."""
    a, x, b, y = (complex(z[k]) for k in (ninepoint.A, ninepoint.X, ninepoint.B, ninepoint.Y))
    P0 = points[0]
    return judge_four_bar((P0 + a, P0 + b, P0 + x, P0 + y), _positions(z, points), points, min_transmission)


def judge_four_bar(pivots: tuple[complex, complex, complex, complex],
                   poses: list[tuple[float, float, float]], points: list[complex],
                   min_transmission: float = MIN_TRANSMISSION_DEG,
                   crank_deg: tuple[float, ...] | None = None) -> PathFourBar:
    """A four-bar (ground pivots A, B, moving pivots M, N at the first point; P the first
    point) moved through the points by the engine, from ``poses``: its (crank, coupler,
    rocker) angles in radians at each point. Its least transmission angle is taken over
    the motion from the first point to the last (on the circuit, in order), or at the
    points where that motion does not exist; below ``min_transmission`` (deg) it is a
    ``transmission`` defect. With ``crank_deg`` (prescribed crank angles, deg), the crank is
    the input: a crank that turns from the first point to another by other than the
    prescribed difference (beyond :data:`ON_POINT` rad) is a ``timing`` defect, and one that
    cannot turn one way from the first point to the last (a limit position of the crank
    between them) a ``grashof`` defect, motion generation's name."""
    from ..kinematics.assemblies import assemblies, same_configuration
    from ..kinematics.circuits import circuits
    from ..kinematics.loading import from_text
    from ..kinematics.rates import place
    from ..problems.closed_form import grashof

    P0 = complex(points[0])
    fb = PathFourBar(*(complex(p) for p in pivots), P0, "", (), math.inf, math.nan, ())
    m = from_text(mechanism_text(fb), "<path synthesis>")
    size = m.length_scale
    errors, trans = [], []
    for (phi, t3, t4), p in zip(poses, points):
        q = [t3, t4]
        F, _ = m.model.functions(phi)
        placed = place(m.model, q, phi)["P"][0]
        closes = max(abs(v) for v in F(q)) <= ON_POINT * size
        errors.append(abs(placed - p) if closes else math.inf)
        trans.append(_transmission(t3, t4))
    defects: list[str] = []
    start = assemblies(m, poses[0][0])
    first = next((i for i, s in enumerate(start.real)
                  if same_configuration(list(poses[0][1:]), s.q, m, 1e-7)), None)
    if first is None:
        defects.append("branch")
    else:
        traced = circuits(m, found=start)
        circ = traced.circuits[traced.circuit_of(first)]
        at = [_arc_index(circ, phi, (t3, t4)) for phi, t3, t4 in poses]
        if any(k is None for k in at):
            defects.append("branch")
        elif not _in_order([k for k in at if k is not None], len(circ.drivers)):
            defects.append("order")
        else:
            path = _along(circ, at)
            trans += [_transmission(circ.configurations[i][0], circ.configurations[i][1]) for i in path]
            if crank_deg is not None and not one_way([circ.drivers[i] for i in path]):
                defects.append("grashof")
    max_error = max(errors) / size
    if max_error > ON_POINT:
        defects.append("positions")
    if min(trans) < min_transmission:
        defects.append("transmission")
    timing = None if crank_deg is None else timing_error_deg([p[0] for p in poses], crank_deg)
    if timing is not None and not radians(timing) <= ON_POINT:
        defects.append("timing")
    return PathFourBar(fb.ground_a, fb.ground_b, fb.pin_m, fb.pin_n, P0, grashof(*fb.lengths),
                       tuple(defects), max(errors), min(trans), tuple(degrees(p[0]) for p in poses), timing)


def timing_error_deg(crank_rad: list[float], crank_deg: tuple[float, ...]) -> float:
    """The largest gap (deg) between the crank's turn from the first point to each other,
    ``crank_rad`` (its angles, rad), and the prescribed turn (``crank_deg``, its prescribed
    angles in deg: only their differences count), modulo a turn."""
    return max(degrees(abs(math.remainder(phi - crank_rad[0] - radians(c - crank_deg[0]), 2 * math.pi)))
               for phi, c in zip(crank_rad, crank_deg))


def _arc_index(circ, phi: float, q: tuple[float, float]) -> int | None:
    """Where along the traced circuit the configuration (phi, q) lies: the nearest traced
    sample, accepted when it is within two arc steps (angles compared modulo a turn)."""
    best, where = math.inf, None
    for k, (d, c) in enumerate(zip(circ.drivers, circ.configurations)):
        gap = max(abs(math.remainder(d - phi, 2 * math.pi)),
                  *(abs(math.remainder(u - v, 2 * math.pi)) for u, v in zip(c, q)))
        if gap < best:
            best, where = gap, k
    return where if best <= 0.1 else None


def _in_order(at: list[int], n: int) -> bool:
    """Whether arc positions increase, or decrease, around the circuit (of ``n`` samples)
    from the first point's."""
    forward = [(k - at[0]) % n for k in at]
    backward = [(at[0] - k) % n for k in at]
    return forward == sorted(forward) or backward == sorted(backward)


def path_options(seed: object, min_transmission: object, workers: object, scheduler: object,
                 orbits: object) -> tuple[int, float, int | None, int | None]:
    """The options of a path synthesis checked: (seed, min_transmission, workers, orbits)."""
    from ..arguments import MAX_SEED, check_number, check_whole, check_workers

    seed = check_whole("seed", seed, 0, MAX_SEED)
    floor = check_number("min_transmission", min_transmission)
    if not 0.0 <= floor <= 90.0:
        raise InputError(f"min_transmission must be from 0 to 90 deg, got {floor:g}")
    workers = check_workers("workers", workers, scheduler)
    if scheduler is not None and not isinstance(scheduler, str):
        raise InputError("scheduler must be threads, processes, synchronous or tcp://HOST:PORT, "
                         f"got {scheduler!r}")
    if orbits is not None:
        orbits = check_whole("orbits", orbits, 1, ninepoint_track.PATHS)
    return seed, floor, workers, orbits  # type: ignore[return-value]


def synthesize_path(points: object, via: object = None, seed: int = 0, scheduler: str | None = None,
                    workers: int | None = None,
                    min_transmission: float = MIN_TRANSMISSION_DEG,
                    progress=None, orbits: int | None = None,
                    ) -> PathSynthesis | TimedPathSynthesis:  # type: ignore[no-untyped-def]
    """Every four-bar whose coupler point passes through nine points; the real ones judged
    by moving them (module docstring). ``points``: five to nine (x, y) pairs, in the order
    the coupler point is to meet them; or five (x, y, crank angle in deg) for prescribed
    timing (:func:`synthesize_timed_path`, which takes ``seed`` and ``min_transmission``).
    Fewer than nine untimed points are made nine by extra points between them
    (:mod:`.path_points`): ``via``, 9 - n pairs, or else the curve's evenly spaced ones.
    The paths are tracked in chunks by the scan's runner: here, on dask's local
    threads or processes, or on a cluster (``scheduler`` tcp://HOST:PORT), ``workers`` at a
    time. ``progress(done, label)`` is told how far it is, out of the paths of a route.
    ``orbits``: track only the first so many of the stored instance's orbits (a quick look,
    :func:`linkage.homotopy.ninepoint_track.solve_points`)."""
    from .path_points import check_via, nine_points

    if is_timed(points):
        options = (("via", via), ("scheduler", scheduler), ("workers", workers), ("orbits", orbits))
        given = [k for k, v in options if v is not None]
        if given:
            raise InputError(f"{', '.join(given)}: for untimed points' path tracking; five timed points "
                             "are two Burmester problems, solved here")
        return synthesize_timed_path(points, seed, min_transmission)
    pts = check_points(points)
    extra = check_via(via, pts)
    seed, floor, workers, orbits = path_options(seed, min_transmission, workers, scheduler, orbits)
    nine = nine_points(pts, extra, seed, 0)
    run = chunk_runner(scheduler, workers)
    return solve_nine(nine.points, nine.extra, seed, run, floor, progress, orbits)


CIRCUIT_DEFECTS = ("branch", "order")
"""Defects of the motion, which a design's three cognates share: their motions correspond
one to one (Roberts-Chebyshev: one coupler curve, traced by all three together)."""


def solve_nine(points: tuple[complex, ...], extra: tuple[int, ...], seed: int, run, floor: float,  # type: ignore[no-untyped-def]
               progress=None, orbits: int | None = None, every_cognate: bool = True) -> PathSynthesis:
    """The four-bars through nine checked points (``extra`` of them not the user's), each
    real one and its cognates judged: :func:`synthesize_path` after its checks. Without
    ``every_cognate`` (a search, which keeps only defect-free designs), a design whose first
    cognate has a defect of CIRCUIT_DEFECTS is that cognate alone."""
    pts = list(points)
    sols = ninepoint_track.solve_points(pts, seed=seed, run=run, progress=progress, orbits=orbits)
    designs = []
    reals = np.flatnonzero(sols.real)
    for k, i in enumerate(reals):
        members = ninepoint.orbit(sols.solutions[i])[:3]
        first = judge(members[0], pts, floor)
        shared = not every_cognate and set(first.defects) & set(CIRCUIT_DEFECTS)
        designs.append((first,) if shared else (first, *(judge(mz, pts, floor) for mz in members[1:])))
        if progress is not None:
            progress(sols.paths * (k + 1) // len(reals), "moving the real four-bars")
    return PathSynthesis(tuple(pts), tuple(designs), len(sols.solutions), sols.missing, sols, extra)


def synthesize_timed_path(points: object, seed: int = 0,
                          min_transmission: float = MIN_TRANSMISSION_DEG) -> TimedPathSynthesis:
    """Every four-bar whose coupler point passes through five points (x, y, crank angle in
    deg) with the crank at those angles (only their differences count: the crank's angle at
    the first point is the design's own), each moved through the points by the engine and
    judged (:func:`judge_four_bar`, with a ``timing`` defect). Other counts of timed points,
    points with and without angles mixed, NaN or coincident points: InputError."""
    check_timed_points(points)  # before the options: a wrong count is the first thing said
    seed, floor, _, _ = path_options(seed, min_transmission, None, None, None)
    found = timed_four_bars(points, seed=seed)
    designs = tuple(judge_four_bar(fb.pivots, list(fb.configurations), list(found.points), floor,
                                   found.crank_deg) for fb in found.four_bars)
    return TimedPathSynthesis(found.points, found.crank_deg, designs, cognate_groups(designs), found)


COGNATE = 1e-7
"""Two four-bars are cognates when one's pivots are within this (of their size) of a member
of the other's orbit."""


def cognate_groups(designs: tuple[PathFourBar, ...]) -> tuple[tuple[int, ...], ...]:
    """Four-bars through the same points grouped by Roberts cognates: one is a member of the
    other's nine-point orbit (ninepoint.orbit: its three cognates, each with the dyads
    either way round)."""
    groups: list[list[int]] = []
    for i, fb in enumerate(designs):
        z = orbit_unknowns(fb)
        size = float(np.abs(z).max())
        mates = ninepoint.orbit(z)
        for g in groups:
            if np.abs(mates - orbit_unknowns(designs[g[0]])).max(axis=1).min() <= COGNATE * size:
                g.append(i)
                break
        else:
            groups.append([i])
    return tuple(tuple(g) for g in groups)


def orbit_unknowns(fb: PathFourBar) -> np.ndarray:
    """The four-bar as the nine-point unknowns (isotropic, relative to its first point P)."""
    z = np.zeros(8, dtype=complex)
    for k, v in ((ninepoint.A, fb.ground_a), (ninepoint.X, fb.pin_m), (ninepoint.B, fb.ground_b),
                 (ninepoint.Y, fb.pin_n)):
        z[k] = v - fb.coupler_point
    bars = [ninepoint.AB, ninepoint.XB, ninepoint.BB, ninepoint.YB]
    z[bars] = np.conj(z[[ninepoint.A, ninepoint.X, ninepoint.B, ninepoint.Y]])
    return z


def coupler_curve(fb: PathFourBar) -> np.ndarray:
    """P (complex) along the circuit through the four-bar's first position, as the engine
    traces it (:mod:`linkage.kinematics.circuits`): the coupler curve a design's figure draws."""
    from ..kinematics.assemblies import assemblies, same_configuration
    from ..kinematics.circuits import circuits
    from ..kinematics.loading import from_text
    from ..kinematics.rates import place

    m = from_text(mechanism_text(fb), "<coupler curve>")
    start = assemblies(m)
    first = next(i for i, s in enumerate(start.real)
                 if same_configuration([m.unknowns[0].value, m.unknowns[1].value], s.q, m, 1e-6))
    traced = circuits(m, found=start)
    circ = traced.circuits[traced.circuit_of(first)]
    return np.array([place(m.model, list(q), d)["P"][0] for d, q in zip(circ.drivers, circ.configurations)])
