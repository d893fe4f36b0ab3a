"""Instant centres of a one-degree-of-freedom planar mechanism at one pose, and the
centrodes of a body over a sweep (docs/centres.md).

Every centre is a point of the projective plane, h = (X, Y, W) in the mechanism's own
frame (lengths measured from the centre of its joints and divided by its size): the
finite point (X/W, Y/W), or where W = 0 the point at infinity in the direction (X, Y).
The line through two points and the meeting point of two lines are cross products, so
Kennedy's theorem needs no special case for a slider's centre at infinity or for parallel
lines (Hartley and Zisserman, Multiple View Geometry, ch. 2). Three ways to a centre:

- primary: a pin shared by two bodies is their centre; a slider's centre relative to the
  body its line is fixed to is at infinity, perpendicular to the line;
- Kennedy (Aronhold-Kennedy): the three centres of any three bodies lie on one line, so
  I_ij is where the line I_ik I_kj meets the line I_im I_mj (Norton, Design of Machinery,
  sec. 6.3; Uicker, Pennock and Shigley, Theory of Machines and Mechanisms, sec. 3.16);
- velocity: where the two bodies' relative velocity vanishes (:func:`velocity_centre`),
  from each body's angular velocity and one point's velocity, by the rates engine
  (:mod:`.rates`) at a unit driver speed.

Every centre is then checked against the velocities: about I_ij, every joint of bodies i
and j moves relative to the other body as omega_ij x r (:func:`velocity_residual`), to
``CHECK_RTOL`` of the mechanism's fastest motion.

A loops-form mechanism has no bodies of its own: it is drawn as joints and links at the
pose first, as ``linkage convert --form joints`` draws it (:mod:`..problems.to_joints`),
and its bodies are named as that command names them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import degrees, radians

H = tuple[float, float, float]
"""A homogeneous point or line in the mechanism's frame."""

INFINITY_RTOL = 1e-12
"""A centre is at infinity where |W| <= INFINITY_RTOL * hypot(X, Y) (:func:`is_at_infinity`):
beyond 1e12 times the mechanism's size, where a computed W that is exactly 0 lands after
rounding (1e-16 of the others), and where no drawing can tell a point from one at infinity."""

DISTINCT = 1e-9
"""Two centres (or two lines) closer than this, as unit homogeneous vectors (the sine of
the angle between them), are one: no line through them, no point where they meet."""

MOTION_RTOL = 1e-12
"""Two bodies whose relative motion (angular velocity and velocity field) is this small
against the mechanism's fastest motion are at rest relative to each other: every point is
then their centre, and the velocities do not place it (a rocker at its limit, on the
ground)."""

CHECK_RTOL = 1e-9
"""The velocity check: about each centre, v = omega x r to this much of the fastest
motion (the fastest joint's speed, or an angular velocity times the size)."""

HOW = ("primary", "Kennedy", "velocity", "undefined")

STATUSES = ("ok", "toggle", "undefined", "check_failed")
"""ok: every centre found and checked against the velocities; toggle: the velocities are
undefined here (J singular), the centres from the joints and Kennedy are shown unchecked;
undefined: some centre could not be placed; check_failed: some centre misses the
velocities by more than CHECK_RTOL."""


# --- the projective plane -------------------------------------------------------------------

def cross(a: H, b: H) -> H:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: H) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def unit(a: H) -> H:
    n = norm(a)
    return (a[0] / n, a[1] / n, a[2] / n) if n > 0.0 and math.isfinite(n) else (0.0, 0.0, 0.0)


def separation(a: H, b: H) -> float:
    """How far apart two projective points are: the sine of the angle between their unit
    vectors (0 for one point, 1 at most). For finite points near the mechanism it is their
    distance over its size, for a far one relative to the square of its distance (the
    precision a meeting point of two lines has)."""
    return norm(cross(unit(a), unit(b)))


def finite(x: float, y: float) -> H:
    return (x, y, 1.0)


def at_infinity(direction_rad: float) -> H:
    return (math.cos(direction_rad), math.sin(direction_rad), 0.0)


@frozen
class Place:
    """Where a homogeneous point is, by the one rule (:func:`place_of`)."""

    kind: str
    """finite, at infinity, or undefined (no point: h is 0 or not a number)."""
    x: float | None = None
    y: float | None = None
    direction_deg: float | None = None
    """At infinity: the direction, in [0, 180) deg (a point at infinity has no sense)."""


