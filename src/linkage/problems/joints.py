"""A mechanism from its drawing: joints with coordinates, links as lists of joints,
sliders, a driver. Derives what the loops form states by hand: each link's lengths and the
fixed angles inside it, the mobility (Gruebler-Kutzbach) and the independent loops (a
cycle basis of the joint-link graph), and hands :func:`~linkage.kinematics.loading.parse_mechanism` the
equivalent loops-form document, so everything downstream works unchanged;
:func:`.toml_text.loops_text` is ``linkage convert``. The shape of the file::

    name = "Offset slider-crank"
    length_unit = "mm"
    ground = ["O2"]                # fixed joints
    [joints]                       # one pose, in length_unit
    O2 = [0, 0]
    A  = [28.2842712474619, 28.2842712474619]
    B  = [146.883113674145, 10]
    P  = [...]                     # on the coupler, nothing else attached: a coupler point
    [links]
    crank   = ["O2", "A"]
    coupler = ["A", "B", "P"]      # a ternary link
    block   = ["B"]                # a slider: a link that slides, carrying B
    [sliders]                      # along a line fixed to `on`, through its first joint as
    block = { on = "ground", angle = 0 }   # drawn, at `angle` (or line = [P, Q] of `on`)
    [driver]
    link = "crank"                 # its angle at its first joint, degrees (or slider = NAME:
    value = 45                     # its travel), where to solve; left out: the drawn angle

Each link's angle is the angle of the line from its first joint to its second, as drawn
and as it moves; its other joints are fixed in it by their drawn offsets. A slider turns
with the body its line is on; its travel is measured along the line from the foot of the
perpendicular from that body's first joint. The drawing gives the lengths and the
assembly; [driver] value says where to solve (left out, the drawn angle or travel). A
value other than the drawn one (beyond the drawing's rounding, :data:`DRIVER_TOLERANCE_DEG`)
is solved on the drawing's branch (:func:`~linkage.kinematics.loading.parse_mechanism`), and a command says
where the crank was drawn in a note.
Derived names (stable: scans and scripts use them): unknowns ``theta_<link>`` and
``s_<slider>``; lengths ``<link>`` (first to second joint), ``<link>_<P>_<Q>``, ``ground``
with its angle ``theta_ground`` (``ground_<P>_<Q>``, ``theta_ground_<P>_<Q>``), and each
slider line's signed offset ``e_<slider>``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from typing import Any

from ..errors import ParseError
from ..records import NamedTuple
from ..units import degrees, radians
from .closed_form import wrap_degrees

GROUND = "ground"
DRIVER_TOLERANCE_DEG = 1e-6
"""How far [driver] value may be from the drawn driver angle and still be the drawn pose
(the drawing's rounding): solved from the drawing's guesses, with no note."""
DRIVER_TOLERANCE_LENGTH = 1e-6
"""The same for a slider's travel, relative to the drawing's size."""
MAX_JOINTS = 1000
"""Joints (and links) a drawing may have: far above any real mechanism, and small enough
that the checks and the cycle basis stay instant on a hostile file."""


def _number(v: Any) -> bool:
    """A finite real number (a TOML integer beyond a double's range is not: never
    converted, so never an OverflowError)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) <= sys.float_info.max


def _angle_deg(p: tuple[float, float], q: tuple[float, float]) -> float:
    return degrees(math.atan2(q[1] - p[1], q[0] - p[0]))


class Slide(NamedTuple):
    """A prismatic pair: a link sliding along a line fixed to ``on`` (the ground or a
    link), through the slider's first joint as drawn, at ``angle_deg`` in the drawing."""

    on: str
    angle_deg: float


class Drawing(NamedTuple):
    xy: dict[str, tuple[float, float]]
    ground: list[str]
    links: dict[str, list[str]]
    bodies: dict[str, list[str]]
    """The links and the ground (a body of its fixed joints)."""
    points: dict[str, str]
    """A joint on one moving link and nothing else (a point on it) -> that link."""
    sliders: dict[str, Slide]
    """Each sliding link and its line."""

    def center(self, body: str) -> str:
        """The joint a body's vectors start from: its first joint that is not a point."""
        return next(j for j in self.bodies[body] if j not in self.points)


