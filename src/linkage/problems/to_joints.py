"""A loops-form mechanism as it is drawn: ``linkage convert --form joints``, the way back
from :func:`.toml_text.loops_text`. Given the loops solved at the file's driver value and
their named points placed (:mod:`linkage.kinematics.to_joints` solves and places them: a
solve is a layer above the problems), each vector tells the body it lies on:

- a vector turning with an unknown or driver angle lies on the link of that angle;
- a vector of constant length and angle joining two fixed points lies on the ground (a
  point is fixed when the loop reaches it from a fixed one along constant vectors only);
- a vector whose length is an unknown (or a length driver) is a slider's travel along a
  line on the body of its angle; the block carries the travel's named end that is not on
  that body, and any constant-angle vector from it to a moving joint (the block
  translates: the rapier's pin D and its tip E).

Links are named after their angles (``theta_crank`` -> ``crank``, ``theta3`` -> ``link3``),
sliders after their travels (``s_block`` -> ``block``, ``s`` -> ``block_s``). The solving
side checks the result by deriving its loops again (:func:`.joints.loops_doc`) and solving
them at the drawn value: a drawing that does not reproduce the placed joints is refused,
never printed. A loop whose vectors do not name their joints cannot be drawn, and says so.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

from ..errors import InputError
from ..records import NamedTuple
from ..units import degrees
from .joints import GROUND
from .toml_text import toml_key, toml_value

Point = tuple[float, float]


class _Vector(NamedTuple):
    loop: int
    index: int
    frame: str  # the angle it turns with, or GROUND for a constant angle
    slide: bool  # its length is an unknown: a slider's travel
    start: str  # named points ("" unnamed)
    end: str
    term: Any


class _Moving(NamedTuple):
    """The names that move: the unknowns' and a driver's, by kind."""

    angles: frozenset[str]
    lengths: frozenset[str]

    def frame(self, t: Any) -> str:
        return t.angle if isinstance(t.angle, str) and t.angle in self.angles else GROUND

    def slides(self, t: Any) -> bool:
        return isinstance(t.length, str) and t.length in self.lengths

    def constant(self, t: Any) -> bool:
        return self.frame(t) == GROUND and not self.slides(t)


def link_name(angle: str) -> str:
    if angle.startswith("theta_") and len(angle) > 6:
        return angle[6:]
    digits = re.fullmatch(r"theta(\d+)", angle)
    return f"link{digits.group(1)}" if digits else f"link_{angle}"


def slider_name(length: str) -> str:
    return length[2:] if length.startswith("s_") and len(length) > 2 else f"block_{length}"


def refusal(m: Any, msg: str) -> InputError:
    """Why ``m`` cannot be drawn, as every step of the drawing says it."""
    return InputError(f"{m.source}: cannot be drawn as joints and links: {msg}")


def check_joints_named(m: Any) -> None:
    """A loop whose vectors do not name their joints cannot be drawn: refused first."""
    for i, loop in enumerate(m.loops):
        if not loop.joints:
            raise refusal(m, f"loops[{i}] ({loop.name}) names no joints: give joints = [...], the "
                             "start point of each vector (\"\" for an unnamed corner)")


def drawing_doc(m: Any, q: Sequence[float], placed: Mapping[str, Point]) -> dict[str, Any]:
    """The joints-form document of the loops-form mechanism ``m`` (see the module), given
    its unknowns ``q`` solved at its driver value and every named point ``placed`` there."""
    check_joints_named(m)
    moving = _moving(m)
    vectors, fixed = _vectors(m, moving)
    blocks = _blocks(m, vectors, fixed, list(q))
    members = _members(m, vectors, fixed, blocks, moving)
    ground = members.pop(GROUND, [])
    first = m.loops[0].joints[0]
    if first in ground:
        ground.remove(first)
        ground.insert(0, first)
    links = _links(members, blocks, vectors, moving)
    sliders = {s: {"on": GROUND if b["frame"] == GROUND else link_name(b["frame"]), "angle": _wrap(b["line"])}
               for s, b in blocks.items()}
    coords = {j: placed[j] for loop in m.loops for j in loop.joints if j} | {p: placed[p] for p in m.points}
    driver = _driver(m, links, ground, blocks, coords)
    used = {j for js in [ground, *links.values()] for j in js}
    doc = {"name": m.name, "description": m.description, "length_unit": m.length_unit,
           "ground": ground, "joints": {j: list(xy) for j, xy in coords.items() if j in used},
           "links": links}
    if sliders:
        doc["sliders"] = sliders
    doc["driver"] = driver
    return doc


def _moving(m: Any) -> _Moving:
    angles = {u.name for u in m.unknowns if u.kind == "angle"} | (
        {m.driver.name} if m.driver.kind == "angle" else set())
    lengths = {u.name for u in m.unknowns if u.kind == "length"} | (
        {m.driver.name} if m.driver.kind == "length" else set())
    return _Moving(frozenset(angles), frozenset(lengths))


def _vectors(m: Any, moving: _Moving) -> tuple[list[_Vector], set[str]]:
    """Every loop vector with the body it turns with, and the named points fixed in the
    ground (reached from a fixed one along constant vectors only)."""
    vectors: list[_Vector] = []
    fixed: set[str] = set()
    for i, loop in enumerate(m.loops):
        names, n = loop.joints, len(loop.vectors)
        for k, t in enumerate(loop.vectors):
            vectors.append(_Vector(i, k, moving.frame(t), moving.slides(t), names[k], names[(k + 1) % n], t))
        start_fixed = i == 0 or names[0] in fixed
        steady = [moving.constant(t) for t in loop.vectors]
        for k, name in enumerate(names):
            if name and start_fixed and (all(steady[:k]) or all(steady[k:])):
                fixed.add(name)
        for k, name in enumerate(names):
            if name:
                continue
            before, after = vectors[-n + (k - 1) % n], vectors[-n + k]
            if not (before.frame == after.frame or before.slide or after.slide):
                raise refusal(m, f"loops[{i}] ({loop.name}): the point after vector {(k - 1) % n} joins "
                                 "two links: name it in joints = [...]")
    return vectors, fixed


def _blocks(m: Any, vectors: list[_Vector], fixed: set[str], q: list[float]) -> dict[str, dict[str, Any]]:
    """The sliders: a travel's named end not on its line's body is the pin its block carries."""
    blocks: dict[str, dict[str, Any]] = {}
    for v in vectors:
        if not v.slide:
            continue
        n = len(m.loops[v.loop].vectors)
        around = {v.start: vectors[_at(vectors, v.loop, (v.index - 1) % n)],
                  v.end: vectors[_at(vectors, v.loop, (v.index + 1) % n)]}
        pins = [j for j, w in around.items() if j and not (w.frame == v.frame and not w.slide and (
                v.frame != GROUND or {w.start, w.end} - {""} <= fixed))]
        if len(pins) != 1:
            raise refusal(m, f"loops[{v.loop}] ({m.loops[v.loop].name}): cannot tell which end of the "
                             f"travel {v.term.length} carries the slider")
        line = degrees(_value(m, v.term.angle, q, m.driver.value) + v.term.offset)
        blocks.setdefault(slider_name(str(v.term.length)), {"pin": pins[0], "frame": v.frame, "line": line,
                                                            "travel": v.term.length})
    return blocks


def _members(m: Any, vectors: list[_Vector], fixed: set[str], blocks: dict[str, dict[str, Any]],
             moving: _Moving) -> dict[str, list[str]]:
    """Each body's joints (GROUND's too), in the order they are met."""
    members: dict[str, list[str]] = {}

    def join(body: str, *joints: str) -> None:
        for j in joints:
            if j and j not in members.setdefault(body, []):
                members[body].append(j)

    for b in blocks.values():
        join(slider_name(str(b["travel"])), b["pin"])
    # a constant-angle vector touching a moving joint lies on a translating block
    pending = [v for v in vectors if not v.slide]
    grew = True
    while grew:
        grew = False
        for v in list(pending):
            if v.frame != GROUND or ({v.start, v.end} - {""}) <= fixed:
                continue
            owner = next((s for s, b in blocks.items() if b["frame"] == GROUND and
                          ({v.start, v.end} & set(members.get(s, [])))), None)
            if owner is not None:
                join(owner, v.start, v.end)
                pending.remove(v)
                grew = True
    for v in pending:
        if v.frame == GROUND and not ({v.start, v.end} - {""}) <= fixed:
            raise refusal(m, f"loops[{v.loop}] ({m.loops[v.loop].name}): vector {v.index} has a fixed "
                             "direction but moves, and no slider carries it")
        join(GROUND if v.frame == GROUND else link_name(v.frame), v.start, v.end)
    for pname, (origin, terms) in m.points.items():
        frames = {moving.frame(t) for t in terms}
        if len(frames) != 1 or any(moving.slides(t) for t in terms):
            raise refusal(m, f"points.{pname}: its vectors run over more than one link")
        (f,) = frames
        if f != GROUND:
            join(link_name(f), pname)
            continue
        owner = next((s for s in blocks if origin in members.get(s, [])), None)
        if owner is None:
            raise refusal(m, f"points.{pname}: a point fixed in the ground: list it in a loop instead")
        join(owner, pname)
    return members


def _links(members: dict[str, list[str]], blocks: dict[str, dict[str, Any]], vectors: list[_Vector],
           moving: _Moving) -> dict[str, list[str]]:
    """Each moving body's joints: a block's pin first, a link's two its angle runs between."""
    links = {}
    for body, joints in sorted(members.items(), key=lambda item: item[0] in blocks):
        if body in blocks:
            joints.remove(blocks[body]["pin"])
            links[body] = [blocks[body]["pin"], *joints]
            continue
        angle = next(f for f in moving.angles if link_name(f) == body)
        links[body] = _ordered(joints, [v for v in vectors if v.frame == angle and not v.slide])
    return links