def is_at_infinity(h: H) -> bool:
    """The one rule for a point at infinity: |W| <= INFINITY_RTOL hypot(X, Y)."""
    return abs(h[2]) <= INFINITY_RTOL * math.hypot(h[0], h[1])


def place_of(h: H, origin: tuple[float, float], size: float) -> Place:
    """h in the frame (origin, size) -> the point in the file's coordinates, finite or at
    infinity by :func:`is_at_infinity`, or undefined (h zero or not a number)."""
    x, y, w = h
    r = math.hypot(x, y)
    if not (math.isfinite(r) and math.isfinite(w)) or (r == 0.0 and w == 0.0):
        return Place("undefined")
    if is_at_infinity(h):
        return Place("at infinity", direction_deg=degrees(math.atan2(y, x)) % 180.0)
    return Place("finite", origin[0] + size * x / w, origin[1] + size * y / w)


# --- the velocity centre: the one definition -------------------------------------------------

def velocity_centre(w_i: float, p_i: tuple[float, float], v_i: tuple[float, float],
                    w_j: float, p_j: tuple[float, float], v_j: tuple[float, float]) -> H:
    """The relative centre of bodies i and j from their motion: body b turns at w_b and its
    point p_b moves at v_b, so its velocity field is v(r) = c_b + w_b k x r with c_b = v_b -
    w_b k x p_b. The relative velocity (c_j - c_i) + (w_j - w_i) k x r vanishes at
    r = k x (c_j - c_i) / (w_j - w_i): homogeneous (-dc_y, dc_x, dw), at infinity where the
    two turn alike (dw = 0: a relative translation, the centre perpendicular to it).
    Points, velocities and the result in one frame (positions over a length, velocities
    over the same length per second)."""
    cix, ciy = v_i[0] + w_i * p_i[1], v_i[1] - w_i * p_i[0]
    cjx, cjy = v_j[0] + w_j * p_j[1], v_j[1] - w_j * p_j[0]
    return (-(cjy - ciy), cjx - cix, w_j - w_i)


# --- a pose's bodies and their motion ----------------------------------------------------------

@frozen
class Pose:
    """A joints-form mechanism solved at one driver value, with the rates of a unit driver
    speed: everything the centres need."""

    mechanism: Any
    """The joints-form mechanism (a loops-form one drawn at the pose)."""
    q: tuple[float, ...]
    driver: float
    """The driver's value, internal units (rad, or the length unit)."""
    rates: Any
    """kinematics.rates.Rates at a unit driver speed (rad/s, or the length unit per s)."""

    @property
    def drawing(self) -> Any:
        return self.mechanism.extra["drawing"]


def turning_with(drawing: Any, body: str) -> str | None:
    """The link whose angle ``body`` turns with (the joints form's rule, problems.joints: a
    link its own, first joint -> second; a slider its line's body's); None for the ground."""
    while body in drawing.sliders:
        body = drawing.sliders[body].on
    return None if body == "ground" else body


def body_angle(pose_mechanism: Any, q: Sequence[float], driver: float, body: str) -> float:
    """A body's angle (rad) at a pose (:func:`turning_with`); the ground's is 0."""
    link = turning_with(pose_mechanism.extra["drawing"], body)
    if link is None:
        return 0.0
    name = f"theta_{link}"
    if name == pose_mechanism.driver.name:
        return driver
    names = [u.name for u in pose_mechanism.unknowns]
    return float(q[names.index(name)])


def drawn_angle(drawing: Any, body: str) -> float:
    """A body's angle (rad) in the drawing itself (what :func:`body_angle` is at the drawn
    pose)."""
    link = turning_with(drawing, body)
    if link is None:
        return 0.0
    a, b = drawing.links[link][:2]
    (ax, ay), (bx, by) = drawing.xy[a], drawing.xy[b]
    return math.atan2(by - ay, bx - ax)


def angular_velocity(mechanism: Any, rates: Any, speed: float, body: str) -> float:
    """A body's angular velocity (rad/s) from the rates: its angle's rate (the driver's: the
    driver's speed; :func:`turning_with`); the ground's 0."""
    link = turning_with(mechanism.extra["drawing"], body)
    if link is None:
        return 0.0
    name = f"theta_{link}"
    return speed if name == mechanism.driver.name else rates.velocities[name]