def drawing_of(doc: Mapping[str, Any], source: str = "<mechanism>") -> Drawing:
    """The checked drawing of a joints-form document: joints, ground, links as bodies,
    points and sliders (what the loads' matrix method needs)."""
    def fail(key: str, msg: str) -> ParseError:
        return ParseError(f"{source}: {key}: {msg}")

    return _read(doc, fail)


def loops_doc(doc: Mapping[str, Any], source: str = "<mechanism>") -> dict[str, Any]:
    """The loops-form document equivalent to a joints-form one (see the module)."""
    def fail(key: str, msg: str) -> ParseError:
        return ParseError(f"{source}: {key}: {msg}")

    drawing = _read(doc, fail)
    unit = doc.get("length_unit")
    dname, value = _driver(doc, drawing, fail)
    frame, unknowns = _frames(drawing, dname)
    slid = _slid(drawing, dname, unit, unknowns)
    loops_needed = _loop_count(drawing)
    if 2 * loops_needed != len(unknowns):
        raise fail("links", f"{loops_needed} independent loop(s) give {2 * loops_needed} equations "
                            f"for {len(unknowns)} unknowns ({', '.join(unknowns)})")
    sliders = drawing.sliders
    owner = {(f"s_{b}" if b in sliders else f"theta_{b}"): f"{b}'s {'travel' if b in sliders else 'angle'}"
             for b in drawing.links}
    w = _Vectors(drawing, unit, fail, frame, slid, {}, owner)
    loops = _loops(w)
    pts = {j: {"from": drawing.center(b), "vectors": [w.vector(b, drawing.center(b), j, 1)]}
           for j, b in drawing.points.items()}
    drv = {"name": dname, "value": float(value), "unit": unit if dname.startswith("s_") else "deg"}
    if isinstance(doc.get("driver"), Mapping) and "range" in doc["driver"]:
        drv["range"] = doc["driver"]["range"]  # checked as the loops form's (one rule)
    out = {"name": doc.get("name", "mechanism"), "length_unit": unit,
           "description": doc.get("description", ""),
           "origin": list(drawing.xy[drawing.ground[0]]),
           "parameters": w.params, "driver": drv, "unknowns": unknowns, "loops": loops}
    if pts:
        out["points"] = pts
    return out


Frames = dict[str, tuple[str | None, float]]
"""Each body's frame: the angle its vectors turn with (an unknown, the driver, or None for
the ground) and the drawn angle of that reference (a link's first two joints)."""


def _frames(drawing: Drawing, dname: str) -> tuple[Frames, dict[str, Any]]:
    """Each body's frame, and the unknowns: the links' angles but the driver's."""
    xy, links = drawing.xy, drawing.links
    base = {b: _angle_deg(xy[js[0]], xy[js[1]]) for b, js in links.items() if len(js) > 1}
    frame: Frames = {GROUND: (None, 0.0)}
    unknowns: dict[str, Any] = {}
    for b in links:
        if b not in drawing.sliders:
            frame[b] = (f"theta_{b}", base[b])
            if frame[b][0] != dname:
                unknowns[f"theta_{b}"] = {"guess": base[b], "unit": "deg"}
    for b, slide in drawing.sliders.items():
        frame[b] = frame[slide.on]
    return frame, unknowns


def _slid(drawing: Drawing, dname: str, unit: Any,
          unknowns: dict[str, Any]) -> dict[str, tuple[float, float]]:
    """Each slider's drawn travel and offset from its line's joint; its travel an unknown
    unless it is the driver's."""
    slid: dict[str, tuple[float, float]] = {}
    for b, slide in drawing.sliders.items():
        (jx, jy), (px, py) = drawing.xy[drawing.center(slide.on)], drawing.xy[drawing.center(b)]
        line = radians(slide.angle_deg)
        ux, uy = math.cos(line), math.sin(line)
        along, across = (px - jx) * ux + (py - jy) * uy, (py - jy) * ux - (px - jx) * uy
        if abs(across) <= 4 * EPS * math.hypot(px - jx, py - jy):
            across = 0.0  # the projection's rounding: the line passes through J0
        slid[b] = (along, across)
        if f"s_{b}" != dname:
            unknowns[f"s_{b}"] = {"guess": along, "unit": unit}
    return slid


