"""Motion generation through five poses: every four-bar made of two Burmester cranks
(:mod:`.burmester`), each checked by sweeping it with the kinematics engine from the first
pose through the others (docs/motion_synthesis.md).

A design's input is one crank (ground pivot O2, moving pivot A), its output the other (O4,
B), its coupler the body (A and B fixed in it). The sweep starts at pose 1 on the assembly
drawn there and turns the input, in the direction that meets the other poses soonest, to
each pose's input angle; the body it carries there is compared with the pose. The defects
have function generation's names (docs/synthesis.md): ``branch`` (the body at a pose's input
angle is not the pose: that pose is on the other assembly), ``grashof`` (the input cannot
turn from pose 1 to every pose: a limit position between), ``order`` (the poses are not met
in the order given, in either direction), ``transmission`` (the transmission angle falls
below the floor on the way) and ``no_linkage`` (two cranks that do not make a four-bar: a
link of zero length).
"""

from __future__ import annotations

import cmath
import itertools
import math
from collections.abc import Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import degrees, radians
from .burmester import POSE_TOL, Burmester, Crank, Pose, burmester_points, checked_poses
from .defects import Defect
from .motion_curves import Curves, four_pose_curves
from .request import MIN_TRANSMISSION_DEG

STEP_DEG = 1.0
"""The sweep's largest input step between poses."""


@frozen
class MotionDesign:
    """A four-bar from Burmester cranks ``cranks`` (input, output), drawn at pose 1."""

    cranks: tuple[int, int]
    joints: dict[str, tuple[float, float]]
    """O2, A, B, O4 at pose 1 (the poses' length unit)."""
    links: dict[str, float]
    grashof: str
    input_deg: tuple[float, ...]
    """The input's angle O2 -> A at each pose (deg, from +x)."""
    direction: int
    """+1: the input turns anticlockwise from pose 1 to the others, -1 clockwise."""
    pose_error: tuple[float | None, ...]
    """At each pose: the swept body's distance from it (position, in the poses' size, and
    angle in rad, the larger); None where the sweep does not reach it."""
    min_transmission_deg: float | None
    defects: tuple[Defect, ...]

    @property
    def defect_names(self) -> list[str]:
        return [d.name for d in self.defects]


@frozen
class MotionSynthesis:
    """The cranks through the poses (every Burmester crank for five poses, the two chosen
    for three) and every four-bar from two of them."""

    poses: tuple[Pose, ...]
    burmester: Burmester | None
    """Five poses: the continuation's account (paths by class); None for three."""
    cranks: tuple[Crank, ...]
    designs: tuple[MotionDesign, ...]
    min_transmission_deg: float
    curves: Curves | None = None
    """Four poses: the centre-point and circle-point curves (no cranks chosen, no designs)."""


THREE_FREE = ("three poses fix a four-bar only once both moving pivots are chosen: 4 free numbers, the "
              "two circle points at pose 1 (the centre points are then the centres of the circles "
              "through each circle point's three positions)")
"""What is free with three poses (Sandor and Erdman vol. 2, ch. 3: the three-position problem)."""


def synthesize_motion(poses: Sequence[Pose | Sequence[float]], *, circle_points: Any = None,
                      min_transmission: float = MIN_TRANSMISSION_DEG, seed: int = 0) -> MotionSynthesis:
    """Four-bars that carry a body through ``poses`` ((x, y, angle in deg), in order), each
    swept through the poses and judged. Five poses: Burmester's cranks by homotopy
    continuation, and every pair. Four poses: the centre-point and circle-point curves
    (:mod:`.motion_curves`; one number along them is free for each crank). Three poses: the
    family's free choice, the two moving pivots at pose 1 (``circle_points``, two (x, y)),
    fixes the cranks (:data:`THREE_FREE`).
    Bad input (another number of poses, coincident ones, NaN or huge values) is an
    InputError."""
    from ..arguments import check_number

    count = len(poses) if isinstance(poses, Sequence) and not isinstance(poses, (str, bytes)) else 5
    if count not in (3, 4, 5):
        raise InputError(f"motion synthesis takes 3 poses (with two circle points), 4 (the centre-point "
                         f"curve) or 5 (Burmester's points), got {count}")
    floor = check_number("min_transmission", min_transmission)
    if not 0.0 <= floor <= 90.0:
        raise InputError(f"min_transmission must be from 0 to 90 deg, got {floor:g}")
    if count == 4:
        if circle_points is not None:
            raise InputError("circle_points are the free choice of three poses: with four, each crank's "
                             "is a point of the circle-point curve")
        ps = checked_poses(poses, 4)
        return MotionSynthesis(ps, None, (), (), floor, four_pose_curves(ps))
    if count == 3:
        ps = checked_poses(poses, 3)
        cranks = tuple(three_pose_crank(ps, w, k) for k, w in enumerate(checked_circle_points(circle_points)))
        found = None
    else:
        if circle_points is not None:
            raise InputError("circle_points are the free choice of three poses: five poses fix them")
        found = burmester_points(poses, seed=seed)
        ps, cranks = found.poses, found.cranks
    designs = [judge_pair(ps, (i, j), cranks[i], cranks[j], floor)
               for i in range(len(cranks)) for j in range(len(cranks)) if i != j]
    return MotionSynthesis(ps, found, cranks, tuple(designs), floor)


