"""A first mechanism in one command (``linkage new KIND``): a four-bar, slider-crank,
inverted slider-crank, Watt or Stephenson six-bar from its link lengths, drawn in one pose
as a joints-form file (:mod:`.joints`) that solves as written.

The pose is plain geometry, one dyad at a time: the crank pin at the drawn angle, then
each dyad's joint where its two circles meet (:func:`.dyads.two_angles`) or where a
circle meets the slider's line (:func:`.dyads.line_circle`,
:func:`.dyads.angle_and_its_length`), on the side the branch names. The branch words are
the project's (:mod:`.derive`): a four-bar dyad is ``open`` where its output link turns
anticlockwise from its coupler (the dyad's joint on the left of the line from the
coupler's other joint to the output's pivot), a slider-crank ``open`` where the coupler
points the way the slide grows; the inverted slider-crank's ``open`` has the rocker
pointing from its pivot towards the block (a positive travel).

:func:`template` gives the joints document, :func:`joints_text` the commented file and
:func:`text` either form (the loops form through :func:`.toml_text.loops_text`, so there is
one derivation)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import radians
from . import dyads
from .toml_text import toml_value

Point = tuple[float, float]
BRANCHES = ("open", "crossed")
COMMENT_WIDTH = 92
"""The file's comments are wrapped to this width."""
MAX_ANGLE_DEG = 1e6
"""The largest drawn angle accepted (degrees): the drawing's check of the driver value
(joints.DRIVER_TOLERANCE_DEG, 1e-6) needs the angle's rounding well below it (here 1e-10)."""


Joints = dict[str, Point]


@frozen
class Kind:
    """A mechanism ``linkage new`` draws: its lengths in ``--links`` order, the sample file
    whose dimensions and driver value are the defaults, its bodies, and how it is drawn."""

    title: str
    sample: str
    links: tuple[str, ...]
    """The --links order: the lengths' names (``offset``: a slider line's, signed)."""
    meaning: tuple[str, ...]
    """What each length is, in the drawing's joint names."""
    defaults: tuple[float, ...]
    angle_deg: float
    open_means: str
    ground: tuple[str, ...]
    bodies: dict[str, list[str]]
    sliders: dict[str, dict[str, Any]]
    notes: dict[str, str]
    """Each joint's comment in the file, in drawing order."""
    link_notes: dict[str, str]
    draw: Callable[[Sequence[float], float, Sequence[float]], Joints]
    """(lengths, crank angle in radians, a side per dyad) -> the joints."""
    dyads: int = 1
    """Two-way steps: one --branch word each."""
    fixed: str = ""
    """Fixed angles of the drawing (the six-bars keep their sample's), for the comments."""
    open_brief: str = ""
    """What ``--branch open`` draws, in a few words for ``linkage new --help`` (a six-bar's
    dyads read as the four-bar's: none of its own)."""

    @property
    def signed(self) -> frozenset[str]:
        return frozenset(n for n in self.links if n == "offset")


class _Cannot(Exception):
    """A dyad that does not close, with the reason in words."""


def _dyad(p: Point, a: float, q: Point, b: float, side: float, names: tuple[str, str, str, str]) -> Point:
    """X with |X - P| = a and |X - Q| = b, on the left of P -> Q for ``side`` +1 (right for
    -1): the circles' meeting point by :func:`.dyads.two_angles` (P e^(ia) + Q e^(ib) + K = 0
    with K = P - Q, X = P + a e^(ia)). ``names``: P, Q, and the links of length a and b."""
    pn, qn, an, bn = names
    d = dyads.norm(q[0] - p[0], q[1] - p[1])
    try:
        got = dyads.two_angles((a, 0.0), (b, 0.0), (p[0] - q[0], p[1] - q[1]), side)
    except ZeroDivisionError:
        got = None
    if got is None:
        if d == 0.0:
            raise _Cannot(f"{pn} is drawn on {qn}: where {an} and {bn} meet is undetermined")
        if a + b < d:
            raise _Cannot(f"{an} + {bn} = {a + b:.9g} < {d:.9g}, the distance from {pn} to {qn}")
        raise _Cannot(f"|{an} - {bn}| = {abs(a - b):.9g} > {d:.9g}, the distance from {pn} to {qn}")
    return _polar(p, a, got[0])


