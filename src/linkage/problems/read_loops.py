"""The loops form of a mechanism file, read: names, units, parameters, driver, unknowns,
loops and points checked and turned into a :class:`~.loops.Mechanism` (the layout is in
:mod:`.loops`; a drawing's loops are derived first, :func:`.joints.loops_doc`). Every
refusal names the file and the key. Reading solves nothing: a drawing whose [driver]
value is not where it is drawn is posed there by :mod:`linkage.kinematics.loading`."""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Mapping
from typing import Any

from ..errors import ParseError
from ..records import frozen
from ..units import radians
from .columns import column_clash
from .loops import (
    ANGLE_LIMIT_DEG,
    ANGLE_UNITS,
    LENGTH_UNITS,
    MAX_LOOPS,
    MAX_POINTS,
    MAX_VECTORS,
    Loop,
    Mechanism,
    Quantity,
    VectorTerm,
    as_float,
    length_factor,
    magnitude_problem,
)

CLOSED_FORMS = ("fourbar", "slider_crank")
"""What an old file's ``closed_form = ...`` may claim (read and checked, no longer needed)."""
TOP_KEYS = {"name", "description", "length_unit", "closed_form", "parameters", "driver", "unknowns",
            "loops", "notes", "points", "origin"}

Fail = Callable[[str, str], ParseError]


@frozen
class _Reading:
    """What every part of one file's reading needs: its name for messages, its length unit
    and how each name is used (the unit a bare number takes)."""

    source: str
    length_unit: str
    use: Mapping[str, set[str]]

    def fail(self, key: str, msg: str) -> ParseError:
        return ParseError(f"{self.source}: {key}: {msg}")

    def quantity(self, key: str, qname: str, spec: Any, field_name: str) -> Quantity:
        """A parameter, driver or unknown: a number or a table with its unit."""
        fail = self.fail
        if isinstance(spec, (int, float)) and not isinstance(spec, bool):
            spec = {field_name: spec}  # a bare number: the file's unit for its kind (below)
        if not isinstance(spec, Mapping):
            raise fail(key, f"expected a number or a table like {{ {field_name} = 1.0, unit = \"deg\" }}")
        for k in spec:
            if k not in (field_name, "unit", "note", "signed"):
                raise fail(f"{key}.{k}", f"unknown key (expected {field_name}, unit, signed)")
        signed = spec.get("signed", False)
        if not isinstance(signed, bool):
            raise fail(f"{key}.signed", "must be true or false")
        if field_name not in spec:
            raise fail(key, f"missing {field_name!r}")
        value = as_float(spec[field_name])
        if value is None:
            raise fail(f"{key}.{field_name}", f"must be a finite number, got {_short(spec[field_name])}")
        accepted = accepted_units(self.length_unit)
        unit = spec.get("unit")
        if unit is None:
            kinds = self.use.get(qname, set())
            if len(kinds) != 1:
                how = ("is used as " + " and as ".join(sorted(kinds)) if kinds else "is in no loop")
                raise fail(key, f"{qname} {how}, so its unit cannot be read from its use: give "
                                f"unit = one of {accepted}")
            unit = "deg" if kinds == {"angle"} else self.length_unit  # the file's unit for its kind
        if not isinstance(unit, str):
            raise fail(f"{key}.unit", f"must be one of {accepted}, got {_short(unit)}")
        if unit != self.length_unit and unit in LENGTH_UNITS and self.length_unit in LENGTH_UNITS:
            value *= length_factor(unit, self.length_unit)  # converted on read: the file's unit inside
            unit = self.length_unit
        if unit in ANGLE_UNITS or unit == self.length_unit:
            kind = "angle" if unit in ANGLE_UNITS else "length"
            internal = value * ANGLE_UNITS[unit] if kind == "angle" else value
            why = magnitude_problem(internal, kind, str(unit), signed)
            if why:
                raise fail(f"{key}.{field_name}", why)
            return Quantity(qname, kind, internal, unit, signed if kind == "length" else False)
        raise fail(f"{key}.unit", f"unknown unit {unit!r}: use one of {accepted}")

    def vector(self, vec: Any, vkey: str, known: Mapping[str, Quantity], used: set[str]) -> VectorTerm:
        """One vector of a loop or a point's path."""
        fail = self.fail
        if not isinstance(vec, Mapping):
            raise fail(vkey, "must be a table like { length = \"r2\", angle = \"theta2\" }")
        for k in vec:
            if k not in ("length", "angle", "offset", "sign"):
                raise fail(f"{vkey}.{k}", "unknown key (expected length, angle, offset, sign)")
        sign = vec.get("sign", 1)
        if sign not in (1, -1) or isinstance(sign, bool):
            raise fail(f"{vkey}.sign", f"must be 1 or -1, got {_short(sign)}")
        length = _ref(vec.get("length"), f"{vkey}.length", "length", known, fail, used)
        angle = _ref(vec.get("angle"), f"{vkey}.angle", "angle", known, fail, used)
        offset = as_float(vec.get("offset", 0.0))
        if offset is None or abs(offset) > ANGLE_LIMIT_DEG:
            raise fail(f"{vkey}.offset", f"must be a finite number of degrees within "
                                         f"+-{ANGLE_LIMIT_DEG:g}")
        return VectorTerm(float(sign), length, angle, radians(offset))