def checked_circle_points(points: Any) -> list[complex]:
    """Two moving pivots (x, y) at pose 1, finite and apart."""
    from ..arguments import check_number

    if points is None:
        raise InputError(THREE_FREE + ": give them (circle_points, or --circle X,Y twice)")
    if isinstance(points, (str, bytes)) or not isinstance(points, Sequence) or len(points) != 2:
        raise InputError(f"circle_points: give two points (x, y), got {points!r}")
    out = []
    for k, w in enumerate(points):
        if isinstance(w, (str, bytes)) or not isinstance(w, Sequence) or len(w) != 2:
            raise InputError(f"circle_points[{k}] must be (x, y), got {w!r}")
        x, y = (check_number(f"circle_points[{k}]", v) for v in w)
        if not max(abs(x), abs(y)) < 1e12:
            raise InputError(f"circle_points[{k}] must be finite numbers below 1e12 in size, got {w!r}")
        out.append(complex(x, y))
    if out[0] == out[1]:
        raise InputError("circle_points: the two moving pivots must differ")
    return out


def three_pose_crank(poses: Sequence[Pose], w: complex, k: int) -> Crank:
    """The crank of circle point ``w`` (at pose 1): its centre is the centre of the circle
    through its three positions; an InputError where they lie on a line (no finite centre)."""
    z = (w - complex(poses[0].x, poses[0].y)) * cmath.exp(-1j * radians(poses[0].angle_deg))
    m1, m2, m3 = (at_pose(p, (z.real, z.imag)) for p in poses)
    u, v = m2 - m1, m3 - m1
    cross = u.real * v.imag - u.imag * v.real
    if abs(cross) <= 1e-12 * max(abs(u), abs(v)) ** 2:
        raise InputError(f"circle_points[{k}]: its three positions lie on a line (no finite centre: that "
                         "point moves on a straight line, not a circle); choose another")
    g = m1 - 1j * (abs(u) ** 2 * v - abs(v) ** 2 * u) / (2 * cross)
    lengths = [abs(m - g) for m in (m1, m2, m3)]
    residual = (max(lengths) - min(lengths)) / size_of(poses)
    return Crank((g.real, g.imag), (z.real, z.imag), (w.real, w.imag), lengths[0], residual, math.nan)


def size_of(poses: Sequence[Pose]) -> float:
    """The poses' size: the largest distance from their centre (1 if they share a point)."""
    centre = sum(complex(p.x, p.y) for p in poses) / len(poses)
    return max(abs(complex(p.x, p.y) - centre) for p in poses) or 1.0


def at_pose(p: Pose, z: tuple[float, float]) -> complex:
    """Where body point z (the body's frame) is at pose p."""
    return complex(p.x, p.y) + cmath.exp(1j * radians(p.angle_deg)) * complex(*z)


def pose_order(angles: Sequence[float]) -> tuple[int, list[float], bool]:
    """The direction (+1/-1) from the first angle that meets the others soonest in order, the
    input's travel to each pose that way (deg, from 0), and whether they come in order."""
    best = None
    for s in (1, -1):
        travel = [0.0] + [(s * (a - angles[0])) % 360.0 for a in angles[1:]]
        ordered = all(u < v for u, v in itertools.pairwise(travel))
        key = (not ordered, travel[-1])
        if best is None or key < best[0]:
            best = (key, s, travel, ordered)
    assert best is not None
    return best[1], best[2], best[3]


def mechanism_text(joints: dict[str, tuple[float, float]], value: float, span: tuple[float, float],
                   name: str = "motion generator", unit: str = "mm") -> str:
    """The four-bar in the joints form (docs/mechanisms.md): the driver the input crank."""
    from ..problems.toml_text import toml_value

    rows = [f"name = {toml_value(name)}", f"length_unit = {toml_value(unit)}", 'ground = ["O2", "O4"]', "",
            "[joints]"]
    rows += [f"{k} = {toml_value([float(v[0]), float(v[1])])}" for k, v in joints.items()]
    rows += ["", "[links]", 'crank = ["O2", "A"]', 'coupler = ["A", "B"]', 'rocker = ["O4", "B"]', "",
             "[driver]", 'link = "crank"', f"value = {toml_value(value)}",
             f"range = {toml_value([min(span), max(span)])}"]
    return "\n".join(rows) + "\n"


