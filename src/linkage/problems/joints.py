"""A mechanism from its drawing: joints with coordinates, links as lists of joints, a
driver link. Derives what the loops form states by hand: each link's lengths and the
fixed angles inside it, the mobility (Gruebler-Kutzbach) and the independent loops (a
cycle basis of the joint-link graph), and hands :func:`~.loops.parse_mechanism` the
equivalent loops-form document, so everything downstream works unchanged.

This is the core of issue 21, revolute joints only (sliders, converting a loops file back
to joints and ``linkage new`` are to come); :func:`loops_text` is ``linkage convert``. The shape of the file::

    name = "Norton four-bar"
    length_unit = "mm"
    ground = ["O2", "O4"]          # fixed joints
    [joints]                       # one pose, in length_unit
    O2 = [0, 0]
    A  = [30.642, 25.712]
    B  = [...]
    O4 = [100, 0]
    [links]
    crank   = ["O2", "A"]
    coupler = ["A", "B", "P"]      # a ternary link; P, on nothing else, is a coupler point
    rocker  = ["B", "O4"]
    [driver]
    link = "crank"                 # its angle at its first joint, degrees
    value = 40                     # the drawn pose is at this value

Each link's angle is the angle of the line from its first joint to its second, as drawn
and as it moves; its other joints are fixed in it by their drawn offsets. The driver
value must be the driver link's drawn angle.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

from ..errors import ParseError
from .closed_form import wrap_degrees

GROUND = "ground"
DRIVER_TOLERANCE_DEG = 1e-6
"""How far the drawn driver angle may be from [driver] value (the drawing's rounding)."""


def is_joints_doc(doc: Mapping[str, Any]) -> bool:
    return "joints" in doc and "links" in doc and "loops" not in doc


def _angle_deg(p: tuple[float, float], q: tuple[float, float]) -> float:
    return math.degrees(math.atan2(q[1] - p[1], q[0] - p[0]))


def loops_doc(doc: Mapping[str, Any], source: str = "<mechanism>") -> dict[str, Any]:
    """The loops-form document equivalent to a joints-form one (see the module)."""
    def fail(key: str, msg: str) -> ParseError:
        return ParseError(f"{source}: {key}: {msg}")

    xy, ground, links, bodies, points = _read(doc, fail)

    drv = doc.get("driver")
    if not isinstance(drv, Mapping) or not isinstance(drv.get("link"), str) or drv["link"] not in links:
        raise fail("driver", f"must name a link: [driver] link = one of {', '.join(links)}")
    dlink = drv["link"]
    if links[dlink][0] not in ground:
        fixed = ", ".join(j for j in links[dlink] if j in ground) or "none of its joints is"
        raise fail("driver.link", f"{dlink} must turn about a ground joint: list it first ({fixed} fixed)")
    drawn = _angle_deg(xy[links[dlink][0]], xy[links[dlink][1]])
    value = drv.get("value", drawn)
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise fail("driver.value", "must be a finite number of degrees")
    if abs(wrap_degrees(value - drawn)) > DRIVER_TOLERANCE_DEG:
        raise fail("driver.value", f"{value:g} deg, but {dlink} is drawn at {drawn:.9g} deg "
                                   f"({links[dlink][0]} -> {links[dlink][1]})")

    unit = doc.get("length_unit")
    params: dict[str, Any] = {}
    unknowns: dict[str, Any] = {}
    angle_of: dict[str, Any] = {GROUND: None, dlink: f"theta_{dlink}"}
    base = {b: _angle_deg(xy[js[0]], xy[js[1]]) for b, js in bodies.items()}
    for b in links:
        if b != dlink:
            angle_of[b] = f"theta_{b}"
            unknowns[f"theta_{b}"] = {"guess": base[b], "unit": "deg"}
    if 2 * _loop_count(bodies, points) != len(unknowns):
        raise fail("links", f"{_loop_count(bodies, points)} independent loop(s) give "
                            f"{2 * _loop_count(bodies, points)} equations for {len(unknowns)} link angles")

    # each body a star from its first joint: the edge to each other joint (points aside)
    edges: list[tuple[str, str, str]] = []  # (body, from joint, to joint)
    for b, js in bodies.items():
        for j in js[1:]:
            if j not in points:
                edges.append((b, js[0], j))

    def vector(b: str, p: str, q: str, sign: int) -> dict[str, Any]:
        length = math.dist(xy[p], xy[q])
        if not length > 0.0:
            raise fail(f"links.{b}" if b != GROUND else "ground",
                       f"joints {p} and {q} are drawn at one place")
        pname = b if q == bodies[b][1] else f"{b}_{p}_{q}"
        params[pname] = {"value": length, "unit": unit}
        offset = wrap_degrees(_angle_deg(xy[p], xy[q]) - base[b])
        out: dict[str, Any] = {"length": pname, "sign": sign}
        if angle_of[b] is None:
            out["angle"] = _angle_deg(xy[p], xy[q])
        else:
            out["angle"] = angle_of[b]
            if offset:
                out["offset"] = offset
        return out

    loops = []
    for cycle in _cycles(edges, ground[0]):
        # start at a fixed joint (the root if the loop has it): the joints are then placed
        # as drawn, the first loop's first joint at the origin of the drawing's frame
        starts = [p if fwd else q for (_, p, q), fwd in cycle]
        first = next((k for k, j in enumerate(starts) if j == ground[0]),
                     next((k for k, j in enumerate(starts) if j in ground), 0))
        cycle = cycle[first:] + cycle[:first]
        names, vecs = [], []
        for (b, p, q), forward in cycle:
            start = p if forward else q
            names.append(start)
            vecs.append(vector(b, p, q, 1 if forward else -1))
        loops.append({"name": "-".join(names), "joints": names, "vectors": vecs})
    pts = {}
    for j, b in points.items():
        pts[j] = {"from": bodies[b][0], "vectors": [vector(b, bodies[b][0], j, 1)]}
    out = {"name": doc.get("name", "mechanism"), "length_unit": unit,
           "description": doc.get("description", ""),
           "parameters": params,
           "driver": {"name": f"theta_{dlink}", "value": float(value), "unit": "deg"},
           "unknowns": unknowns, "loops": loops}
    if pts:
        out["points"] = pts
    return out


class Drawing(NamedTuple):
    xy: dict[str, tuple[float, float]]
    ground: list[str]
    links: dict[str, list[str]]
    bodies: dict[str, list[str]]
    """The links and the ground (a body of its fixed joints)."""
    points: dict[str, str]
    """A joint on one moving link and nothing else (a point on it) -> that link."""


def _read(doc: Mapping[str, Any], fail: Any) -> Drawing:
    """The drawing's joints, ground, links and points, checked: every name known and
    used, the bodies connected, and the mobility 1."""
    allowed = {"name", "description", "length_unit", "ground", "joints", "links", "driver", "notes"}
    for key in doc:
        if key not in allowed:
            raise fail(key, f"unknown key in a joints file (expected one of {', '.join(sorted(allowed))})")
    joints_doc, links_doc = doc["joints"], doc["links"]
    if not isinstance(joints_doc, Mapping) or not joints_doc:
        raise fail("joints", "must be a table of joint = [x, y]")
    xy: dict[str, tuple[float, float]] = {}
    for name, p in joints_doc.items():
        if (not isinstance(p, list) or len(p) != 2 or
                not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                        for v in p)):
            raise fail(f"joints.{name}", "must be [x, y]: two finite numbers in the file's length_unit")
        xy[str(name)] = (float(p[0]), float(p[1]))
    ground = doc.get("ground")
    if not isinstance(ground, list) or len(ground) < 2 or not all(isinstance(g, str) for g in ground):
        raise fail("ground", "must list at least two fixed joints, e.g. [\"O2\", \"O4\"]")
    for g in ground:
        if g not in xy:
            raise fail("ground", f"{g!r} is not a joint (joints: {', '.join(xy)})")
    if len(set(ground)) != len(ground):
        raise fail("ground", "names a joint twice")
    if not isinstance(links_doc, Mapping) or not links_doc:
        raise fail("links", "must be a table of link = [joints]")
    links: dict[str, list[str]] = {}
    for name, js in links_doc.items():
        key = f"links.{name}"
        if name == GROUND:
            raise fail(key, "the ground is listed under ground = [...], not as a link")
        if not isinstance(js, list) or len(js) < 2 or not all(isinstance(j, str) for j in js):
            raise fail(key, "must list at least two joints, e.g. [\"O2\", \"A\"]")
        for j in js:
            if j not in xy:
                raise fail(key, f"{j!r} is not a joint (joints: {', '.join(xy)})")
        if len(set(js)) != len(js):
            raise fail(key, "names a joint twice")
        if all(j in ground for j in js):
            raise fail(key, "every joint of it is fixed: it is part of the ground")
        links[str(name)] = list(js)
    bodies = {GROUND: list(ground), **links}
    at: dict[str, list[str]] = {j: [b for b, js in bodies.items() if j in js] for j in xy}
    loose = [j for j, bs in at.items() if not bs]
    if loose:
        raise fail(f"joints.{loose[0]}", "is on no link")

    # coupler points: a joint on one moving link and nothing else, drawn on it
    points = {j: bs[0] for j, bs in at.items() if len(bs) == 1 and bs[0] != GROUND}
    # mobility (Gruebler-Kutzbach): 3 (n - 1) - 2 j1, a joint shared by k bodies being k - 1 pairs
    n = len(bodies)
    pairs = sum(len(bs) - 1 for bs in at.values())
    mobility = 3 * (n - 1) - 2 * pairs
    if mobility != 1:
        what = ("this is a structure" if mobility == 0 else "it is overconstrained" if mobility < 0
                else f"name {mobility - 1} more driver{'s' if mobility > 2 else ''}")
        raise fail("links", f"mobility {mobility} ({n} bodies with the ground, {pairs} revolute pairs: "
                            f"3 x {n - 1} - 2 x {pairs}): {what}; a joints file needs mobility 1")
    _connected(bodies, at, fail)
    return Drawing(xy, list(ground), links, bodies, points)