def is_joints_doc(doc: Mapping[str, Any]) -> bool:
    """Any key of the joints form: a drawing missing [links] (or holding [[loops]] too) is
    then told what it lacks, not read as a loops file. Here, not in problems/joints.py:
    a loops file's reading does not import the joints form's reader."""
    return any(k in doc for k in ("joints", "links", "ground", "sliders"))


def read_mechanism(doc: Mapping[str, Any], source: str = "<mechanism>") -> Mechanism:
    """The mechanism a parsed file describes, every error naming the file and the key. A
    drawing (the joints form) is read as drawn: its guesses are the drawn pose even where
    its [driver] value is elsewhere; :func:`linkage.kinematics.loading.parse_mechanism`,
    which every loader calls, solves them there (a solve is a layer above this one)."""
    def fail(key: str, msg: str) -> ParseError:
        return ParseError(f"{source}: {key}: {msg}")

    _check_printable(doc, fail)  # a drawing's too, before its names are in a message
    drawn: Mapping[str, Any] | None = None
    if is_joints_doc(doc):  # a drawing: its loops derived (problems/joints.py)
        from .joints import loops_doc

        drawn = doc
        doc = loops_doc(doc, source)
    name, length_unit, closed_form = _header(doc, fail)
    r = _Reading(source, length_unit, kinds_by_use(doc))
    parameters = _parameters(doc, r)
    driver, driver_range = _driver(doc, r, parameters)
    unknowns = _unknowns(doc, r, parameters, driver.name)
    known = {**parameters, driver.name: driver, **{u.name: u for u in unknowns}}
    used: set[str] = set()
    loops = _loops(doc, r, known, used)
    _check_use(r, loops, unknowns, driver.name, known, used, closed_form)

    def vector(vec: Any, vkey: str, seen: set[str]) -> VectorTerm:
        return r.vector(vec, vkey, known, seen)

    points = _points(doc.get("points", {}), loops, vector, fail)
    mechanism = Mechanism(name, source, length_unit, parameters, driver, unknowns, tuple(loops),
                          closed_form, str(doc.get("description", "")),
                          {"notes": doc.get("notes", "")}, points, _origin(doc.get("origin"), fail),
                          driver_range)
    clash = column_clash(mechanism)
    if clash:
        raise fail(*clash)
    if drawn is not None:
        _keep_drawing(mechanism, drawn, source)
    if closed_form is not None:
        _check_closed_form(mechanism, closed_form, fail)
    return mechanism


def _header(doc: Mapping[str, Any], fail: Fail) -> tuple[str, str, str | None]:
    """The file's known keys, its name, length unit and (old) closed-form claim."""
    for key in doc:
        if key not in TOP_KEYS:
            raise fail(key, f"unknown key (expected one of {', '.join(sorted(TOP_KEYS))})")
    name = doc.get("name")
    if not isinstance(name, str) or not name:
        raise fail("name", "missing or not a string")
    length_unit = doc.get("length_unit")
    if not isinstance(length_unit, str) or not length_unit:
        raise fail("length_unit", "missing: give the unit every length uses, e.g. \"mm\"")
    closed_form = doc.get("closed_form")
    if closed_form is not None and closed_form not in CLOSED_FORMS:
        raise fail("closed_form", f"unknown closed form {closed_form!r} (fourbar or slider_crank)")
    return name, length_unit, closed_form


def _parameters(doc: Mapping[str, Any], r: _Reading) -> dict[str, Quantity]:
    params_doc = doc.get("parameters", {})
    if not isinstance(params_doc, Mapping):
        raise r.fail("parameters", "must be a table")
    parameters = {k: r.quantity(f"parameters.{k}", k, v, "value") for k, v in params_doc.items()}
    for k, q in parameters.items():
        if q.kind == "length" and not q.signed and q.value <= 0.0:
            raise r.fail(f"parameters.{k}.value", f"a length must be > 0, got {q.value!r} "
                                                  "(declare signed = true for an offset)")
    return parameters