class _Vectors(NamedTuple):
    """The loops' and points' vectors being written from a drawing: the parameters they
    name (``params``, filled as they are written) and what owns each derived name. (A
    NamedTuple, not a frozen dataclass: this module is imported by every mechanism
    command, and a frozen dataclass built at import costs about 0.5 ms against 0.05 ms.)"""

    drawing: Drawing
    unit: Any
    fail: Any
    frame: Frames
    slid: dict[str, tuple[float, float]]
    params: dict[str, Any]
    owner: dict[str, str]

    def own(self, name: str, what: str) -> None:
        """Each derived name one thing: a link named like another's derived name would
        silently share its number."""
        if self.owner.setdefault(name, what) != what:
            raise self.fail("links", f"the derived name {name} is {self.owner[name]} and {what}: rename a "
                                     "link (names: <link>, <link>_<P>_<Q>, theta_<link>, s_ and e_<slider>)")

    def angle(self, b: str, drawn_deg: float) -> dict[str, Any]:
        ref, b0 = self.frame[b]
        if ref is None:
            return {"angle": drawn_deg}
        offset = wrap_degrees(drawn_deg - b0)
        return {"angle": ref, "offset": offset} if offset else {"angle": ref}

    def vector(self, b: str, p: str, q: str, sign: int) -> dict[str, Any]:
        xy, bodies = self.drawing.xy, self.drawing.bodies
        length = math.dist(xy[p], xy[q])
        if not length > 0.0:
            raise self.fail(f"links.{b}" if b != GROUND else "ground",
                            f"joints {p} and {q} are drawn at one place")
        first_two = len(bodies[b]) > 1 and (p, q) == (bodies[b][0], bodies[b][1])
        pname = b if first_two else f"{b}_{p}_{q}"
        self.own(pname, f"the length {p} -> {q} of {b}")
        self.params[pname] = {"value": length, "unit": self.unit}
        if b == GROUND:  # a length and an angle parameter: a scan may move a ground joint
            self.own(f"theta_{pname}", f"the ground's angle {p} -> {q}")
            self.params[f"theta_{pname}"] = {"value": _angle_deg(xy[p], xy[q]), "unit": "deg"}
            return {"length": pname, "angle": f"theta_{pname}", "sign": sign}
        return {"length": pname, **self.angle(b, _angle_deg(xy[p], xy[q])), "sign": sign}

    def slide_vectors(self, b: str, forward: bool) -> tuple[list[str], list[dict[str, Any]]]:
        """A slider's edge J0 -> P: its offset across the line, then its travel along it."""
        slide = self.drawing.sliders[b]
        start, end = self.drawing.center(slide.on), self.drawing.center(b)
        line = slide.angle_deg
        self.own(f"e_{b}", f"slider {b}'s offset")
        self.params[f"e_{b}"] = {"value": self.slid[b][1], "unit": self.unit, "signed": True}
        e = {"length": f"e_{b}", **self.angle(slide.on, wrap_degrees(line + 90.0))}
        s = {"length": f"s_{b}", **self.angle(slide.on, line)}
        if forward:
            return [start, ""], [{**e, "sign": 1}, {**s, "sign": 1}]
        return [end, ""], [{**s, "sign": -1}, {**e, "sign": -1}]


def _loops(w: _Vectors) -> list[dict[str, Any]]:
    """One loop per cycle of the joint-link graph, its vectors written by ``w``."""
    drawing, sliders = w.drawing, w.drawing.sliders
    edges: list[tuple[str, str, str]] = []  # (body, from joint, to joint)
    for b, js in drawing.bodies.items():
        c = drawing.center(b)
        edges += [(b, c, j) for j in js if j != c and j not in drawing.points]
    edges += [(b, drawing.center(slide.on), drawing.center(b)) for b, slide in sliders.items()]
    loops = []
    for cycle in _placed_in_order(_cycles(edges, drawing.ground[0]), drawing.ground):
        names, vecs = [], []
        for (b, p, q), forward in cycle:
            if b in sliders and (p, q) == (drawing.center(sliders[b].on), drawing.center(b)):
                n, v = w.slide_vectors(b, forward)
            else:
                n, v = [p if forward else q], [w.vector(b, p, q, 1 if forward else -1)]
            names += n
            vecs += v
        loops.append({"name": "-".join(n for n in names if n), "joints": names, "vectors": vecs})
    return loops