@frozen
class HomogeneousFrame:
    """The frame the homogeneous points are in: lengths from ``origin`` over ``size``."""

    origin: tuple[float, float]
    size: float

    def point(self, xy: tuple[float, float]) -> H:
        return finite((xy[0] - self.origin[0]) / self.size, (xy[1] - self.origin[1]) / self.size)

    @classmethod
    def of(cls, joints: Mapping[str, tuple[float, float]]) -> HomogeneousFrame:
        xs, ys = [p[0] for p in joints.values()], [p[1] for p in joints.values()]
        origin = (sum(xs) / len(xs), sum(ys) / len(ys))
        size = max(math.hypot(x - origin[0], y - origin[1]) for x, y in zip(xs, ys))
        return cls(origin, size if size > 0.0 and math.isfinite(size) else 1.0)


def body_motions(mechanism: Any, rates: Any, frame: HomogeneousFrame, speed: float = 1.0
                 ) -> dict[str, tuple[float, tuple[float, float], tuple[float, float]]]:
    """Each body's (omega, a point, its velocity) in ``frame`` (per second), from the
    rates: the point is the body's first joint that is not a point on it."""
    d = mechanism.extra["drawing"]
    out = {}
    for body in d.bodies:
        j = d.center(body)
        (x, y), (vx, vy) = rates.joints[j], rates.joint_velocities.get(j, (0.0, 0.0))
        if body == "ground":
            vx = vy = 0.0
        px, py, _ = frame.point((x, y))
        w = angular_velocity(mechanism, rates, speed, body)
        out[body] = (w, (px, py), (vx / frame.size, vy / frame.size))
    return out


def fastest_motion(motions: Mapping[str, Any], rates: Any, frame: HomogeneousFrame) -> float:
    """The scale the velocity check and the rest test are relative to: the fastest joint's
    speed or the fastest turning, both per second in ``frame`` (a unit driver speed)."""
    v = max((math.hypot(*u) for u in rates.joint_velocities.values()), default=0.0) / frame.size
    return max(v, max((abs(m[0]) for m in motions.values()), default=0.0))


def relative_centre(motions: Mapping[str, Any], i: str, j: str) -> H:
    """:func:`velocity_centre` of bodies i and j from their motions (:func:`body_motions`)."""
    (wi, pi, vi), (wj, pj, vj) = motions[i], motions[j]
    return velocity_centre(wi, pi, vi, wj, pj, vj)


def at_rest(h: H, scale: float) -> bool:
    """Whether two bodies with velocity centre ``h`` move alike (MOTION_RTOL)."""
    return not norm(h) > MOTION_RTOL * scale


def velocity_residual(h: H, i: str, j: str, motions: Mapping[str, Any], rates: Any, frame: HomogeneousFrame,
                      mechanism: Any, scale: float) -> float:
    """The check of centre ``h`` of bodies i and j: at every joint P of either body, the
    velocity of j's point at P relative to i's must be (w_j - w_i) k x (P - I) about a
    finite centre I, and for one at infinity perpendicular to it with w_j = w_i. The
    largest miss, over ``scale`` (:func:`fastest_motion`); each body's own joints move
    as the rates say, the other's field from its first joint."""
    d = mechanism.extra["drawing"]
    wi, wj = motions[i][0], motions[j][0]
    dw = wj - wi
    unit_h = unit(h)
    far = is_at_infinity(unit_h)
    worst = abs(dw) if far else 0.0  # at infinity: a relative translation, no relative turning
    for joint in dict.fromkeys([*d.bodies[i], *d.bodies[j]]):
        x, y = frame.point(rates.joints[joint])[:2]
        v = {}
        for b in (i, j):
            if joint in d.bodies[b] and b != "ground":
                vx, vy = rates.joint_velocities[joint]
                v[b] = (vx / frame.size, vy / frame.size)
            else:
                w, (px, py), (pvx, pvy) = motions[b]
                v[b] = (pvx - w * (y - py), pvy + w * (x - px))
        rx, ry = v[j][0] - v[i][0], v[j][1] - v[i][1]
        X, Y, W = unit_h
        if far:
            n = math.hypot(X, Y)
            miss = abs(rx * X + ry * Y) / n  # the relative velocity is across the direction
        else:
            cx, cy = X / W, Y / W
            miss = math.hypot(rx + dw * (y - cy), ry - dw * (x - cx))
        worst = max(worst, miss)
    return worst / scale if scale > 0.0 else (0.0 if worst == 0.0 else math.inf)


# --- the centres ------------------------------------------------------------------------------