def _driver(m: Any, links: dict[str, list[str]], ground: list[str], blocks: dict[str, dict[str, Any]],
            coords: Mapping[str, Point]) -> dict[str, Any]:
    """The drawing's [driver]: the link it turns (its fixed joint first) at the drawn angle,
    or the slider whose travel it is; its range in the drawing's unit."""
    if m.driver.kind == "angle":
        link = link_name(m.driver.name)
        js = links[link]
        if js[0] not in ground:
            if len(js) == 2 and js[1] in ground:
                links[link] = js = [js[1], js[0]]
            else:
                raise refusal(m, f"the driver {m.driver.name} turns a link with no fixed joint first")
        (x0, y0), (x1, y1) = coords[js[0]], coords[js[1]]
        drawn, stated = degrees(math.atan2(y1 - y0, x1 - x0)), degrees(m.driver.value)
        # the file's own value where the drawing agrees with it (it does but for rounding
        # when the driver's vector runs first joint -> second with no offset)
        value = stated if abs(_wrap(drawn - stated)) <= 1e-9 else drawn
        driver: dict[str, Any] = {"link": link, "value": value}
    else:
        slider = next((s for s, b in blocks.items() if b["travel"] == m.driver.name), None)
        if slider is None:
            raise refusal(m, f"the driver {m.driver.name} is a length but no slider's travel")
        driver = {"slider": slider}
    if m.driver_range is not None:  # in the driver's unit; a drawing's is deg or its length unit
        driver["range"] = [v * _to_drawing_unit(m) for v in m.driver_range]
    return driver