def _polar(p: Point, r: float, t: float) -> Point:
    return p[0] + r * math.cos(t), p[1] + r * math.sin(t)


def _angle(p: Point, q: Point) -> float:
    return math.atan2(q[1] - p[1], q[0] - p[0])


def _fourbar(r: Sequence[float], t: float, sides: Sequence[float]) -> Joints:
    """Crank r[0] about O2 = (0, 0), coupler r[1], rocker r[2] about O4 = (r[3], 0)."""
    o2, o4 = (0.0, 0.0), (r[3], 0.0)
    a = _polar(o2, r[0], t)
    b = _dyad(a, r[1], o4, r[2], sides[0], ("A", "the rocker's pivot O4", "coupler", "rocker"))
    return {"O2": o2, "A": a, "B": b, "O4": o4}


WATT_C_DEG, WATT_O6_DEG = 40.0, 60.0
STEPHENSON_C_DEG, STEPHENSON_O6_DEG = 30.0, 110.0


def _watt(r: Sequence[float], t: float, sides: Sequence[float]) -> Joints:
    """The four-bar, its rocker a ternary link O4-B-C (C r[4] from O4, 40 deg ahead of
    O4B), and a dyad C-D-O6 (r[5], r[6]) to a third pivot O6, r[7] from O4 at 60 deg."""
    xy = _fourbar(r, t, sides)
    o4 = xy["O4"]
    c = _polar(o4, r[4], _angle(o4, xy["B"]) + radians(WATT_C_DEG))
    o6 = _polar(o4, r[7], radians(WATT_O6_DEG))
    d = _dyad(c, r[5], o6, r[6], sides[1], ("C", "link7's pivot O6", "link6", "link7"))
    return {**xy, "C": c, "D": d, "O6": o6}


def _stephenson(r: Sequence[float], t: float, sides: Sequence[float]) -> Joints:
    """The four-bar, its coupler a ternary link A-B-C (C r[4] from A, 30 deg ahead of
    AB), and a dyad C-D-O6 (r[5], r[6]) to a third pivot O6, r[7] from O2 at 110 deg."""
    xy = _fourbar(r, t, sides)
    a = xy["A"]
    c = _polar(a, r[4], _angle(a, xy["B"]) + radians(STEPHENSON_C_DEG))
    o6 = _polar(xy["O2"], r[7], radians(STEPHENSON_O6_DEG))
    d = _dyad(c, r[5], o6, r[6], sides[1], ("C", "link6's pivot O6", "link5", "link6"))
    return {**xy, "C": c, "D": d, "O6": o6}


def _slider_crank(r: Sequence[float], t: float, sides: Sequence[float]) -> Joints:
    """Crank r[0] about O2 = (0, 0); the block's pin B on the line y = e = r[2] where the
    coupler's circle about A meets it: |s + z| = r[1] with z = -A_x + i (e - A_y)
    (:func:`.dyads.line_circle`, the larger s open)."""
    r2, r3, e = r
    a = _polar((0.0, 0.0), r2, t)
    s = dyads.line_circle((-a[0], e - a[1]), r3, sides[0])
    if s is None:
        raise _Cannot(f"coupler = {r3:.9g} < {abs(e - a[1]):.9g}, the distance from A to the slider's "
                      f"line y = {e:.9g}")
    return {"O2": (0.0, 0.0), "A": a, "B": (s, e)}


