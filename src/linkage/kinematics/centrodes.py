"""The centrodes of a body over a sweep (docs/centres.md): at each position, the instant
centre of the body relative to the ground by the velocities (kinematics.centres'
:func:`~.centres.velocity_centre` rule through the body's motion), in the ground's frame
(the fixed centrode) and in the body's own (the moving centrode); points at infinity kept
as directions.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import degrees, radians
from .centres import (
    HomogeneousFrame,
    Place,
    at_rest,
    body_angle,
    body_motions,
    drawing_unit,
    fastest_motion,
    joints_form,
    place_of,
    relative_centre,
)


@frozen
class CentrodePoint:
    input: float
    """The driver value (display unit)."""
    status: str
    """The sweep's status, or where it solved: ok, at_rest (the body is not moving
    relative to the ground: no centre), toggle (velocities undefined)."""
    fixed: Place
    """The centre in the ground's frame."""
    moving: Place
    """The same centre in the body's frame: from its first joint, x along its angle."""
    omega: float | None = None
    """The body's angular velocity at a unit driver speed (rad/s per driver unit/s): where it
    changes sign between positions, the centre passes through infinity."""


@frozen
class Centrodes:
    """The fixed and moving centrodes of ``body`` relative to the ground over a sweep."""

    mechanism: str
    body: str
    driver: str
    driver_unit: str
    length_unit: str
    points: tuple[CentrodePoint, ...]
    frame_joint: str
    """The body's first joint: its frame's origin (x along the body's angle)."""
    size: float = 1.0
    """The mechanism's size (its longest length, the length unit)."""

    @property
    def through_infinity(self) -> tuple[tuple[float, float], ...]:
        """The driver intervals between neighbouring solved positions over which the centre
        passes through infinity: the body's angular velocity changes sign there while the
        centre is finite on both sides and not the same point. A body pinned to the ground
        reverses about its pivot (its centre stays put), and a translating body's centre is
        at infinity throughout, its angular velocity rounding noise: neither passes."""
        out = []
        for a, b in zip(self.points, self.points[1:]):
            if a.omega is None or b.omega is None or not a.omega * b.omega < 0.0:
                continue
            pa, pb = a.fixed, b.fixed
            if pa.kind != "finite" or pb.kind != "finite":
                continue
            if math.hypot(pa.x - pb.x, pa.y - pb.y) <= 1e-9 * max(1.0, math.hypot(pa.x, pa.y)):
                continue
            out.append((a.input, b.input))
        return tuple(out)


def default_body(m: Any) -> str:
    """The coupler: the first link with no ground joint, a turning link before a slider."""
    d = m.extra["drawing"]
    free = [b for b in d.links if not any(j in d.ground for j in d.links[b])]
    turning = [b for b in free if b not in d.sliders]
    if not free:
        raise InputError(f"{m.source}: every link has a ground joint: name the body with --body")
    return (turning or free)[0]


def check_body(m: Any, body: Any) -> str:
    d = m.extra["drawing"]
    links = [b for b in d.bodies if b != "ground"]
    if not isinstance(body, str) or body not in links:
        raise InputError(f"body must name a link of {m.source} (links: {', '.join(links)}), got {body!r}")
    return body


def centrode_point(m: Any, q: Sequence[float], driver: float, rates: Any, body: str, shown: float
                   ) -> CentrodePoint:
    """One sweep position's centre of ``body`` relative to the ground, by the velocities
    (:func:`velocity_centre`), in both frames."""
    none = Place("undefined")
    if rates is None or rates.status == "undefined" or not rates.joint_velocities:
        return CentrodePoint(shown, "toggle", none, none)
    frame = HomogeneousFrame.of(rates.joints)
    motions = body_motions(m, rates, frame)
    h = relative_centre(motions, "ground", body)
    if at_rest(h, fastest_motion(motions, rates, frame)):
        return CentrodePoint(shown, "at_rest", none, none)
    fixed = place_of(h, frame.origin, frame.size)
    d = m.extra["drawing"]
    turn = body_angle(m, q, driver, body)
    c, s = math.cos(turn), math.sin(turn)
    o = rates.joints[d.links[body][0]]
    if fixed.kind == "finite":
        dx, dy = fixed.x - o[0], fixed.y - o[1]  # type: ignore[operator]
        moving = Place("finite", c * dx + s * dy, -s * dx + c * dy)
    elif fixed.kind == "at infinity":
        moving = Place("at infinity", direction_deg=(fixed.direction_deg - degrees(turn)) % 180.0)
    else:
        moving = none
    return CentrodePoint(shown, "ok" if fixed.kind != "undefined" else "undefined", fixed, moving, h[2])


def centrodes(mechanism: Any, values: Any, body: str | None = None, *, branch: str | None = None
              ) -> Centrodes:
    """The fixed and moving centrodes of ``body`` (default the coupler: :func:`default_body`)
    relative to the ground over driver ``values`` (display units), by the velocities at
    each position of a sweep; points at infinity kept as directions. The public
    ``linkage.centrodes``."""
    from ..arguments import check_reals, check_text
    from .loading import mechanism_of
    from .positions import MAX_POSITIONS
    from .sweep import sweep_mechanism

    m = mechanism_of("mechanism", mechanism)
    values = check_reals("values", values, most=MAX_POSITIONS)
    check_text("branch", branch)
    if body is not None:
        check_text("body", body)
    if branch is not None:  # the branch is named by the file as given: its assembly at its value
        from ..problems.start import start_on_branch

        m = start_on_branch(m, branch, False)
    jm, _ = joints_form(m)
    body = default_body(jm) if body is None else check_body(jm, body)
    # the values in the file's driver unit; a drawing's is deg (or its length unit)
    k = drawing_unit(m)
    result = sweep_mechanism(jm, [v * k for v in values], speed=1.0)
    names = [u.name for u in jm.unknowns]
    scale = radians(1.0) if jm.driver.kind == "angle" else 1.0
    points = []
    none = Place("undefined")
    for p in result.positions:
        if p.solution is None:
            points.append(CentrodePoint(p.input / k, p.status, none, none))
            continue
        q = [radians(p.solution[n]) if u.kind == "angle" else p.solution[n]
             for n, u in zip(names, jm.unknowns)]
        points.append(centrode_point(jm, q, p.input * scale, p.rates, body, p.input / k))
    return Centrodes(jm.name, body, m.driver.name, m.driver.unit, jm.length_unit, tuple(points),
                     jm.extra["drawing"].links[body][0], jm.length_scale)