def _to_drawing_unit(m: Any) -> float:
    from .loops import ANGLE_UNITS, length_factor

    if m.driver.kind == "angle":
        return degrees(ANGLE_UNITS[m.driver.unit]) if m.driver.unit != "deg" else 1.0
    return 1.0 if m.driver.unit == m.length_unit else length_factor(m.driver.unit, m.length_unit)


def _at(vectors: list[_Vector], loop: int, index: int) -> int:
    return next(k for k, v in enumerate(vectors) if v.loop == loop and v.index == index)


def _value(m: Any, ref: Any, q: list[float], d: float) -> float:
    if not isinstance(ref, str):
        return float(ref)
    if ref == m.driver.name:
        return d
    names = [u.name for u in m.unknowns]
    return q[names.index(ref)] if ref in names else m.parameters[ref].value


def _wrap(deg: float) -> float:
    from .closed_form import wrap_degrees

    return wrap_degrees(deg)


def _ordered(joints: list[str], vectors: list[_Vector]) -> list[str]:
    """A link's joints with the two its angle runs between first (a vector along the
    angle itself, no offset), so the joints form's link angle is the loops' angle."""
    for v in vectors:
        if v.term.offset == 0.0 and v.start and v.end:
            a, b = (v.start, v.end) if v.term.sign > 0 else (v.end, v.start)
            return [a, b, *(j for j in joints if j not in (a, b))]
    return joints


def shown_driver(m: Any) -> str:
    """The driver's value as the user reads it (deg, or the length unit)."""
    v = degrees(m.driver.value) if m.driver.kind == "angle" else m.driver.value
    return f"{v:g} {'deg' if m.driver.kind == 'angle' else m.length_unit}"


def drawing_text(m: Any, doc: Mapping[str, Any], source: str) -> str:
    """The joints form ``doc`` of ``m`` (:func:`drawing_doc`) as a commented TOML file."""
    unit = doc["length_unit"]
    names: dict[str, set[str]] = {}
    for loop in m.loops:
        for t in loop.vectors:
            if isinstance(t.angle, str) and isinstance(t.length, str) and not any(
                    u.name == t.length for u in m.unknowns) and t.length != m.driver.name:
                names.setdefault(t.angle, set()).add(t.length)
    out = [f"# {source} drawn as joints and links (linkage convert --form joints): its loops",
           f"# solved at {m.driver.name} = {shown_driver(m)}, each joint where they place it",
           f"name = {toml_value(doc['name'])}"]
    if doc["description"]:
        out.append(f"description = {toml_value(doc['description'])}")
    out += [f"length_unit = {toml_value(unit)}", f"ground = {toml_value(doc['ground'])}  # fixed joints",
            "", f"[joints]  # one pose, in {unit}"]
    out += [f"{toml_key(j)} = {toml_value(xy)}" for j, xy in doc["joints"].items()]
    out += ["", "[links]  # the joints each rigid link carries; its angle: first joint -> second"]
    for link, js in doc["links"].items():
        was = next((a for a in names if link_name(a) == link), None)
        note = f"  # {was}: {', '.join(sorted(names[was]))}" if was else ""
        out.append(f"{toml_key(link)} = {toml_value(js)}{note}")
    if "sliders" in doc:
        out += ["", "[sliders]  # a link sliding along a line fixed to `on`, through its first joint"]
        out += [f"{toml_key(s)} = {toml_value(spec)}" for s, spec in doc["sliders"].items()]
    out += ["", "[driver]"] + [f"{k} = {toml_value(v)}" for k, v in doc["driver"].items()]
    if "slider" in doc["driver"]:
        out[-1] += "  # its travel is the drawn one"
    return "\n".join(out) + "\n"