def _inverted(r: Sequence[float], t: float, sides: Sequence[float]) -> Joints:
    """Crank r[0] about O2 = (0, 0); its pin A carries a block sliding along the rocker,
    which turns about O4 = (r[1], 0), the block's line r[2] = e across it:
    A - O4 = (s + i e) e^(i theta4) (:func:`.dyads.angle_and_its_length`, the larger s
    open). C, a point on the rocker r[0] + r[1] from O4, gives its line's direction."""
    r2, r1, e = r
    o4 = (r1, 0.0)
    a = _polar((0.0, 0.0), r2, t)
    try:
        got = dyads.angle_and_its_length((0.0, e), (1.0, 0.0), (o4[0] - a[0], o4[1] - a[1]), sides[0])
    except ZeroDivisionError:
        raise _Cannot("A is drawn on O4: the rocker's angle is undetermined") from None
    if got is None:
        d = dyads.norm(a[0] - o4[0], a[1] - o4[1])
        raise _Cannot(f"the offset |{e:.9g}| > {d:.9g}, the distance from A to O4: the block's line "
                      "misses A")
    return {"O2": (0.0, 0.0), "A": a, "O4": o4, "C": _polar(o4, r2 + r1, got[0])}


FOURBAR_NOTES = {"O2": "the crank's ground pivot", "A": "the crank pin", "B": "coupler and rocker",
                 "O4": "the rocker's ground pivot"}
TWO_DYADS = "each dyad's output turns anticlockwise from its coupler (B left of A -> O4, D left of C -> O6)"

KINDS: dict[str, Kind] = {
    "fourbar": Kind(
        "Four-bar", "crank_rocker.toml", ("crank", "coupler", "rocker", "ground"),
        ("O2A", "AB", "O4B", "O2O4"), (40.0, 120.0, 80.0, 100.0), 30.0,
        "the rocker turns anticlockwise from the coupler (B on the left of A -> O4)",
        ("O2", "O4"), {"crank": ["O2", "A"], "coupler": ["A", "B"], "rocker": ["O4", "B"]}, {},
        FOURBAR_NOTES, {"crank": "the driver", "coupler": "", "rocker": ""}, _fourbar,
        open_brief="a four-bar's rocker turns anticlockwise from its coupler"),
    "slider-crank": Kind(
        "Slider-crank", "slider_crank.toml", ("crank", "coupler", "offset"),
        ("O2A", "AB", "the slider's line y = offset: any sign, 0 in line with O2"),
        (40.0, 120.0, 10.0), 45.0, "the coupler points the way the slide grows (B ahead of A)",
        ("O2",), {"crank": ["O2", "A"], "coupler": ["A", "B"], "block": ["B"]},
        {"block": {"on": "ground", "angle": 0.0}},
        {"O2": "the crank's ground pivot", "A": "the crank pin", "B": "the block's pin, on its line"},
        {"crank": "the driver", "coupler": "", "block": "a slider block carrying B"}, _slider_crank,
        open_brief="a slider-crank's coupler points the way the slide grows"),
    "inverted-slider": Kind(
        "Inverted slider-crank", "inverted_slider_crank.toml", ("crank", "ground", "offset"),
        ("O2A", "O2O4", "the block's line from O4, across the rocker: any sign, 0 through O4"),
        (40.0, 100.0, 10.0), 60.0, "the rocker points from O4 towards the block (its travel > 0)",
        ("O2", "O4"), {"crank": ["O2", "A"], "rocker": ["O4", "C"], "block": ["A"]},
        {"block": {"on": "rocker", "line": ["O4", "C"]}},
        {"O2": "the crank's ground pivot", "A": "the crank pin, the block on it", "O4": "the rocker's pivot",
         "C": "a point on the rocker (crank + ground from O4): its line's direction"},
        {"crank": "the driver", "rocker": "the block slides along it", "block": "a slider block carrying A"},
        _inverted, open_brief="an inverted slider's rocker points towards the block"),
    "watt": Kind(
        "Watt six-bar", "watt_sixbar.toml",
        ("crank", "coupler", "rocker", "ground", "O4C", "CD", "O6D", "O4O6"),
        ("O2A", "AB", "O4B", "O2O4", "C on the rocker", "link6", "link7", "the third pivot O6 from O4"),
        (40.0, 120.0, 80.0, 100.0, 70.0, 110.0, 80.0, 120.0), 30.0, TWO_DYADS,
        ("O2", "O4", "O6"), {"crank": ["O2", "A"], "coupler": ["A", "B"], "rocker": ["O4", "B", "C"],
                             "link6": ["C", "D"], "link7": ["O6", "D"]}, {},
        {**FOURBAR_NOTES, "C": "on the rocker, and link6", "D": "link6 and link7",
         "O6": "link7's ground pivot"},
        {"crank": "the driver", "coupler": "", "rocker": "a ternary link", "link6": "", "link7": ""},
        _watt, 2, f"C {WATT_C_DEG:g} deg ahead of O4B on the rocker, O6 at {WATT_O6_DEG:g} deg from O4"),
    "stephenson": Kind(
        "Stephenson III six-bar", "stephenson_sixbar.toml",
        ("crank", "coupler", "rocker", "ground", "AC", "CD", "O6D", "O2O6"),
        ("O2A", "AB", "O4B", "O2O4", "C on the coupler", "link5", "link6", "the third pivot O6 from O2"),
        (40.0, 120.0, 80.0, 100.0, 60.0, 100.0, 90.0, 160.0), 30.0, TWO_DYADS,
        ("O2", "O4", "O6"), {"crank": ["O2", "A"], "coupler": ["A", "B", "C"], "rocker": ["O4", "B"],
                             "link5": ["C", "D"], "link6": ["O6", "D"]}, {},
        {**FOURBAR_NOTES, "C": "on the coupler, and link5", "D": "link5 and link6",
         "O6": "link6's ground pivot"},
        {"crank": "the driver", "coupler": "a ternary link", "rocker": "", "link5": "", "link6": ""},
        _stephenson, 2,
        f"C {STEPHENSON_C_DEG:g} deg ahead of AB on the coupler, O6 at {STEPHENSON_O6_DEG:g} deg from O2"),
}
"""The kinds, in the order --help lists them: the one registry ``linkage new`` reads its
choices, help and defaults from. A new kind is an entry here (with its ``draw``) and the
sample file its defaults are. The six-bars' --links run as their samples' parameters do,
the four-bar's first (crank, coupler, rocker, ground), then the second dyad's."""


