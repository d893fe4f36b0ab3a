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
from dataclasses import dataclass
from typing import Any

from ..errors import InputError
from ..units import degrees, radians
from .burmester import Burmester, Crank, Pose, burmester_points
from .defects import Defect
from .request import MIN_TRANSMISSION_DEG

POSE_TOL = 1e-9
"""A body within this (of the poses' size, and in radians) of a pose is at the pose."""
STEP_DEG = 1.0
"""The sweep's largest input step between poses."""


@dataclass(frozen=True)
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


@dataclass(frozen=True)
class MotionSynthesis:
    """Every Burmester crank through the poses and every four-bar from two of them."""

    poses: tuple[Pose, ...]
    burmester: Burmester
    designs: tuple[MotionDesign, ...]
    min_transmission_deg: float


def synthesize_motion(poses: Sequence[Pose | Sequence[float]], *,
                      min_transmission: float = MIN_TRANSMISSION_DEG, seed: int = 0) -> MotionSynthesis:
    """Four-bars that carry a body through five ``poses`` ((x, y, angle in deg), in order):
    Burmester's cranks by homotopy continuation, then every pair, each swept through the
    poses and judged. Bad input (not five poses, coincident ones, NaN or huge values) is an
    InputError."""
    from ..arguments import check_number

    if isinstance(poses, Sequence) and not isinstance(poses, (str, bytes)) and len(poses) != 5:
        raise InputError(f"motion synthesis takes exactly 5 poses (Burmester's points), got {len(poses)}; "
                         "3 and 4 poses are not supported yet")
    floor = check_number("min_transmission", min_transmission)
    if not 0.0 <= floor <= 90.0:
        raise InputError(f"min_transmission must be from 0 to 90 deg, got {floor:g}")
    found = burmester_points(poses, seed=seed)
    if len(found.cranks) < 2:
        return MotionSynthesis(found.poses, found, (), floor)
    designs = [
        judge_pair(found.poses, (i, j), found.cranks[i], found.cranks[j], floor)
        for i in range(len(found.cranks)) for j in range(len(found.cranks)) if i != j
    ]
    return MotionSynthesis(found.poses, found, tuple(designs), floor)


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
    from ..problems.joints import toml_value

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
    from ..kinematics.sweep import sweep_mechanism
    from ..problems.closed_form import transmission
    from ..problems.loops import from_text

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
