"""CAD export of one pose: ``linkage draw FILE -o pose.dxf`` or ``-o pose.svg`` (docs/plots.md).

The sheet (:class:`Sheet`) holds, in the file's length unit and at the solved joint
coordinates exactly (no rounding, no scaling): each body (the ground and every link) as
a polyline through its joints, closed for a link of three or more; each slider's line
and block; the joints (the ground pivots marked); and the coupler curves, the paths of
the file's ``[points]`` over a sweep of the driver, broken wherever the sweep has no
solution on the followed assembly (a gap is never bridged by a straight stroke).

- DXF through ezdxf (the ``cad`` extra, imported only here when a .dxf is written): a
  layer per body (``GROUND``, ``LINK_<name>``), joints as circles with text labels on
  ``JOINTS``, the coupler curves as LWPOLYLINEs on ``PATHS`` (their vertices are the
  solved positions themselves, which a fitted SPLINE would not pass through), and
  ``$INSUNITS`` from the file's length_unit.
- SVG written directly as XML: matplotlib's SVG places everything in points (1/72 in) of
  a figure, flipped and offset by the axes, and prints coordinates with six decimals, so
  neither the file's unit nor 1e-9 of it survives. Here one user unit is one unit of the
  file, the viewBox holds the sheet, and width/height carry the unit where SVG has it
  (mm, cm, in); a file in m or ft gets width/height in mm or in, scaled and said so in a
  comment and the ``<desc>``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import radians

SUFFIXES = (".dxf", ".svg")
"""The suffixes that ``draw -o`` writes as CAD sheets (the rest go to matplotlib)."""

INSUNITS = {"in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}
"""DXF $INSUNITS codes of the files' length units (AutoCAD DXF reference, HEADER section);
0 is unitless."""

SVG_UNITS = {"mm": ("mm", 1.0), "cm": ("cm", 1.0), "in": ("in", 1.0), "m": ("mm", 1000.0),
             "ft": ("in", 12.0)}
"""Each length unit's SVG width/height unit and how many of them one file unit is: SVG
has mm, cm and in (SVG 1.1, section 7.10), not m or ft."""

CAD_EXTRA = "pip install 'linkage-kinematics[cad]'"

Point = tuple[float, float]


@frozen
class Body:
    """A body's outline at the pose: ``role`` is ground, driven or link."""

    name: str
    layer: str
    points: tuple[Point, ...]
    closed: bool
    role: str

    def drawn(self) -> bool:
        """A body of one place (a ground of one pivot, a slider block's pin) has no outline:
        its layer holds its other marks (the pivot, the block)."""
        return any(p != self.points[0] for p in self.points)


@frozen
class SlideMark:
    """A slider's line (on the layer of the body it is fixed to) and its block (on its own)."""

    name: str
    line_layer: str
    line: tuple[Point, Point]
    layer: str
    block: tuple[Point, Point, Point, Point]


@frozen
class Mark:
    """A named joint (``kind`` joint or ground) or point (``kind`` point) at the pose; an
    unnamed loop corner has the name ""."""

    name: str
    xy: Point
    kind: str


@frozen
class Curve:
    """A point's path over the sweep: one polyline per stretch the sweep solved."""

    name: str
    pieces: tuple[tuple[Point, ...], ...]


@frozen
class Sheet:
    title: str
    unit: str
    bodies: tuple[Body, ...]
    slides: tuple[SlideMark, ...]
    marks: tuple[Mark, ...]
    curves: tuple[Curve, ...]
    sweep_note: str
    """The driver range the curves cover, e.g. "theta2 from 0 to 360 deg in 360 steps"."""

    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of everything drawn."""
        pts = [p for b in self.bodies for p in b.points] + [m.xy for m in self.marks] + [
            p for s in self.slides for p in (*s.line, *s.block)] + [
            p for c in self.curves for piece in c.pieces for p in piece]
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]
        return min(xs), min(ys), max(xs), max(ys)

    def size(self) -> float:
        """The sheet's scale (its larger side): symbols and text are sized from it."""
        x0, y0, x1, y1 = self.extent()
        size = max(x1 - x0, y1 - y0)
        return size if size > 0 else max(abs(x0), abs(y0), 1.0)