def kind_names() -> str:
    """The kinds as --help lists them: ``fourbar, slider-crank, ... or stephenson``."""
    names = list(KINDS)
    return ", ".join(names[:-1]) + f" or {names[-1]}" if len(names) > 1 else names[0]


def kind_titles() -> str:
    """The kinds' titles: ``Four-bar, Slider-crank, ... or Stephenson III six-bar``."""
    titles = [k.title for k in KINDS.values()]
    return ", ".join(titles[:-1]) + f" or {titles[-1]}" if len(titles) > 1 else titles[0]


def branch_help() -> str:
    """What --branch means for every kind, for --help."""
    briefs = [k.open_brief for k in KINDS.values() if k.open_brief]
    several = [key for key, k in KINDS.items() if k.dyads > 1]
    per_dyad = (f"; {' and '.join(several)} take one word per dyad, e.g. open/crossed" if several else "")
    return f"The assembly drawn: open ({'; '.join(briefs)}) or crossed{per_dyad}."


def links_order(kind: str | None = None) -> str:
    """The --links order of a kind (``fourbar: crank coupler rocker ground``), or of all."""
    return "; ".join(f"{key}: {' '.join(k.links)}" for key, k in KINDS.items() if kind in (None, key))


def angles() -> str:
    """Each kind's default crank angle (its sample's), for --help."""
    return ", ".join(f"{key} {_num(k.angle_deg)}" for key, k in KINDS.items())


def _num(v: float) -> str:
    """The shortest text that reads back as ``v`` (40, not 40.0)."""
    text = repr(float(v))
    return text[:-2] if text.endswith(".0") else text