EPS = 2.220446049250313e-16


def _driver(doc: Mapping[str, Any], d: Drawing, fail: Any) -> tuple[str, float]:
    """The driver's derived name and its value: [driver] value, or the drawn one when it
    is left out (:func:`drawn_driver`)."""
    drv = doc.get("driver")
    if not isinstance(drv, Mapping):
        raise fail("driver", "missing: [driver] link = NAME (an angle) or slider = NAME (a travel)")
    for key in drv:
        if key not in ("link", "slider", "value", "range"):
            raise fail(f"driver.{key}", "unknown key (expected link or slider, value and range)")
    if ("link" in drv) == ("slider" in drv):
        raise fail("driver", "name one: link = NAME (its angle) or slider = NAME (its travel)")
    value = drv.get("value")
    if value is not None and not _number(value):
        raise fail("driver.value", "must be a finite number (degrees for a link, the length "
                                   "unit for a slider)")
    if "slider" in drv:
        s = drv["slider"]
        if not isinstance(s, str) or s not in d.sliders:
            raise fail("driver.slider", f"must name a slider (sliders: {', '.join(d.sliders) or 'none'})")
        if d.sliders[s].on != GROUND:
            raise fail("driver.slider", f"{s} slides on {d.sliders[s].on}: a driving slider runs on "
                                        "the ground")
        return f"s_{s}", drawn_driver(d, drv) if value is None else float(value)
    link = drv["link"]
    if not isinstance(link, str) or link not in d.links:
        raise fail("driver.link", f"must name a link (links: {', '.join(d.links)})")
    if link in d.sliders:
        raise fail("driver.link", f"{link} slides: drive it by its travel, [driver] slider = \"{link}\"")
    js = d.links[link]
    if js[0] not in d.ground:
        fixed = ", ".join(j for j in js if j in d.ground) or "none of its joints is"
        raise fail("driver.link", f"{link} must turn about a ground joint: list it first ({fixed} fixed)")
    return f"theta_{link}", drawn_driver(d, drv) if value is None else float(value)


def drawn_driver(d: Drawing, driver: Mapping[str, Any]) -> float:
    """Where the drawing puts its (checked) driver: a link's angle first joint -> second
    (deg), or a slider's travel from the foot of the ground's first joint on its line."""
    if "slider" in driver:
        s = driver["slider"]
        (jx, jy), (px, py) = d.xy[d.center(GROUND)], d.xy[d.center(s)]
        t = radians(d.sliders[s].angle_deg)
        return (px - jx) * math.cos(t) + (py - jy) * math.sin(t)
    js = d.links[driver["link"]]
    return _angle_deg(d.xy[js[0]], d.xy[js[1]])


def off_drawing(d: Drawing, driver: Mapping[str, Any], value: float) -> float | None:
    """The drawn driver value when [driver] ``value`` is not it (beyond the drawing's
    rounding: :data:`DRIVER_TOLERANCE_DEG`, or :data:`DRIVER_TOLERANCE_LENGTH` of the
    drawing's size), else None. An angle is compared a whole turn apart as the same."""
    drawn = drawn_driver(d, driver)
    if "slider" in driver:
        scale = max(math.dist(d.xy[d.ground[0]], p) for p in d.xy.values()) or 1.0
        return drawn if abs(value - drawn) > DRIVER_TOLERANCE_LENGTH * scale else None
    return drawn if abs(wrap_degrees(value - drawn)) > DRIVER_TOLERANCE_DEG else None