def primary_centres(mechanism: Any, q: Sequence[float], driver: float, joints: Mapping[str, Any],
                    frame: HomogeneousFrame) -> dict[tuple[str, str], H]:
    """The centres the joints give: each pin shared by two bodies, and each slider's at
    infinity perpendicular to its line (the line turned with its body since the drawing)."""
    d = mechanism.extra["drawing"]
    order = {b: k for k, b in enumerate(d.bodies)}
    out: dict[tuple[str, str], H] = {}
    for joint in d.xy:
        on = [b for b in d.bodies if joint in d.bodies[b]]
        for a in range(len(on)):
            for b in range(a + 1, len(on)):
                out[pair(on[a], on[b], order)] = frame.point(joints[joint])
    for s, slide in d.sliders.items():
        turn = body_angle(mechanism, q, driver, slide.on) - drawn_angle(d, slide.on)
        out[pair(s, slide.on, order)] = at_infinity(radians(slide.angle_deg) + turn + math.pi / 2)
    return out


def pair(a: str, b: str, order: Mapping[str, int]) -> tuple[str, str]:
    return (a, b) if order[a] < order[b] else (b, a)


def kennedy(bodies: Sequence[str], known: Mapping[tuple[str, str], H]
            ) -> dict[tuple[str, str], tuple[H, tuple[str, str]]]:
    """The centres Kennedy's theorem places from ``known``: repeatedly, of every centre
    still unknown, the one whose two lines I_ik I_kj and I_im I_mj meet most clearly
    (the largest of min(line strengths) x sine between the lines, each line's strength the
    sine between its two points), until none has two distinct lines. Only the new ones,
    each with the third bodies (k, m) of its two lines."""
    order = {b: k for k, b in enumerate(bodies)}
    have = {k: unit(v) for k, v in known.items()}
    found: dict[tuple[str, str], tuple[H, tuple[str, str]]] = {}
    while True:
        best: tuple[float, tuple[str, str], H, tuple[str, str]] | None = None
        for a in range(len(bodies)):
            for b in range(a + 1, len(bodies)):
                i, j = bodies[a], bodies[b]
                if (i, j) in have:
                    continue
                lines = []
                for k in bodies:
                    if k in (i, j):
                        continue
                    p, r = have.get(pair(i, k, order)), have.get(pair(j, k, order))
                    if p is None or r is None:
                        continue
                    line = cross(p, r)
                    strength = norm(line)
                    if strength > DISTINCT:
                        lines.append((strength, unit(line), k))
                for x in range(len(lines)):
                    for y in range(x + 1, len(lines)):
                        meet = cross(lines[x][1], lines[y][1])
                        score = min(lines[x][0], lines[y][0]) * norm(meet)
                        if norm(meet) > DISTINCT and (best is None or score > best[0]):
                            best = (score, (i, j), unit(meet), (lines[x][2], lines[y][2]))
        if best is None:
            return found
        have[best[1]] = best[2]
        found[best[1]] = (best[2], best[3])


@frozen
class Centre:
    """One relative instant centre."""

    label: str
    """I13: bodies numbered 1 for the ground, then the links in the file's order."""
    i: str
    j: str
    kind: str
    """finite, at infinity, or undefined."""
    x: float | None
    y: float | None
    """The file's coordinates and length unit (None unless finite)."""
    direction_deg: float | None
    """At infinity: its direction, [0, 180) deg."""
    how: str
    """primary, Kennedy, velocity or undefined (:data:`HOW`)."""
    residual: float | None
    """The velocity check (:func:`velocity_residual`, relative to the fastest motion);
    None where the velocities are undefined."""
    via: tuple[str, ...] = ()
    """Kennedy: the two lines it is on, each through two centres (\"I12 I23\")."""
    velocity_separation: float | None = None
    """How far the velocities' own centre is from this one (:func:`separation`); None where
    the velocities do not place it (undefined, or the two bodies at rest relative to each
    other)."""


@frozen
class InstantCentres:
    """The n(n-1)/2 instant centres of a mechanism at one pose (:func:`instant_centres`)."""

    mechanism: str
    driver: str
    driver_value: float
    """In the driver's display unit (deg for an angle)."""
    driver_unit: str
    length_unit: str
    bodies: tuple[str, ...]
    centres: tuple[Centre, ...]
    status: str
    """:data:`STATUSES`."""
    message: str
    worst_residual: float | None
    converted: bool = False
    """A loops-form file, drawn at the pose to name its bodies (linkage convert --form joints)."""

    def centre(self, i: str, j: str) -> Centre:
        """The centre of bodies i and j (either order)."""
        for c in self.centres:
            if {c.i, c.j} == {i, j}:
                return c
        raise InputError(f"no bodies {i!r} and {j!r} (bodies: {', '.join(self.bodies)})")