def _kind(kind: str) -> Kind:
    if kind not in KINDS:
        raise InputError(f"KIND: {kind!r} is not a kind linkage new draws (kinds: {', '.join(KINDS)})")
    return KINDS[kind]


def _lengths(k: Kind, kind: str, links: Sequence[float] | None) -> tuple[float, ...]:
    if links is None or len(links) == 0:
        return k.defaults
    if len(links) != len(k.links):
        raise InputError(f"links: {kind} takes {len(k.links)} lengths ({' '.join(k.links)}), "
                         f"got {len(links)}")
    from .loops import LENGTH_RANGE

    lo, hi = LENGTH_RANGE
    for name, v in zip(k.links, links):
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
            raise InputError(f"links: {name} must be a finite number, got {v!r}")
        if name in k.signed:
            if v != 0.0 and not lo <= abs(v) <= hi:
                raise InputError(f"links: {name} = {v:g}: an offset is 0 or between {lo:g} and {hi:g}")
        elif not v > 0.0:
            raise InputError(f"links: {name} must be a positive length, got {v:g}")
        elif not lo <= v <= hi:
            raise InputError(f"links: {name} = {v:g}: a length is between {lo:g} and {hi:g}")
    return tuple(float(v) for v in links)


def _sides(k: Kind, branch: str) -> tuple[float, ...]:
    words = branch.split("/")
    if len(words) == 1:
        words = words * k.dyads
    if len(words) != k.dyads or any(w not in BRANCHES for w in words):
        per = "" if k.dyads == 1 else (", or one word per dyad joined by / (the four-bar's first, "
                                       "e.g. open/crossed)")
        raise InputError(f"branch: {branch!r}: give open or crossed{per}")
    return tuple(1.0 if w == "open" else -1.0 for w in words)


def template(kind: str, links: Sequence[float] | None = None, angle_deg: float | None = None,
             branch: str = "open", unit: str = "mm", name: str | None = None) -> dict[str, Any]:
    """The joints-form document of a ``kind`` (see :data:`KINDS`) with these lengths in
    ``--links`` order (default: its sample's), drawn with the crank at ``angle_deg``
    (default: the sample's driver value) on ``branch``. Raises InputError naming the
    argument, and saying why when the lengths cannot be assembled at that angle."""
    k = _kind(kind)
    lengths = _lengths(k, kind, links)
    angle = k.angle_deg if angle_deg is None else angle_deg
    if (not isinstance(angle, (int, float)) or isinstance(angle, bool) or not math.isfinite(angle)
            or abs(angle) > MAX_ANGLE_DEG):
        raise InputError(f"angle_deg: must be a finite number of degrees within +-{MAX_ANGLE_DEG:g}, "
                         f"got {angle!r}")
    sides = _sides(k, branch)
    from .loops import LENGTH_UNITS

    if unit not in LENGTH_UNITS:
        raise InputError(f"unit: {unit!r} is not a length unit (units: {', '.join(LENGTH_UNITS)})")
    if name is not None and (not name.strip() or not name.isprintable()):
        raise InputError("name: must be one line of printable text")
    t = radians(math.remainder(angle, 360.0))  # exact: the remainder of a double is one
    try:
        joints = k.draw(lengths, t, sides)
    except _Cannot as exc:
        raise InputError(f"links {' '.join(map(_num, lengths))}: the {kind} cannot be assembled "
                         f"at {_num(angle)} deg ({branch}): {exc}") from None
    shown = ", ".join(f"{n} {_num(v)}" for n, v in zip(k.links, lengths))
    doc: dict[str, Any] = {
        "name": name if name is not None else k.title,
        "description": f"{k.title}: {shown} {unit}, drawn with the crank at {_num(angle)} deg ({branch})",
        "length_unit": unit,
        "ground": list(k.ground),
        "joints": {j: [float(x), float(y)] for j, (x, y) in joints.items()},
        "links": {b: list(js) for b, js in k.bodies.items()},
    }
    if k.sliders:
        doc["sliders"] = {b: dict(s) for b, s in k.sliders.items()}
    doc["driver"] = {"link": "crank", "value": float(angle)}
    return doc