def _read(doc: Mapping[str, Any], fail: Any) -> Drawing:
    """The drawing's joints, ground, links, sliders and points, checked: every name known
    and used, the bodies connected, and the mobility 1."""
    xy, ground = _joints(doc, fail)
    links_doc, sliders_doc = doc.get("links"), doc.get("sliders", {})
    if not isinstance(links_doc, Mapping) or not links_doc:
        raise fail("links", "must be a table of link = [joints]")
    if not isinstance(sliders_doc, Mapping):
        raise fail("sliders", "must be a table of link = { on = BODY, angle = DEG } or { on, line = [P, Q] }")
    links = _links(links_doc, sliders_doc, xy, ground, fail)
    bodies = {GROUND: list(ground), **links}
    sliders = _sliders(sliders_doc, bodies, xy, fail)
    at: dict[str, list[str]] = {j: [] for j in xy}
    for b, js in bodies.items():
        for j in js:
            at[j].append(b)
    # a fixed joint on no link is a slip, unless it marks a slider's line
    lines = {j for v in sliders_doc.values() if isinstance(v, Mapping) for j in v.get("line", [])}
    loose = [j for j, bs in at.items() if not [b for b in bs if b != GROUND] and j not in lines]
    if loose:
        raise fail(f"joints.{loose[0]}", "is on no link" + (" (a fixed joint carries a link)"
                                                           if at[loose[0]] else ""))
    # before the mobility: a part apart from the ground has its own, which would mislead
    _connected(bodies, at, sliders, fail)

    # coupler points: a joint on one moving link and nothing else, drawn on it (a slider's
    # first joint is its pin on the line, never a point)
    points = {j: bs[0] for j, bs in at.items()
              if len(bs) == 1 and bs[0] != GROUND and not (bs[0] in sliders and bodies[bs[0]][0] == j)}
    _check_mobility(bodies, at, sliders, fail)
    return Drawing(xy, list(ground), links, bodies, points, sliders)


def _joints(doc: Mapping[str, Any], fail: Any) -> tuple[dict[str, tuple[float, float]], list[str]]:
    """The file's keys, its joints (x, y) and its fixed joints, checked."""
    allowed = {"name", "description", "length_unit", "ground", "joints", "links", "sliders",
               "driver", "notes", "loads", "mass"}
    for key in doc:
        if key not in allowed:
            raise fail(key, f"unknown key in a joints file (expected one of {', '.join(sorted(allowed))})")
    joints_doc, links_doc = doc.get("joints"), doc.get("links")
    if not isinstance(joints_doc, Mapping) or not joints_doc:
        raise fail("joints", "must be a table of joint = [x, y]")
    for key, table in (("joints", joints_doc), ("links", links_doc)):
        if isinstance(table, Mapping) and len(table) > MAX_JOINTS:
            raise fail(key, f"{len(table):,} entries; at most {MAX_JOINTS:,} are accepted, far above "
                            "any real mechanism")
    for key, table in (("joints", joints_doc), ("links", links_doc)):
        if isinstance(table, Mapping) and "" in table:  # "" is a loop's unnamed point (a foot)
            raise fail(key, '"" is no name: give each a name')
    xy: dict[str, tuple[float, float]] = {}
    for name, p in joints_doc.items():
        if (not isinstance(p, list) or len(p) != 2 or
                not all(_number(v) for v in p)):
            raise fail(f"joints.{name}", "must be [x, y]: two finite numbers in the file's length_unit")
        xy[str(name)] = (float(p[0]), float(p[1]))
    ground = doc.get("ground")
    if not isinstance(ground, list) or not ground or not all(isinstance(g, str) for g in ground):
        raise fail("ground", "must list the fixed joints, e.g. [\"O2\", \"O4\"]")
    for g in ground:
        if g not in xy:
            raise fail("ground", f"{g!r} is not a joint (joints: {', '.join(xy)})")
    if len(set(ground)) != len(ground):
        raise fail("ground", "names a joint twice")
    return xy, ground