def require_ezdxf() -> None:
    """Refuse a .dxf before any work when ezdxf is missing: one line naming the extra."""
    import importlib.util

    if importlib.util.find_spec("ezdxf") is None:
        raise InputError(f"a .dxf needs ezdxf: {CAD_EXTRA}")


# --- the sheet ----------------------------------------------------------------------------------


def layer_names(bodies: Iterable[str]) -> dict[str, str]:
    """Each body's DXF layer: ``GROUND`` or ``LINK_<name>``, the name's characters that a
    layer name may not hold (``<>/\\":;?*|=,`` and controls) as ``_``, and a suffix where
    two would be the same layer (layer names are case-insensitive)."""
    taken = {"0", "DEFPOINTS", "GROUND", "JOINTS", "PATHS"}
    out: dict[str, str] = {}
    for body in bodies:
        if body == "ground":
            out[body] = "GROUND"
            continue
        base = "LINK_" + re.sub(r"[^A-Za-z0-9_.\-]", "_", body)[:200]
        name, k = base, 2
        while name.upper() in taken:
            name, k = f"{base}-{k}", k + 1
        taken.add(name.upper())
        out[body] = name
    return out


def sheet(mechanism: Any, q: Sequence[float], sweep: Any = None, sweep_note: str = "") -> Sheet:
    """The sheet of ``mechanism`` at the unknowns ``q`` (internal units) and its file's
    driver value; ``sweep``: a sweep with joints (``linkage.sweep(..., joints=True)``)
    whose positions give the coupler curves and the sliders' travel."""
    from ..kinematics.placing import place

    placed = {k: (v[0].real, v[0].imag) for k, v in place(mechanism.model, q, mechanism.driver.value).items()}
    drawing = _drawing(mechanism)
    swept = [p for p in sweep.positions] if sweep is not None else []
    if drawing is None:
        bodies, slides, marks = _vectors_only(mechanism, q)
    else:
        bodies, slides = _bodies(mechanism, drawing, placed, swept)
        points = set(mechanism.points)
        ground = set(drawing.ground)
        marks = tuple(Mark(name, xy, "point" if name in points else "ground" if name in ground else "joint")
                      for name, xy in placed.items())
    curves = tuple(Curve(name, curve_pieces(swept, name)) for name in mechanism.points) if swept else ()
    return Sheet(mechanism.name, mechanism.length_unit, bodies, slides, marks, curves, sweep_note)


def needs_sweep(mechanism: Any) -> bool:
    """A sheet needs a sweep for its coupler curves (the file's points) and for how far its
    sliders' lines reach."""
    if mechanism.points:
        return True
    drawing = _drawing(mechanism)
    return drawing is not None and bool(drawing.sliders)


def curve_pieces(positions: Sequence[Any], name: str) -> tuple[tuple[Point, ...], ...]:
    """The path of joint or point ``name`` over sweep positions, as the runs of solved
    positions: a position without a solution ends a run, and so does a re-entry on the
    other assembly (the sweep plot breaks its lines at the same places:
    :func:`.plots.sweep_plot`). A run of one position is no curve and is left out."""
    from ..kinematics.continuation import REENTERED

    pieces: list[tuple[Point, ...]] = []
    run: list[Point] = []
    for p in positions:
        solved = p.rates is not None and p.status == "converged"
        if run and (not solved or p.note == REENTERED):
            pieces.append(tuple(run))
            run = []
        if solved:
            run.append(tuple(p.rates.joints[name]))
    pieces.append(tuple(run))
    return tuple(piece for piece in pieces if len(piece) > 1)


def _drawing(mechanism: Any) -> Any:
    """The joints-form drawing (bodies, sliders) of the file, or for a loops-form file the
    one ``linkage convert --form joints`` derives; None where its loops name no joints."""
    drawing = mechanism.extra.get("drawing")
    if drawing is not None:
        return drawing
    from ..kinematics.to_joints import joints_doc
    from ..problems.joints import drawing_of

    try:
        return drawing_of(joints_doc(mechanism), mechanism.source)
    except InputError:
        return None