def _loop_count(bodies: Mapping[str, list[str]], points: Mapping[str, str]) -> int:
    joints = {j for js in bodies.values() for j in js if j not in points}
    edges = sum(len([j for j in js[1:] if j not in points]) for js in bodies.values())
    return edges - len(joints) + 1


def _connected(bodies: Mapping[str, list[str]], at: Mapping[str, list[str]], fail: Any) -> None:
    seen = {GROUND}
    todo = [GROUND]
    while todo:
        b = todo.pop()
        for j in bodies[b]:
            for other in at[j]:
                if other not in seen:
                    seen.add(other)
                    todo.append(other)
    apart = [b for b in bodies if b not in seen]
    if apart:
        raise fail(f"links.{apart[0]}", "is not connected to the ground through the other links")


def _cycles(edges: list[tuple[str, str, str]], root: str) -> list[list[tuple[tuple[str, str, str], bool]]]:
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


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v).__name__)


def loops_text(doc: Mapping[str, Any], source: str = "<mechanism>") -> str:
    """The derived loops-form file of a drawing, as TOML text: each loop under a comment
    naming its joints, so the loop-closure equations the drawing implies can be read."""
    d = loops_doc(doc, source)
    out = [f"# the vector loops of {source}, derived from its joints and links (linkage convert)",
           f"name = {_toml_value(d['name'])}"]
    if d.get("description"):
        out.append(f"description = {_toml_value(d['description'])}")
    out += [f"length_unit = {_toml_value(d['length_unit'])}", "", "[parameters]  # the drawn lengths"]
    out += [f"{k} = {_toml_value(v)}" for k, v in d["parameters"].items()]
    out += ["", "[driver]"] + [f"{k} = {_toml_value(v)}" for k, v in d["driver"].items()]
    out += ["", "[unknowns]  # each moving link's angle, guessed from the drawing"]
    out += [f"{k} = {_toml_value(v)}" for k, v in d["unknowns"].items()]
    for loop in d["loops"]:
        names = loop["joints"]
        out += ["", f"# {' -> '.join([*names, names[0]])}: the sum of these vectors is zero",
                "[[loops]]", f"name = {_toml_value(loop['name'])}", f"joints = {_toml_value(names)}",
                "vectors = ["]
        out += [f"  {_toml_value(v)},  # {a} -> {b}"
                for v, a, b in zip(loop["vectors"], names, [*names[1:], names[0]])]
        out.append("]")
    for name, p in d.get("points", {}).items():
        out += ["", f"[points.{name}]  # on a link, nothing else attached",
                f"from = {_toml_value(p['from'])}", f"vectors = {_toml_value(p['vectors'])}"]
    return "\n".join(out) + "\n"