def _links(links_doc: Mapping[str, Any], sliders_doc: Mapping[str, Any], xy: Mapping[str, Any],
           ground: list[str], fail: Any) -> dict[str, list[str]]:
    """``[links]``: each a list of known joints, not all fixed (a slider may have one)."""
    links: dict[str, list[str]] = {}
    for name, js in links_doc.items():
        key = f"links.{name}"
        if name == GROUND:
            raise fail(key, "the ground is listed under ground = [...], not as a link")
        least = 1 if name in sliders_doc else 2
        if not isinstance(js, list) or len(js) < least or not all(isinstance(j, str) for j in js):
            raise fail(key, "must list at least two joints, e.g. [\"O2\", \"A\"] (a slider, one)")
        if len(js) > MAX_JOINTS:
            raise fail(key, f"{len(js):,} joints; at most {MAX_JOINTS:,} are accepted")
        for j in js:
            if j not in xy:
                raise fail(key, f"{j!r} is not a joint (joints: {', '.join(xy)})")
        if len(set(js)) != len(js):
            raise fail(key, "names a joint twice")
        if all(j in ground for j in js):
            raise fail(key, "every joint of it is fixed: it is part of the ground")
        links[str(name)] = list(js)
    return links


def _check_mobility(bodies: Mapping[str, list[str]], at: Mapping[str, list[str]],
                    sliders: Mapping[str, Slide], fail: Any) -> None:
    """Mobility 1 (Gruebler-Kutzbach): 3 (n - 1) - 2 j1, a joint shared by k bodies being
    k - 1 revolute pairs, and each slider one prismatic pair."""
    n = len(bodies)
    revolute = sum(len(bs) - 1 for bs in at.values())
    pairs = revolute + len(sliders)
    mobility = 3 * (n - 1) - 2 * pairs
    if mobility != 1:
        what = ("this is a structure" if mobility == 0 else "it is overconstrained" if mobility < 0
                else f"name {mobility - 1} more driver{'s' if mobility > 2 else ''}")
        kinds = f"{revolute} revolute" + (f" and {len(sliders)} sliding" if sliders else "")
        raise fail("links", f"mobility {mobility} ({n} bodies with the ground, {kinds} pairs: "
                            f"3 x {n - 1} - 2 x {pairs}): {what}; a joints file needs mobility 1")


def _sliders(spec: Mapping[str, Any], bodies: Mapping[str, list[str]],
             xy: Mapping[str, tuple[float, float]], fail: Any) -> dict[str, Slide]:
    """``[sliders]``: each a link that slides along a line fixed to the ground or a link."""
    out: dict[str, Slide] = {}
    for name, s in spec.items():
        key = f"sliders.{name}"
        if name not in bodies or name == GROUND:
            raise fail(key, f"must be a link (links: {', '.join(b for b in bodies if b != GROUND)})")
        if not isinstance(s, Mapping):
            raise fail(key, "must be { on = BODY, angle = DEG } or { on = BODY, line = [P, Q] }")
        for k in s:
            if k not in ("on", "angle", "line"):
                raise fail(f"{key}.{k}", "unknown key (expected on, and angle or line)")
        on = s.get("on")
        if not isinstance(on, str) or on not in bodies or on == name:
            others = ", ".join(b for b in bodies if b not in (GROUND, name))
            raise fail(f"{key}.on", f"must name the body its line is fixed to: \"ground\" or another "
                                    f"link (links: {others})")
        if on in spec:
            raise fail(f"{key}.on", f"{on} slides itself: a line must be fixed to the ground or a "
                                    "turning link")
        if bodies[name][0] in bodies[on]:
            raise fail(key, f"its first joint {bodies[name][0]} is on {on} too: it cannot both turn on "
                            "and slide along it")
        if ("angle" in s) == ("line" in s):
            raise fail(key, "a slider needs its line: angle = DEG (its direction as drawn) or "
                            f"line = [P, Q] (parallel to two joints of {on})")
        if "angle" in s:
            a = s["angle"]
            if not _number(a) or abs(a) > 1e6:
                raise fail(f"{key}.angle", "must be a finite number of degrees (the line's direction "
                                           "as drawn)")
            angle = float(a)
        else:
            line = s["line"]
            if (not isinstance(line, list) or len(line) != 2 or not all(isinstance(j, str) for j in line)
                    or not all(j in bodies[on] for j in line)):
                raise fail(f"{key}.line", f"must be two joints of {on} ({', '.join(bodies[on])}): "
                                          "the line runs parallel to them")
            if xy[line[0]] == xy[line[1]]:
                raise fail(f"{key}.line", f"{line[0]} and {line[1]} are drawn at one place: no direction")
            angle = _angle_deg(xy[line[0]], xy[line[1]])
        out[str(name)] = Slide(on, angle)
    return out