def command(kind: str, links: Sequence[float] | None = None, angle_deg: float | None = None,
            branch: str = "open", unit: str = "mm", name: str | None = None, form: str = "joints") -> str:
    """The ``linkage new`` command line that makes this file, every choice spelt out."""
    import shlex

    k = _kind(kind)
    lengths = _lengths(k, kind, links)
    words = ["linkage", "new", kind, "--links", *map(_num, lengths),
             "--angle", _num(k.angle_deg if angle_deg is None else angle_deg), "--branch", branch,
             "--unit", unit]
    if name is not None:
        words += ["--name", name]
    if form != "joints":
        words += ["--form", form]
    return " ".join(shlex.quote(w) for w in words)


def joints_text(doc: Mapping[str, Any], kind: str, made_by: str) -> str:
    """A template's joints document as a commented TOML file: the --links order and
    values, what each joint and link is, the branch drawn, and the commands to try."""
    k = _kind(kind)
    unit = doc["length_unit"]
    import textwrap

    said = [f"--links order for {kind}: " + ", ".join(f"{n} ({m})" for n, m in zip(k.links, k.meaning)),
            f"Defaults: the lengths and crank angle of sample_inputs/{k.sample}.",
            f"--branch open: {k.open_means}; crossed: the other assembly.",
            *([f"Fixed in the drawing: {k.fixed}."] if k.fixed else []),
            "Every length and angle comes from the joints below: move them to change the design.",
            "Try: linkage solve FILE; linkage sweep FILE; linkage draw FILE; linkage convert FILE"]
    out = [f"# {k.title}, drawn by: {made_by}"]  # one line, to copy
    out += [line for s in said for line in textwrap.wrap(s, COMMENT_WIDTH, initial_indent="# ",
                                                        subsequent_indent="#   ", break_long_words=False,
                                                        break_on_hyphens=False)]
    out += ["",
           f"name = {toml_value(doc['name'])}",
           f"description = {toml_value(doc['description'])}",
           f"length_unit = {toml_value(unit)}",
           f"ground = {toml_value(doc['ground'])}  # fixed joints",
           "",
           f"[joints]  # one pose, in {unit}"]
    out += [f"{j} = {toml_value(p)}  # {k.notes[j]}" for j, p in doc["joints"].items()]
    out += ["", "[links]  # the joints each rigid link carries; its angle: first joint -> second"]
    out += [f"{b} = {toml_value(js)}" + (f"  # {k.link_notes[b]}" if k.link_notes[b] else "")
            for b, js in doc["links"].items()]
    if "sliders" in doc:
        out += ["", "[sliders]  # a link sliding along a line fixed to `on`, through its joint as drawn"]
        out += [f"{b} = {toml_value(s)}" for b, s in doc["sliders"].items()]
    out += ["", "[driver]", 'link = "crank"  # its angle O2 -> A, degrees',
            f"value = {toml_value(doc['driver']['value'])}  # the drawn pose is at this value"]
    return "\n".join(out) + "\n"


def text(kind: str, links: Sequence[float] | None = None, angle_deg: float | None = None,
         branch: str = "open", unit: str = "mm", name: str | None = None, form: str = "joints") -> str:
    """The file ``linkage new`` writes: the joints form (commented), or with ``form`` =
    "loops" the loops form the joints imply (:func:`.toml_text.loops_text`)."""
    if form not in ("joints", "loops"):
        raise InputError(f"form: {form!r}: give joints or loops")
    doc = template(kind, links, angle_deg, branch, unit, name)
    made_by = command(kind, links, angle_deg, branch, unit, name, form)
    if form == "loops":
        from .toml_text import loops_text

        return f"# drawn by: {made_by}\n" + loops_text(doc, f"this {kind}")
    return joints_text(doc, kind, made_by)