def _driven(mechanism: Any) -> str | None:
    """The body the driver turns or slides."""
    doc = mechanism.extra.get("drawing_driver")
    if doc is not None:
        return doc.get("link") or doc.get("slider")
    from ..problems.to_joints import link_name, slider_name

    name = mechanism.driver.name
    return link_name(name) if mechanism.driver.kind == "angle" else slider_name(name)


def _bodies(mechanism: Any, drawing: Any, placed: Mapping[str, Point], swept: Sequence[Any]
            ) -> tuple[tuple[Body, ...], tuple[SlideMark, ...]]:
    layers = layer_names(drawing.bodies)
    driven = _driven(mechanism)
    bodies = []
    for name, joints in drawing.bodies.items():
        pts = tuple(placed[j] for j in joints)
        role = "ground" if name == "ground" else "driven" if name == driven else "link"
        bodies.append(Body(name, layers[name], pts, len(pts) >= 3, role))
    size = _span(list(placed.values()))
    slides = tuple(_slide(drawing, name, placed, swept, layers, size) for name in drawing.sliders)
    return tuple(bodies), slides


def _span(points: Sequence[Point]) -> float:
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    span = max(max(xs) - min(xs), max(ys) - min(ys))
    return span if span > 0 else max(max(map(abs, xs)), max(map(abs, ys)), 1.0)


def _slide(drawing: Any, name: str, placed: Mapping[str, Point], swept: Sequence[Any],
           layers: Mapping[str, str], size: float) -> SlideMark:
    """A slider's line through its pin, along the direction it was drawn at turned with the
    body it is fixed to, long enough for the pin's travel over the sweep; its block a
    rectangle centred on the pin."""
    slide = drawing.sliders[name]
    pin, centre = drawing.bodies[name][0], drawing.center(slide.on)

    def direction(at: Mapping[str, Any]) -> tuple[float, float]:
        turn = 0.0
        if slide.on != "ground":
            a, b = drawing.bodies[slide.on][:2]
            turn = _angle(at[a], at[b]) - _angle(drawing.xy[a], drawing.xy[b])
        t = radians(slide.angle_deg) + turn
        return math.cos(t), math.sin(t)

    def along(at: Mapping[str, Any]) -> float:
        u = direction(at)
        return (at[pin][0] - at[centre][0]) * u[0] + (at[pin][1] - at[centre][1]) * u[1]

    u = direction(placed)
    n = (-u[1], u[0])
    c, p = placed[centre], placed[pin]
    across = (p[0] - c[0]) * n[0] + (p[1] - c[1]) * n[1]
    travel = [along(placed)] + [along(s.rates.joints) for s in swept if s.rates is not None
                                and s.status == "converged"]
    half = 0.06 * size
    lo, hi = min(travel) - 2 * half, max(travel) + 2 * half

    def at(t: float, k: float = 0.0) -> Point:
        return (c[0] + across * n[0] + t * u[0] + k * n[0], c[1] + across * n[1] + t * u[1] + k * n[1])

    t0, h = along(placed), 0.6 * half
    block = (at(t0 - half, -h), at(t0 + half, -h), at(t0 + half, h), at(t0 - half, h))
    return SlideMark(name, layers[slide.on], (at(lo), at(hi)), layers[name], block)


def _angle(a: Sequence[float], b: Sequence[float]) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def _vectors_only(mechanism: Any, q: Sequence[float]
                  ) -> tuple[tuple[Body, ...], tuple[SlideMark, ...], tuple[Mark, ...]]:
    """A loops-form file whose loops name no joints: each vector a segment on the layer of
    the link its angle turns with (``GROUND`` for a constant angle), each corner a joint
    without a name."""
    from ..problems.to_joints import link_name

    moving = {u.name for u in mechanism.unknowns} | {mechanism.driver.name}
    angle_name = {str(t.angle) for loop in mechanism.loops for t in loop.vectors
                  if isinstance(t.angle, str) and t.angle in moving}
    layers = layer_names(["ground", *sorted(link_name(a) for a in angle_name)])
    driven = _driven(mechanism)
    bodies, corners = [], {}
    for points, loop in zip(mechanism.model.points(q, mechanism.driver.value), mechanism.loops):
        for k, term in enumerate(loop.vectors):
            a, b = points[k], points[k + 1]
            body = link_name(term.angle) if term.angle in angle_name else "ground"
            role = "ground" if body == "ground" else "driven" if body == driven else "link"
            bodies.append(Body(body, layers[body], ((a.real, a.imag), (b.real, b.imag)), False, role))
            corners.setdefault((a.real, a.imag), None)
    return tuple(bodies), (), tuple(Mark("", xy, "joint") for xy in corners)