def _driver(doc: Mapping[str, Any], r: _Reading, parameters: Mapping[str, Quantity]
            ) -> tuple[Quantity, tuple[float, float] | None]:
    drv = doc.get("driver")
    if not isinstance(drv, Mapping) or "name" not in drv:
        raise r.fail("driver", "missing: give [driver] with name, value and unit")
    drv_name = drv["name"]
    if not isinstance(drv_name, str):
        raise r.fail("driver.name", "must be a string")
    driver = r.quantity("driver", drv_name, {k: v for k, v in drv.items() if k not in ("name", "range")},
                        "value")
    driver_range = _driver_range(drv.get("range"), driver, r.fail)
    if drv_name in parameters:
        raise r.fail("driver.name", f"{drv_name!r} is also listed under [parameters]")
    return driver, driver_range


def _unknowns(doc: Mapping[str, Any], r: _Reading, parameters: Mapping[str, Quantity],
              drv_name: str) -> tuple[Quantity, ...]:
    unk_doc = doc.get("unknowns")
    if not isinstance(unk_doc, Mapping) or not unk_doc:
        raise r.fail("unknowns", "missing: list each unknown with its guess and unit")
    if len(unk_doc) > 2 * MAX_LOOPS:
        raise r.fail("unknowns", f"{len(unk_doc):,} unknowns; at most {2 * MAX_LOOPS} ({MAX_LOOPS} "
                                 "loops) are accepted, far above any real mechanism")
    unknowns = tuple(r.quantity(f"unknowns.{k}", k, v, "guess") for k, v in unk_doc.items())
    clash = [u.name for u in unknowns if u.name in parameters or u.name == drv_name]
    if clash:
        raise r.fail(f"unknowns.{clash[0]}", "is also a parameter or the driver")
    return unknowns


def _loops(doc: Mapping[str, Any], r: _Reading, known: Mapping[str, Quantity], used: set[str]) -> list[Loop]:
    fail = r.fail
    loops_doc = doc.get("loops")
    if not isinstance(loops_doc, list) or not loops_doc:
        raise fail("loops", "missing: give at least one [[loops]] with its vectors")
    if len(loops_doc) > MAX_LOOPS:
        raise fail("loops", f"{len(loops_doc):,} loops; at most {MAX_LOOPS} are accepted, far "
                            "above any real mechanism")
    loops = []
    for li, loop in enumerate(loops_doc):
        lkey = f"loops[{li}]"
        if not isinstance(loop, Mapping) or not isinstance(loop.get("vectors"), list):
            raise fail(lkey, "needs a list 'vectors'")
        for k in loop:
            if k not in ("name", "vectors", "joints"):
                raise fail(f"{lkey}.{k}", "unknown key (expected name, vectors, joints)")
        joints = loop.get("joints", [])
        if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints) or (
                joints and len(joints) != len(loop["vectors"])):
            raise fail(f"{lkey}.joints", f"must list one name per vector ({len(loop['vectors'])}), "
                                         "\"\" for an unnamed point")
        if len(loop["vectors"]) > MAX_VECTORS:
            raise fail(f"{lkey}.vectors", f"{len(loop['vectors']):,} vectors; at most {MAX_VECTORS} "
                                          "are accepted in one loop")
        terms = [r.vector(vec, f"{lkey}.vectors[{vi}]", known, used)
                 for vi, vec in enumerate(loop["vectors"])]
        loops.append(Loop(str(loop.get("name", f"loop {li + 1}")), tuple(terms), tuple(joints)))
    return loops


def _check_use(r: _Reading, loops: list[Loop], unknowns: tuple[Quantity, ...], drv_name: str,
               known: Mapping[str, Quantity], used: set[str], closed_form: str | None) -> None:
    """As many equations as unknowns, every unknown and the driver in a loop, and the
    names an old closed-form claim needs."""
    n_eq = 2 * len(loops)
    if n_eq != len(unknowns):
        raise r.fail("unknowns", f"{len(loops)} loop(s) give {n_eq} equations but there are "
                                 f"{len(unknowns)} unknowns ({', '.join(u.name for u in unknowns)})")
    if closed_form is not None:
        from .closed_form import REQUIRED_NAMES

        missing = [k for k in REQUIRED_NAMES[closed_form] if k not in known]
        if missing:
            raise r.fail("closed_form", f"{closed_form} needs the names {', '.join(missing)}{KEY_HINT}")
    unused = [u.name for u in unknowns if u.name not in used]
    if unused:
        raise r.fail(f"unknowns.{unused[0]}", "appears in no loop")
    if drv_name not in used:
        raise r.fail("driver.name", f"{drv_name!r} appears in no loop")