def centres_at(pose: Pose) -> InstantCentres:
    """Every centre of a solved pose: primary, then Kennedy, then the velocities for what
    is left; each checked against the velocities (see the module)."""
    m, rates = pose.mechanism, pose.rates
    d = pose.drawing
    bodies = tuple(d.bodies)
    order = {b: k for k, b in enumerate(bodies)}

    def label(i: str, j: str) -> str:
        """I13: bodies numbered 1 for the ground, then the links in the file's order."""
        a, b = sorted((order[i] + 1, order[j] + 1))
        return f"I{a}{b}" if len(bodies) < 10 else f"I{a},{b}"

    frame = HomogeneousFrame.of(rates.joints)
    primary = primary_centres(m, pose.q, pose.driver, rates.joints, frame)
    by_kennedy = kennedy(bodies, primary)
    moving = rates.status != "undefined" and bool(rates.joint_velocities)
    motions = body_motions(m, rates, frame) if moving else {}
    scale = fastest_motion(motions, rates, frame) if moving else 0.0
    centres = []
    for a in range(len(bodies)):
        for b in range(a + 1, len(bodies)):
            i, j = bodies[a], bodies[b]
            key = pair(i, j, order)
            via: tuple[str, ...] = ()
            h_v = relative_centre(motions, i, j) if moving else None
            if h_v is not None and at_rest(h_v, scale):
                h_v = None
            if key in primary:
                h, how = primary[key], "primary"
            elif key in by_kennedy:
                (h, thirds), how = by_kennedy[key], "Kennedy"
                via = tuple(f"{label(i, k)} {label(k, j)}" for k in thirds)
            elif h_v is not None:
                h, how = h_v, "velocity"
            else:
                h, how = (0.0, 0.0, 0.0), "undefined"
            where = place_of(h, frame.origin, frame.size)
            if where.kind == "undefined":
                how = "undefined"
            residual = (velocity_residual(h, i, j, motions, rates, frame, m, scale)
                        if moving and how != "undefined" else None)
            apart = separation(h, h_v) if h_v is not None and how != "undefined" else None
            centres.append(Centre(label(i, j), i, j, where.kind, where.x, where.y, where.direction_deg, how,
                                  residual, via, apart))
    worst = max((c.residual for c in centres if c.residual is not None), default=None)
    undefined = [c.label for c in centres if c.how == "undefined"]
    if undefined:
        status = "undefined"
        message = (f"{', '.join(undefined)} undefined here: the joints, Kennedy's theorem (its lines "
                   "coincide) and the velocities do not place " + ("it" if len(undefined) == 1 else "them")
                   + ("" if moving else " (the velocities are undefined: a toggle)"))
    elif not moving:
        status = "toggle"
        message = ("the velocities are undefined here (a toggle: the loop equations' Jacobian is "
                   "singular), so the centres from the joints and Kennedy's theorem are not checked")
    elif worst is not None and not worst <= CHECK_RTOL:
        status = "check_failed"
        bad = [c.label for c in centres if c.residual is not None and not c.residual <= CHECK_RTOL]
        message = (f"{', '.join(bad)} miss the velocities by up to {worst:.2g} of the fastest motion "
                   f"(more than {CHECK_RTOL:g}): near a toggle or limit the centres are ill-conditioned")
    else:
        status = "ok"
        message = (f"every centre checked against the velocities: v = omega x r about it within "
                   f"{CHECK_RTOL:g} of the fastest motion (worst {worst:.2g})" if worst is not None
                   else "every centre found")
    driver = m.driver
    shown = read_degrees(pose.driver, driver.unit) if driver.kind == "angle" else pose.driver
    return InstantCentres(m.name, driver.name, shown, "deg" if driver.kind == "angle" else m.length_unit,
                          m.length_unit, bodies, tuple(centres), status, message, worst)


# --- from a mechanism -------------------------------------------------------------------------

def joints_form(m: Any) -> tuple[Any, bool]:
    """The mechanism in the joints form (its bodies named), and whether it was drawn here
    from a loops-form file (at its driver value, as linkage convert --form joints draws it;
    a loop that names no joints is refused with that command's message)."""
    if m.extra.get("drawing") is not None:
        return m, False
    from .loading import parse_mechanism
    from .to_joints import joints_doc

    return parse_mechanism(joints_doc(m), m.source), True