# --- DXF ------------------------------------------------------------------------------------------


LAYER_COLOURS = {"ground": 8, "driven": 1, "link": 5}
"""AutoCAD colour indices: grey, red, blue (the matplotlib drawing's colours)."""


def write_dxf(s: Sheet, path: Path) -> None:
    """``s`` as a DXF R2010 file, written atomically (see the module)."""
    require_ezdxf()
    import ezdxf

    from ..files import atomic_target

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = INSUNITS.get(s.unit, 0)
    doc.header["$MEASUREMENT"] = 0 if s.unit in ("in", "ft") else 1
    doc.header["$LUPREC"] = 8
    for body in s.bodies:
        if body.layer not in doc.layers:
            doc.layers.add(body.layer, color=LAYER_COLOURS[body.role])
    doc.layers.add("JOINTS", color=7)
    doc.layers.add("PATHS", color=3)
    msp = doc.modelspace()
    size = s.size()
    radius, text = 0.012 * size, 0.025 * size
    for body in s.bodies:
        if body.drawn():
            msp.add_lwpolyline(body.points, format="xy", close=body.closed, dxfattribs={"layer": body.layer})
    for slide in s.slides:
        msp.add_line(slide.line[0], slide.line[1], dxfattribs={"layer": slide.line_layer})
        msp.add_lwpolyline(slide.block, format="xy", close=True, dxfattribs={"layer": slide.layer})
    for mark in s.marks:
        layer = "PATHS" if mark.kind == "point" else "JOINTS"
        msp.add_circle(mark.xy, radius, dxfattribs={"layer": layer})
        if mark.kind == "ground":
            msp.add_lwpolyline(_pivot(mark.xy, radius), format="xy", close=True,
                               dxfattribs={"layer": "GROUND"})
        if mark.name:
            label = msp.add_text(_plain(mark.name), height=text, dxfattribs={"layer": layer})
            label.set_placement((mark.xy[0] + 1.5 * radius, mark.xy[1] + 1.5 * radius))
    for curve in s.curves:
        for piece in curve.pieces:
            msp.add_lwpolyline(piece, format="xy", dxfattribs={"layer": "PATHS"})
    with atomic_target(path) as tmp:
        doc.saveas(tmp)


def _pivot(xy: Point, r: float) -> tuple[Point, Point, Point]:
    """The ground-pivot symbol: a triangle under the joint, its apex at the circle."""
    x, y = xy
    return (x, y - r), (x - 2 * r, y - 3.5 * r), (x + 2 * r, y - 3.5 * r)


def _plain(text: str) -> str:
    """A name as one line of text: control characters (a TOML key may hold a newline) as spaces."""
    return re.sub(r"[\x00-\x1f\x7f]", " ", text)


# --- SVG ------------------------------------------------------------------------------------------


SVG_STYLE = {"ground": 'stroke="#8c8c8c" stroke-dasharray="{d} {d}"', "driven": 'stroke="#d62728"',
             "link": 'stroke="#1f77b4"'}