def judge_pair(poses: Sequence[Pose], pair: tuple[int, int], inp: Crank, out: Crank,
               floor: float) -> MotionDesign:
    """One four-bar (input crank ``inp``, output ``out``) swept through the poses and judged."""
    from ..problems.closed_form import grashof

    size = size_of(poses)
    o2, o4 = complex(*inp.ground), complex(*out.ground)
    a1, b1 = at_pose(poses[0], inp.body), at_pose(poses[0], out.body)
    joints = {"O2": (o2.real, o2.imag), "A": (a1.real, a1.imag), "B": (b1.real, b1.imag),
              "O4": (o4.real, o4.imag)}
    links = {"input": abs(a1 - o2), "coupler": abs(b1 - a1), "output": abs(b1 - o4), "ground": abs(o4 - o2)}
    angles = [degrees(cmath.phase(at_pose(p, inp.body) - o2)) for p in poses]
    base = dict(cranks=pair, joints=joints, links=links, input_deg=tuple(angles))
    if min(links.values()) <= 1e-9 * size:
        short = min(links, key=lambda k: links[k])
        return MotionDesign(**base, grashof="", direction=1, pose_error=(None,) * len(poses),  # type: ignore[arg-type]
                            min_transmission_deg=None,
                            defects=(Defect("no_linkage", f"no_linkage: the {short} link has no length"),))
    s, travel, ordered = pose_order(angles)
    errors, mu = sweep_poses(poses, joints, inp.body, out.body, angles[0], s, travel, size)
    defects = motion_defects(errors, travel, ordered, mu, floor)
    kind = grashof(links["ground"], links["input"], links["coupler"], links["output"])
    return MotionDesign(**base, grashof=kind, direction=s, pose_error=tuple(errors),  # type: ignore[arg-type]
                        min_transmission_deg=mu, defects=tuple(defects))


def sweep_poses(poses: Sequence[Pose], joints: dict[str, tuple[float, float]], za: tuple[float, float],
                zb: tuple[float, float], start: float, s: int, travel: Sequence[float],
                size: float) -> tuple[list[float | None], float | None]:
    """The body's distance from each pose where the engine's sweep (linkage.sweep, joints on)
    reaches its input angle from pose 1, and the least transmission angle on the way (deg,
    folded; closed_form.transmission). The sweep stops at the first position it cannot solve."""
    from ..kinematics.loading import from_text
    from ..kinematics.sweep import sweep_mechanism
    from ..problems.closed_form import transmission

    steps = sorted({0.0, *travel} | {k * STEP_DEG for k in range(1, int(travel[-1] / STEP_DEG) + 1)})
    values = [start + s * u for u in steps]
    mech = from_text(mechanism_text(joints, start, (values[0], values[-1])), "<motion design>")
    result = sweep_mechanism(mech, values, joints=True)
    reached: dict[float, tuple[complex, complex]] = {}
    mus = []
    for u, pos in zip(steps, result.positions):
        if pos.status != "converged" or pos.rates is None:
            break
        j = pos.rates.joints
        a, b, o4 = complex(*j["A"]), complex(*j["B"]), complex(*j["O4"])
        reached[u] = (a, b)
        mus.append(transmission(degrees(cmath.phase(b - a)), degrees(cmath.phase(b - o4))))
    errors: list[float | None] = []
    body = complex(*zb) - complex(*za)
    for p, u in zip(poses, travel):
        if u not in reached:
            errors.append(None)
            continue
        a, b = reached[u]
        turn = cmath.phase((b - a) / body)  # the body's angle, from its frame
        origin = a - cmath.exp(1j * turn) * complex(*za)
        off = abs(origin - complex(p.x, p.y)) / size
        errors.append(max(off, abs(math.remainder(turn - radians(p.angle_deg), 2 * math.pi))))
    return errors, (min(mus) if mus else None)


def motion_defects(errors: Sequence[float | None], travel: Sequence[float], ordered: bool,
                   mu: float | None, floor: float) -> list[Defect]:
    """The design's defects, function generation's names (:data:`.defects.DEFECTS`)."""
    out = []
    missed = [k + 1 for k, e in enumerate(errors) if e is not None and e > POSE_TOL]
    if missed:
        out.append(Defect("branch", f"branch: at pose {', '.join(map(str, missed))} the linkage's body is "
                          "not at the pose: the pose is on the other assembly than pose 1's"))
    unreached = [k + 1 for k, e in enumerate(errors) if e is None]
    if unreached:
        out.append(Defect("grashof", "grashof: the input cannot turn from pose 1 to pose "
                          f"{unreached[0]} on one assembly: a limit position lies between"))
    if not ordered:
        out.append(Defect("order", "order: turning the input either way from pose 1 meets the poses out "
                          "of the order given"))
    if mu is not None and mu < floor:
        out.append(Defect("transmission", f"transmission: the transmission angle falls to {mu:.4g} deg "
                          f"on the way, below {floor:g} deg"))
    return out


def pose_list(values: Any) -> list[tuple[float, float, float]]:
    """Poses as given on the command line: ``x,y,deg`` strings, each checked."""
    from ..numbers import parse_number

    out = []
    for k, text in enumerate(values):
        parts = str(text).split(",")
        if len(parts) != 3:
            raise InputError(f"--pose {text!r}: write X,Y,DEG")
        x, y, a = (parse_number(f"--pose {k + 1}", v) for v in parts)
        out.append((x, y, a))
    return out