def _check_closed_form(mechanism: Mechanism, closed_form: str, fail: Fail) -> None:
    """An old file's ``closed_form = ...`` claim, checked against its loops."""
    from .closed_form import verify

    why = verify(mechanism)
    if why:
        raise fail("closed_form", f"{closed_form!r} does not describe this file: {why}{KEY_HINT}")
    if not mechanism.derivation.complete:
        raise fail("closed_form", f"{closed_form!r} does not describe this file: "
                                  f"{mechanism.derivation.summary}{KEY_HINT}")


def accepted_units(length_unit: str) -> str:
    lengths = [length_unit] + [u for u in LENGTH_UNITS if u != length_unit and length_unit in LENGTH_UNITS]
    return ", ".join(["deg", "rad", *lengths])


def kinds_by_use(doc: Mapping[str, Any]) -> dict[str, set[str]]:
    """Each name a loop or point vector uses, with how: "length" or "angle" (a bare number
    or a table without a unit takes the file's unit for its use)."""
    out: dict[str, set[str]] = {}
    vectors: list[Any] = []
    for loop in doc.get("loops", []) if isinstance(doc.get("loops"), list) else []:
        if isinstance(loop, Mapping) and isinstance(loop.get("vectors"), list):
            vectors += loop["vectors"]
    points = doc.get("points", {})
    for p in points.values() if isinstance(points, Mapping) else []:
        if isinstance(p, Mapping) and isinstance(p.get("vectors"), list):
            vectors += p["vectors"]
    for v in vectors:
        if isinstance(v, Mapping):
            for kind in ("length", "angle"):
                if isinstance(v.get(kind), str):
                    out.setdefault(v[kind], set()).add(kind)
    return out



def _keep_drawing(mechanism: Mechanism, doc: Mapping[str, Any], source: str) -> None:
    """A drawing's bodies, driver and loads kept with its mechanism (kinematics.forces)."""
    from ..errors import InputError
    from .joints import drawing_of
    from .loads import parse_loads

    drawing = drawing_of(doc, source)
    driver = doc.get("driver", {})
    mechanism.extra["drawing"] = drawing
    mechanism.extra["drawing_driver"] = {k: driver[k] for k in ("link", "slider") if k in driver}
    # the parameters as drawn (internal units): while the ground's are these, its joints
    # are where they were drawn (LoopModel.drawn); a --set or a scan may change them
    mechanism.extra["drawn_parameters"] = {k: q.value for k, q in mechanism.parameters.items()}
    try:
        mechanism.extra["loads"] = parse_loads(doc, drawing, source)
    except InputError as exc:
        raise ParseError(str(exc)) from None



KEY_HINT = "; the key is no longer needed: delete it and the closed form is derived from the loops"
"""What a refused ``closed_form = ...`` claim adds: the way out (the claim is the old way)."""


def _driver_range(spec: Any, driver: Quantity, fail: Any) -> tuple[float, float] | None:
    """``range = [LO, HI]`` under [driver]: two finite numbers in the driver's unit."""
    if spec is None:
        return None
    lo, hi = ([as_float(v) for v in spec] if isinstance(spec, list) and len(spec) == 2
              else (None, None))
    if lo is None or hi is None or not lo < hi:
        raise fail("driver.range", f"must be [LO, HI] with LO < HI, in the driver's unit ({driver.unit})")
    for v in (lo, hi):
        internal = radians(v) if driver.kind == "angle" else v
        why = magnitude_problem(internal, driver.kind, driver.unit, signed=True)
        if why:
            raise fail("driver.range", why)
    return (lo, hi)


def _origin(spec: Any, fail: Any) -> tuple[float, float]:
    """``origin = [x, y]``: where the first loop's first joint is, in the length unit."""
    if spec is None:
        return (0.0, 0.0)
    xy = [as_float(v) for v in spec] if isinstance(spec, list) and len(spec) == 2 else None
    if xy is None or any(v is None or magnitude_problem(v, "length", "", signed=True) for v in xy):
        raise fail("origin", "must be [x, y]: where the first loop's first joint is, two finite "
                             "numbers in the file's length_unit")
    return (xy[0], xy[1])  # type: ignore[return-value]