def svg_text(s: Sheet) -> str:
    """``s`` as an SVG document (see the module): shapes in a group that flips y (SVG's y
    points down), so every coordinate in it is the mechanism's own; labels outside it at
    (x, -y), so they read upright."""
    from xml.sax.saxutils import escape, quoteattr

    x0, y0, x1, y1 = s.extent()
    size = s.size()
    pad = 0.08 * size
    vx, vy, vw, vh = x0 - pad, -(y1 + pad), (x1 - x0) + 2 * pad, (y1 - y0) + 2 * pad
    unit, per = SVG_UNITS.get(s.unit, ("", 1.0))
    width, height = _num(vw * per) + unit, _num(vh * per) + unit
    if s.unit in SVG_UNITS and per != 1.0:
        scaled = (f"one user unit is 1 {s.unit}; SVG has no {s.unit}, so width and height are in "
                  f"{unit}, {per:g} {unit} to the {s.unit}")
    elif s.unit in SVG_UNITS:
        scaled = f"one user unit is 1 {s.unit}"
    else:
        scaled = f"one user unit is 1 {s.unit or 'unit of the file'} (no SVG unit: width and height unitless)"
    desc = f"{s.title}: links, joints and coupler curves; {scaled}"
    if s.sweep_note:
        desc += f"; curves over {s.sweep_note}"
    line, r, font = 0.006 * size, 0.012 * size, 0.025 * size
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f"<!-- {escape(scaled).replace('--', '- -')} -->",
           f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}" height="{height}" '
           f'viewBox="{_num(vx)} {_num(vy)} {_num(vw)} {_num(vh)}">',
           f"<title>{escape(s.title)}</title>", f"<desc>{escape(desc)}</desc>",
           f'<g id="geometry" transform="scale(1,-1)" fill="none" stroke-width="{_num(line)}" '
           'stroke-linecap="round" stroke-linejoin="round">']
    for body in (b for b in s.bodies if b.drawn()):
        style = SVG_STYLE[body.role].format(d=_num(3 * line))
        tag = "polygon" if body.closed else "polyline"
        out.append(f'<{tag} class="body" data-layer={quoteattr(body.layer)} {style} '
                   f'points="{_points(body.points)}"/>')
    for slide in s.slides:
        (ax, ay), (bx, by) = slide.line
        out.append(f'<line class="slide" data-layer={quoteattr(slide.line_layer)} stroke="#ff7f0e" '
                   f'stroke-dasharray="{_num(line)} {_num(2 * line)}" x1="{_num(ax)}" y1="{_num(ay)}" '
                   f'x2="{_num(bx)}" y2="{_num(by)}"/>')
        out.append(f'<polygon class="block" data-layer={quoteattr(slide.layer)} stroke="#ff7f0e" '
                   f'points="{_points(slide.block)}"/>')
    for curve in s.curves:
        for piece in curve.pieces:
            out.append(f'<polyline class="path" data-layer="PATHS" data-point={quoteattr(curve.name)} '
                       f'stroke="#2ca02c" points="{_points(piece)}"/>')
    for mark in s.marks:
        if mark.kind == "ground":
            out.append(f'<polygon class="pivot" data-layer="GROUND" stroke="#8c8c8c" '
                       f'points="{_points(_pivot(mark.xy, r))}"/>')
        colour = "#2ca02c" if mark.kind == "point" else "black"
        out.append(f'<circle class="{mark.kind}" data-name={quoteattr(mark.name)} cx="{_num(mark.xy[0])}" '
                   f'cy="{_num(mark.xy[1])}" r="{_num(r)}" stroke="{colour}" fill="white"/>')
    out.append("</g>")
    out.append(f'<g id="labels" font-family="sans-serif" font-size="{_num(font)}">')
    for mark in s.marks:
        if mark.name:
            out.append(f'<text x="{_num(mark.xy[0] + 1.5 * r)}" y="{_num(-mark.xy[1] - 1.5 * r)}">'
                       f"{escape(_plain(mark.name))}</text>")
    out += ["</g>", "</svg>", ""]
    return "\n".join(out)


def _num(v: float) -> str:
    """The shortest text that reads back as the same double (repr), without a trailing .0."""
    text = repr(float(v))
    return text[:-2] if text.endswith(".0") else text


def _points(points: Iterable[Point]) -> str:
    return " ".join(f"{_num(x)},{_num(y)}" for x, y in points)


def write_svg(s: Sheet, path: Path) -> None:
    from ..files import write_atomic

    write_atomic(path, svg_text(s))


def write_sheet(s: Sheet, path: Path) -> None:
    """The sheet in the format of ``path``'s suffix (.dxf or .svg)."""
    if path.suffix.lower() == ".dxf":
        write_dxf(s, path)
    else:
        write_svg(s, path)