def solve_pose(m: Any) -> Pose:
    """The joints-form mechanism ``m`` solved at its driver value (from its guesses: a
    drawing's drawn pose), with the rates of a unit driver speed; an InputError where it
    cannot be assembled."""
    from .rates import position_rates

    q = tuple(float(v) for v in assembled(m).x)
    return Pose(m, q, m.driver.value, position_rates(m.model, list(q), m.driver.value, 1.0, 0.0))


def assembled(m: Any) -> Any:
    """The mechanism ``m`` solved at its driver value from its guesses (tol 1e-12): the pose
    that ``centres`` and ``draw`` work from; an InputError ("cannot be
    assembled at ...": where the closed form has no real solution, as ``solve`` refuses it;
    otherwise with the solve's reason) where it does not solve."""
    from ..solve import solve_system
    from ..solve.system import check_assembles

    problem = m.problem()
    check_assembles(problem, m.source)
    result = solve_system(problem, tol=1e-12, record=False)
    if not result.converged:
        raise InputError(f"{m.source}: cannot be assembled at {_driver_text(m)}: {result.message}")
    return result


def drawing_unit(m: Any) -> float:
    """The drawing's driver unit (deg, or the length unit) per the file's."""
    from ..problems.loops import ANGLE_UNITS, length_factor

    if m.driver.kind == "angle":
        return degrees(ANGLE_UNITS[m.driver.unit])
    return 1.0 if m.driver.unit == m.length_unit else length_factor(m.driver.unit, m.length_unit)


def read_degrees(value: float, unit: str) -> float:
    """An angle (internal radians) in degrees as its file or argument gave it in ``unit``:
    a value read in degrees was multiplied by ANGLE_UNITS["deg"], and converting back by
    math.degrees can miss it by an ulp (30 -> 29.999999999999996), so the shortest decimal
    that reads as the same radians is given (the value typed, or one indistinguishable from
    it); a value read in radians, math.degrees of it."""
    from ..problems.loops import ANGLE_UNITS

    if unit != "deg" or not math.isfinite(value):
        return degrees(value)
    per = ANGLE_UNITS["deg"]
    near = value / per
    for digits in range(16):
        shown = round(near, digits)
        if shown * per == value:
            return shown
    return degrees(value)


def _driver_text(m: Any) -> str:
    d = m.driver
    v = read_degrees(d.value, d.unit) if d.kind == "angle" else d.value
    return f"{d.name} = {v:.12g} {'deg' if d.kind == 'angle' else m.length_unit}"


def at_driver(mechanism: Any, driver_value: Any = None, branch: Any = None) -> tuple[Any, Pose, bool]:
    """(the mechanism as given, at ``driver_value``, started on ``branch``), its pose, and
    whether it was converted from the loops form: the front door's work, shared by the
    command line."""
    from ..arguments import check_number, check_text
    from .loading import mechanism_of

    m = mechanism_of("mechanism", mechanism)
    if driver_value is not None:
        m = m.with_values({m.driver.name: check_number("driver_value", driver_value)}, {})
    if check_text("branch", branch) is not None:
        from ..problems.start import start_on_branch

        m = start_on_branch(m, branch, False)
    if m.extra.get("drawing") is None:
        assembled(m)
    jm, converted = joints_form(m)
    return m, solve_pose(jm), converted


def instant_centres(mechanism: Any, driver_value: Any = None, *, branch: str | None = None) -> InstantCentres:
    """All n(n-1)/2 instant centres of a one-degree-of-freedom mechanism (a path or a
    :class:`~linkage.Mechanism`, either form) at ``driver_value`` (the driver's display
    unit: degrees for an angle; default the file's), on the assembly ``branch`` names (as
    ``solve --branch``; default the file's guesses): the public ``linkage.instant_centres``.
    Each :class:`Centre` is finite or at infinity (with its direction), says how it was
    found (primary, Kennedy, velocity) and how closely the velocities bear it out. A
    misuse, a mechanism that does not assemble at the value, or a loops file whose loops
    name no joints raises :class:`~linkage.errors.InputError`."""
    m, pose, converted = at_driver(mechanism, driver_value, branch)
    return as_given(centres_at(pose), m, converted)


def as_given(ic: InstantCentres, m: Any, converted: bool) -> InstantCentres:
    """The centres named by the file as given: a loops-form file's driver by its own name."""
    from dataclasses import replace

    return replace(ic, driver=m.driver.name, converted=converted)