def _loop_count(d: Drawing) -> int:
    joints = {j for js in d.bodies.values() for j in js if j not in d.points}
    edges = sum(len([j for j in js if j not in d.points]) - 1 for js in d.bodies.values())
    return edges + len(d.sliders) - len(joints) + 1


def _connected(bodies: Mapping[str, list[str]], at: Mapping[str, list[str]],
               sliders: Mapping[str, Slide], fail: Any) -> None:
    seen = {GROUND}
    todo = [GROUND]
    while todo:
        b = todo.pop()
        near = [other for j in bodies[b] for other in at[j]]
        near += [s for s, slide in sliders.items() if slide.on == b]
        near += [sliders[b].on] if b in sliders else []
        for other in near:
            if other not in seen:
                seen.add(other)
                todo.append(other)
    apart = [b for b in bodies if b not in seen]
    if apart:
        raise fail(f"links.{apart[0]}", "is not connected to the ground through the other links")


Cycle = list[tuple[tuple[str, str, str], bool]]


def _placed_in_order(cycles: list[Cycle], ground: list[str]) -> list[Cycle]:
    """The loops ordered and each turned to start at a joint an earlier loop placed (the
    first at the ground's first joint, a fixed joint wherever one is placed), so that the
    loops place every joint from the drawing's origin onwards."""
    placed = {ground[0]}
    out: list[Cycle] = []
    todo = list(cycles)
    while todo:
        k = next((i for i, c in enumerate(todo)
                  if any((p if fwd else q) in placed for (_, p, q), fwd in c)), 0)
        cycle = todo.pop(k)
        starts = [p if fwd else q for (_, p, q), fwd in cycle]
        first = next((i for i, j in enumerate(starts) if j == ground[0]),
                     next((i for i, j in enumerate(starts) if j in ground and j in placed),
                          next((i for i, j in enumerate(starts) if j in placed), 0)))
        out.append(cycle[first:] + cycle[:first])
        placed.update(starts)
    return out


def _cycles(edges: list[tuple[str, str, str]], root: str) -> list[Cycle]:
    """A fundamental cycle basis: a spanning tree by breadth-first search from ``root``, and
    for each edge not in it, the edge followed by the tree path back to its start. Each
    cycle is a list of (edge, forward) in order around the loop."""
    adjacent: dict[str, list[tuple[int, str, bool]]] = {}
    for k, (_, p, q) in enumerate(edges):
        adjacent.setdefault(p, []).append((k, q, True))
        adjacent.setdefault(q, []).append((k, p, False))
    parent: dict[str, tuple[int, str, bool] | None] = {root: None}
    order = [root]
    tree: set[int] = set()
    for node in order:
        for k, other, forward in adjacent.get(node, []):
            if other not in parent:
                parent[other] = (k, node, forward)  # reached from node along edge k
                tree.add(k)
                order.append(other)

    def up(node: str) -> list[tuple[int, bool, str]]:
        """The tree path from ``node`` to the root: (edge, forward as walked, next node)."""
        path = []
        while parent[node] is not None:
            k, prev, forward = parent[node]  # type: ignore[misc]
            path.append((k, not forward, prev))
            node = prev
        return path

    cycles = []
    for k, (_, p, q) in enumerate(edges):
        if k in tree:
            continue
        # p -> q along edge k, then q back to p through the tree (up to their common ancestor)
        from_q, from_p = up(q), up(p)
        on_p = {p, *(n for _, _, n in from_p)}
        walk = []
        node = q
        i = 0
        while node not in on_p:
            kk, fwd, nxt = from_q[i]
            walk.append((edges[kk], fwd))
            node, i = nxt, i + 1
        meet = node
        down = []
        node = p
        for kk, fwd, nxt in from_p:
            if node == meet:
                break
            down.append((edges[kk], not fwd))
            node = nxt
        cycles.append([(edges[k], True), *walk, *reversed(down)])
    return cycles