def _points(spec: Any, loops: list[Loop], vector: Any,
            fail: Any) -> dict[str, tuple[str, tuple[VectorTerm, ...]]]:
    """``[points.NAME]`` tables: a named joint to start from and vectors to add."""
    if not isinstance(spec, Mapping):
        raise fail("points", "must be a table of points, like [points.P]")
    if len(spec) > MAX_POINTS:
        raise fail("points", f"{len(spec):,} points; at most {MAX_POINTS} are accepted (each is a "
                             "column at every position)")
    joints = {j for loop in loops for j in loop.joints if j}
    out = {}
    for pname, p in spec.items():
        key = f"points.{pname}"
        if not isinstance(p, Mapping):
            raise fail(key, "must be a table with 'from' and 'vectors'")
        for k in p:
            if k not in ("from", "vectors", "note"):
                raise fail(f"{key}.{k}", "unknown key (expected from, vectors)")
        origin = p.get("from")
        if not isinstance(origin, str) or origin not in joints:
            named = ", ".join(sorted(joints)) if joints else "none: give the loops joints = [...]"
            raise fail(f"{key}.from", f"must name a joint of the loops ({named}), got {_short(origin)}")
        if pname in joints:
            raise fail(key, f"{pname!r} is already a joint")
        vecs = p.get("vectors")
        if not isinstance(vecs, list) or not vecs:
            raise fail(f"{key}.vectors", "must list at least one vector")
        if len(vecs) > MAX_VECTORS:
            raise fail(f"{key}.vectors", f"{len(vecs):,} vectors; at most {MAX_VECTORS} are accepted")
        out[str(pname)] = (origin, tuple(vector(v, f"{key}.vectors[{i}]", set())
                                         for i, v in enumerate(vecs)))
    return out


CONTROL_CHARACTERS = "[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]"
"""Control characters (ESC, CR, NUL, tab, newline, DEL, C1) and the bidirectional ones
(U+202E and its kin), a regular expression's class: printed raw they would drive the
terminal, break a line, or make text read in an order other than the one it is in."""


@functools.cache
def _control() -> re.Pattern[str]:
    return re.compile(CONTROL_CHARACTERS)


def control_character(text: str) -> re.Match[str] | None:
    """The first of :data:`CONTROL_CHARACTERS` in ``text``, or None. Every one of them is
    a character ``str.isprintable`` refuses (Unicode's Cc and Cf), so printable text needs
    no search, and the expression is compiled only when a text is not (a cold start that
    reads a printable file compiles none)."""
    return None if text.isprintable() else _control().search(text)
_PROSE = ("description", "notes", "note")
"""Keys whose text may have tabs and newlines."""


def _check_printable(doc: Mapping[str, Any], fail: Any) -> None:
    """Refuse a control character in any key or string (tab and newline are allowed in the
    prose of _PROSE): everything read may be printed."""
    stack: list[tuple[str, str, Any]] = [("", "", doc)]
    while stack:
        where, last, value = stack.pop()
        if isinstance(value, str):
            bad = control_character(value.replace("\n", "").replace("\t", "") if last in _PROSE
                                    else value)
            if bad:
                raise fail(where, f"contains the control character {bad.group()!r}; use "
                                  "printable text")
        elif isinstance(value, Mapping):
            for k, v in value.items():
                key = f"{where}.{k}" if where else str(k)
                if isinstance(k, str) and control_character(k):
                    raise fail(ascii(key), "a name may not contain control characters")
                stack.append((key, str(k), v))
        elif isinstance(value, list):
            stack.extend((f"{where}[{i}]", last, v) for i, v in enumerate(value))


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"


def _ref(value: Any, key: str, kind: str, known: Mapping[str, Quantity], fail: Any,
         used: set[str]) -> str | float:
    if value is None:
        raise fail(key, "missing")
    if isinstance(value, bool):
        raise fail(key, f"must be a name or a number, got {value!r}")
    if isinstance(value, (int, float)):
        v = as_float(value)
        if v is None:
            raise fail(key, f"must be a finite number, got {_short(value)}")
        internal = radians(v) if kind == "angle" else v
        why = magnitude_problem(internal, kind, "")
        if why:
            raise fail(key, why)
        if kind == "length" and internal <= 0.0:  # the rule of [parameters] lengths (_parameters)
            raise fail(key, f"a length must be > 0, got {v!r} (give sign = -1 to reverse a vector, "
                            "or a parameter with signed = true for an offset)")
        return internal
    if not isinstance(value, str):
        raise fail(key, f"must be a name or a number, got {value!r}")
    q = known.get(value)
    if q is None:
        raise fail(key, f"unknown name {value!r} (parameters, driver and unknowns: "
                        f"{', '.join(known)})")
    if q.kind != kind:
        raise fail(key, f"{value!r} is a {q.kind}, not a {kind}")
    used.add(value)
    return value


