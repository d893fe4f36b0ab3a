"""Mechanisms as data: vector loops read from TOML, turned into loop equations and Jacobians.

A loop is a list of planar vectors that sums to zero. Each vector is
``sign * length * e^(i * angle)``; ``length`` and ``angle`` each name a parameter,
the driver or an unknown, or give a number; an angle may add a fixed ``offset``
(rigid ternary links). Each loop gives two real equations (x and y). Derivatives are
exact: d/d(angle) of r e^(i t) is i r e^(i t), d/d(length) is e^(i t).

File layout (see sample_inputs/ for complete, commented examples)::

    name = "..."
    length_unit = "cm"                      # every length shares it
    closed_form = "fourbar"                 # no longer needed (derived from the loops);
                                            # still read and checked: "fourbar", "slider_crank"
    [parameters]                            # fixed values; angles in deg unless unit = "rad"
    r1 = { value = 90, unit = "cm" }        # a link: must be > 0
    e = { value = 0, unit = "cm", signed = true }   # an offset: any sign
    theta1 = { value = 0, unit = "deg" }
    [driver]                                # the input: a name and a value
    name = "theta2"
    value = 65
    unit = "deg"
    [unknowns]                              # each with its kind and initial guess
    theta3 = { guess = 0, unit = "deg" }
    [[loops]]
    name = "ABCD"
    vectors = [ { length = "r2", angle = "theta2" }, { length = "r4", angle = "theta4", sign = -1 } ]
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from ..errors import InputError, ParseError
from .columns import column_clash
from .system import SystemProblem

if TYPE_CHECKING:
    from .derive import Derivation

ANGLE_UNITS = {"deg": math.pi / 180.0, "rad": 1.0}

LENGTH_RANGE = (1e-100, 1e100)
"""Magnitudes a nonzero length may have: squares and products of two stay normal doubles."""

LENGTH_UNITS = {"mm": 10, "cm": 100, "m": 10_000, "in": 254, "ft": 3048}
"""Lengths a file may give in another of these units than its length_unit, converted on
read: each in tenths of a millimetre, exactly (an inch is 25.4 mm by definition)."""


def length_factor(unit: str, length_unit: str) -> float:
    """The double nearest the exact ratio of two LENGTH_UNITS (in to mm: 25.4): a true
    division of integers is correctly rounded."""
    return LENGTH_UNITS[unit] / LENGTH_UNITS[length_unit]


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


ANGLE_LIMIT_DEG = 1e6
"""Largest |angle| in degrees: beyond it a degree has too few bits to follow a sweep."""

MAX_LOOPS = 12
"""Most loops in a file, so at most 24 unknowns: a real mechanism has 1 to 5 loops, and the
dense LU of each Newton step costs the cube of the unknowns in pure Python."""
MAX_VECTORS = 24
"""Most vectors in one loop or one point's path."""
MAX_POINTS = 24
"""Most ``[points]``: each is a column of every position of a sweep or a scan."""


def magnitude_problem(value: float, kind: str, unit: str, signed: bool = False) -> str | None:
    """Why a finite value is out of the range this engine can represent faithfully, or None.
    A signed length (an offset) may be as small as it likes: it only adds to others."""
    if kind == "angle":
        deg = value * 180.0 / math.pi
        if abs(deg) > ANGLE_LIMIT_DEG:
            return f"an angle must be within +-{ANGLE_LIMIT_DEG:g} deg, got {deg:g} deg"
        return None
    lo, hi = LENGTH_RANGE
    if signed:
        lo = 0.0
    if value != 0.0 and not lo <= abs(value) <= hi:
        return (f"a length must be 0 or between {lo:g} and {hi:g} {unit} in magnitude, got {value!r} "
                "(change length_unit to rescale)")
    return None


def as_float(value: Any) -> float | None:
    """A TOML or CLI number as a finite float; None for booleans, non-numbers, overflow, NaN."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        v = float(value)
    except OverflowError:
        return None
    return v if math.isfinite(v) else None


# Quantity, VectorTerm and Loop are NamedTuples, not frozen dataclasses: built once per
# class at import, one costs 0.1 ms against 0.7 ms, and every mechanism command's start
# pays for its classes.
class Quantity(NamedTuple):
    name: str
    kind: str  # "angle" or "length"
    value: float  # internal units (rad for angles)
    unit: str  # as written in the file
    signed: bool = False  # an offset: may be zero or negative (links must be > 0)


class VectorTerm(NamedTuple):
    sign: float
    length: str | float  # a name or a number (in the file's length unit)
    angle: str | float  # a name or a number (internal: rad)
    offset: float = 0.0  # rad


class Loop(NamedTuple):
    name: str
    vectors: tuple[VectorTerm, ...]
    joints: tuple[str, ...] = ()  # the start point of each vector ("" unnamed), for drawings


@dataclass(frozen=True)
class Mechanism:
    """A mechanism read from a file: parameters, driver, unknowns and vector loops."""

    name: str
    source: str
    length_unit: str
    parameters: dict[str, Quantity]
    driver: Quantity
    unknowns: tuple[Quantity, ...]  # value = initial guess
    loops: tuple[Loop, ...]
    closed_form: str | None = None
    description: str = ""
    extra: dict[str, Any] = field(default_factory=dict)
    points: dict[str, tuple[str, tuple[VectorTerm, ...]]] = field(default_factory=dict)
    """Named points on links: name -> (the joint it starts from, its vectors)."""
    origin: tuple[float, float] = (0.0, 0.0)
    """Where the first loop's first joint is (length unit): a drawing's joints are placed
    where they were drawn."""
    driver_range: tuple[float, float] | None = None
    """``[driver] range = [LO, HI]``, in the driver's unit: what a sweep, a scan and an
    animation run over unless told otherwise."""

    def value_of(self, name: str) -> Quantity:
        if name == self.driver.name:
            return self.driver
        return self.parameters[name]

    def with_values(self, overrides: Mapping[str, float], guesses: Mapping[str, float]) -> Mechanism:
        """Override parameters/driver (``--set``) and guesses (``--guess``), in file units:
        each a mapping of name to number (arguments.check_number: not a bool, not a string)."""
        from ..arguments import check_number, describe

        checked = []
        for label, given in (("overrides", overrides), ("guesses", guesses)):
            if not isinstance(given, Mapping):
                raise InputError(f"{label}: give a dict of name -> number, got {describe(given)}")
            checked.append({k: check_number(f"{label}[{k!r}]", v) for k, v in given.items()})
        overrides, guesses = checked
        params = dict(self.parameters)
        driver = self.driver
        for key, v in overrides.items():
            if key == driver.name:
                driver = _requantify(driver, v)
            elif key in params:
                params[key] = _requantify(params[key], v)
                if params[key].kind == "length" and not params[key].signed and params[key].value <= 0.0:
                    raise ParseError(f"--set {key}: a length must be > 0, got {v!r} "
                                     "(declare signed = true for an offset)")
            else:
                known = ", ".join([driver.name, *params])
                raise ParseError(f"--set {key}: no parameter or driver named {key!r} in "
                                 f"{self.source} (known: {known})")
        unknowns = list(self.unknowns)
        for key, v in guesses.items():
            idx = next((i for i, u in enumerate(unknowns) if u.name == key), None)
            if idx is None:
                raise ParseError(f"--guess {key}: no unknown named {key!r} in {self.source} "
                                 f"(unknowns: {', '.join(u.name for u in unknowns)})")
            unknowns[idx] = _requantify(unknowns[idx], v)
        return Mechanism(self.name, self.source, self.length_unit, params, driver, tuple(unknowns),
                         self.loops, self.closed_form, self.description, self.extra, self.points,
                         self.origin, self.driver_range)

    def problem(self) -> SystemProblem:
        return build_problem(self)

    @property
    def closed_form_note(self) -> str | None:
        """What to tell the reader of a file that still says ``closed_form = ...`` (None
        for one that does not): the key is read and checked, but the closed form now comes
        from the loops (:attr:`derivation`). A program prints it; the library does not."""
        if self.closed_form is None:
            return None
        return f"{self.source}: closed_form is no longer needed: the closed form is derived from the loops"

    @property
    def drawing_note(self) -> str | None:
        """Where a drawing was drawn when its [driver] value is elsewhere (None otherwise):
        a program prints it beside its output, as :attr:`closed_form_note`."""
        return self.extra.get("drawing_note")

    @functools.cached_property
    def derivation(self) -> Derivation:
        """The stepwise closed form derived from the loops (:mod:`.derive`), or why there
        is none (``.complete`` is False)."""
        from .derive import derive

        return derive(self)

    @functools.cached_property
    def model(self) -> LoopModel:
        """The loop model, compiled once per mechanism (its generated functions with it)."""
        return LoopModel.compile(self)

    def __getstate__(self) -> dict[str, Any]:
        # the compiled model holds generated functions, which do not pickle (scans send
        # mechanisms to worker processes): a worker compiles its own
        state = dict(self.__dict__)
        state.pop("model", None)
        return state

    @functools.cached_property
    def length_scale(self) -> float:
        """The longest length in the loops (parameters, numbers, a length driver): the
        size that residual tolerances are relative to."""
        sizes = [abs(q.value) for q in self.parameters.values() if q.kind == "length"]
        if self.driver.kind == "length":
            sizes.append(abs(self.driver.value))
        sizes += [abs(t.length) for loop in self.loops for t in loop.vectors
                  if isinstance(t.length, float)]
        big = max(sizes, default=0.0)
        return big if big > 0.0 else 1.0


def _requantify(q: Quantity, value: float) -> Quantity:
    if not math.isfinite(value):
        raise ParseError(f"{q.name} must be finite, got {value!r}")
    scale = ANGLE_UNITS[q.unit] if q.kind == "angle" else 1.0
    internal = value * scale
    why = magnitude_problem(internal, q.kind, q.unit, q.signed)
    if why:
        raise ParseError(f"{q.name}: {why}")
    return Quantity(q.name, q.kind, internal, q.unit, q.signed)


# --- loading ------------------------------------------------------------------------------

def load(path: str | Path) -> Mechanism:
    """Read and validate a mechanism file; every error names the file and the key."""
    from ..arguments import check_path  # (arguments imports nothing of ours: no cycle)
    from ..files import read_input

    p = Path(check_path("path", path))
    return from_text(read_input(p), str(p))


def mechanism_of(name: str, value: Any) -> Mechanism:
    """A Mechanism, or a path (str or os.PathLike) to a mechanism file, loaded: the API's
    front doors take either (:mod:`linkage.arguments` checks everything else)."""
    from ..arguments import describe

    if isinstance(value, Mechanism):
        return value
    if isinstance(value, (str, PathLike)):
        return load(value)
    raise InputError(f"{name} must be a Mechanism or a path to a mechanism file, got {describe(value)}")


def from_text(text: str, source: str) -> Mechanism:
    """A mechanism from the text of a file (read once: ``-`` cannot be read twice)."""
    from ..files import parse_toml

    return parse_mechanism(parse_toml(text, source), source)


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


def _at_driver_value(m: Mechanism, doc: Mapping[str, Any], source: str) -> Mechanism:
    """A drawing whose [driver] value is not where it is drawn (problems.joints.off_drawing):
    its guesses moved to that value on the drawing's branch - the drawn pose's signs, the
    branch a sweep follows unless told (kinematics.pose.file_branch), solved there by the
    derived closed form (:meth:`~.derive.Derivation.solve`) - so that solve, sweep and scan
    take the drawing's assembly there; the note :attr:`Mechanism.drawing_note` says where
    it was drawn. Loops without a closed form are solved there from the drawn pose and
    must keep its sign of det J. A value the drawing's branch does not reach is refused."""
    from .closed_form import wrap_degrees
    from .joints import off_drawing

    driver = doc["driver"]
    value = _display(m.driver)
    drawn = off_drawing(m.extra["drawing"], driver, value)
    if drawn is None:
        return m
    angle = m.driver.kind == "angle"
    scale = ANGLE_UNITS[m.driver.unit] if angle else 1.0
    what = f"{driver['link']} is drawn at {drawn:.9g} deg" if angle else \
        f"{driver['slider']} is drawn at travel {drawn:.9g} {m.length_unit}"
    unit = " deg" if angle else f" {m.length_unit}"
    to = (drawn + wrap_degrees(value - drawn) if angle else value) * scale  # an angle: the same turn
    q = _on_drawn_branch(m, [u.value for u in m.unknowns], drawn * scale, to)
    if q is None:
        raise ParseError(f"{source}: driver.value: {value:g}{unit} is not reached from the drawing ({what}) "
                         "on its branch: the linkage does not assemble there that way; leave value out to "
                         "solve where it is drawn")
    moved = m.with_values({}, {u.name: math.degrees(v) if u.kind == "angle" else v
                               for u, v in zip(m.unknowns, q)})
    moved.extra["drawing_note"] = (f"{source}: {what}; solved at [driver] value = {value:g}{unit}, on the "
                                   "drawing's branch")
    return moved


def _on_drawn_branch(m: Mechanism, q0: list[float], start: float, to: float) -> list[float] | None:
    """The configuration at driver ``to`` on the branch of ``q0`` (the drawn pose, exact
    at ``start``), internal units; None where that branch has no assembly there."""
    from ..methods._linalg import SingularMatrix, det_from_lu, lu
    from ..solve import solve_system

    d = m.derivation
    if d.complete:
        from .derive import Indeterminate

        signs = d.signs_of(q0, start)
        try:
            return d.solve(to, signs) if all(signs) or not d.two_way else None
        except Indeterminate:
            return None
    r = solve_system(m.model.problem_at(to, tuple(q0)), tol=1e-12)

    def det_sign(driver: float, q: Any) -> float:
        try:
            return math.copysign(1.0, det_from_lu(lu(m.model.problem_at(driver).J(list(q)))))
        except SingularMatrix:
            return 0.0

    return list(r.x) if r.converged and det_sign(to, r.x) == det_sign(start, q0) != 0.0 else None


def parse_mechanism(doc: Mapping[str, Any], source: str = "<mechanism>") -> Mechanism:
    def fail(key: str, msg: str) -> ParseError:
        return ParseError(f"{source}: {key}: {msg}")

    from .joints import is_joints_doc, loops_doc

    _check_printable(doc, fail)  # a drawing's too, before its names are in a message
    drawn: Mapping[str, Any] | None = None
    if is_joints_doc(doc):  # a drawing: its loops derived (problems/joints.py)
        drawn = doc
        doc = loops_doc(doc, source)

    allowed = {"name", "description", "length_unit", "closed_form", "parameters", "driver",
               "unknowns", "loops", "notes", "points", "origin"}
    for key in doc:
        if key not in allowed:
            raise fail(key, f"unknown key (expected one of {', '.join(sorted(allowed))})")
    name = doc.get("name")
    if not isinstance(name, str) or not name:
        raise fail("name", "missing or not a string")
    length_unit = doc.get("length_unit")
    if not isinstance(length_unit, str) or not length_unit:
        raise fail("length_unit", "missing: give the unit every length uses, e.g. \"mm\"")
    closed_form = doc.get("closed_form")
    if closed_form is not None and closed_form not in ("fourbar", "slider_crank"):
        raise fail("closed_form", f"unknown closed form {closed_form!r} (fourbar or slider_crank)")

    use = kinds_by_use(doc)
    accepted = accepted_units(length_unit)  # for the messages

    def quantity(key: str, qname: str, spec: Any, field_name: str) -> Quantity:
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
        unit = spec.get("unit")
        if unit is None:
            kinds = use.get(qname, set())
            if len(kinds) != 1:
                how = ("is used as " + " and as ".join(sorted(kinds)) if kinds else "is in no loop")
                raise fail(key, f"{qname} {how}, so its unit cannot be read from its use: give "
                                f"unit = one of {accepted}")
            unit = "deg" if kinds == {"angle"} else length_unit  # the file's unit for its kind
        if not isinstance(unit, str):
            raise fail(f"{key}.unit", f"must be one of {accepted}, got {_short(unit)}")
        if unit != length_unit and unit in LENGTH_UNITS and length_unit in LENGTH_UNITS:
            value *= length_factor(unit, length_unit)  # converted on read: the file's unit inside
            unit = length_unit
        if unit in ANGLE_UNITS or unit == length_unit:
            kind = "angle" if unit in ANGLE_UNITS else "length"
            internal = value * ANGLE_UNITS[unit] if kind == "angle" else value
            why = magnitude_problem(internal, kind, str(unit), signed)
            if why:
                raise fail(f"{key}.{field_name}", why)
            return Quantity(qname, kind, internal, unit, signed if kind == "length" else False)
        raise fail(f"{key}.unit", f"unknown unit {unit!r}: use one of {accepted}")

    params_doc = doc.get("parameters", {})
    if not isinstance(params_doc, Mapping):
        raise fail("parameters", "must be a table")
    parameters = {k: quantity(f"parameters.{k}", k, v, "value") for k, v in params_doc.items()}
    for k, q in parameters.items():
        if q.kind == "length" and not q.signed and q.value <= 0.0:
            raise fail(f"parameters.{k}.value", f"a length must be > 0, got {q.value!r} "
                                                "(declare signed = true for an offset)")

    drv = doc.get("driver")
    if not isinstance(drv, Mapping) or "name" not in drv:
        raise fail("driver", "missing: give [driver] with name, value and unit")
    drv_name = drv["name"]
    if not isinstance(drv_name, str):
        raise fail("driver.name", "must be a string")
    driver = quantity("driver", drv_name, {k: v for k, v in drv.items() if k not in ("name", "range")},
                      "value")
    driver_range = _driver_range(drv.get("range"), driver, fail)
    if drv_name in parameters:
        raise fail("driver.name", f"{drv_name!r} is also listed under [parameters]")

    unk_doc = doc.get("unknowns")
    if not isinstance(unk_doc, Mapping) or not unk_doc:
        raise fail("unknowns", "missing: list each unknown with its guess and unit")
    if len(unk_doc) > 2 * MAX_LOOPS:
        raise fail("unknowns", f"{len(unk_doc):,} unknowns; at most {2 * MAX_LOOPS} ({MAX_LOOPS} "
                               "loops) are accepted, far above any real mechanism")
    unknowns = tuple(quantity(f"unknowns.{k}", k, v, "guess") for k, v in unk_doc.items())
    clash = [u.name for u in unknowns if u.name in parameters or u.name == drv_name]
    if clash:
        raise fail(f"unknowns.{clash[0]}", "is also a parameter or the driver")

    known = {**parameters, drv_name: driver, **{u.name: u for u in unknowns}}

    def vector(vec: Any, vkey: str, used: set[str]) -> VectorTerm:
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
        return VectorTerm(float(sign), length, angle, math.radians(offset))

    loops_doc = doc.get("loops")
    if not isinstance(loops_doc, list) or not loops_doc:
        raise fail("loops", "missing: give at least one [[loops]] with its vectors")
    if len(loops_doc) > MAX_LOOPS:
        raise fail("loops", f"{len(loops_doc):,} loops; at most {MAX_LOOPS} are accepted, far "
                            "above any real mechanism")
    loops = []
    used: set[str] = set()
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
        terms = []
        for vi, vec in enumerate(loop["vectors"]):
            terms.append(vector(vec, f"{lkey}.vectors[{vi}]", used))
        loops.append(Loop(str(loop.get("name", f"loop {li + 1}")), tuple(terms), tuple(joints)))

    n_eq = 2 * len(loops)
    if n_eq != len(unknowns):
        raise fail("unknowns", f"{len(loops)} loop(s) give {n_eq} equations but there are "
                               f"{len(unknowns)} unknowns ({', '.join(u.name for u in unknowns)})")
    if closed_form is not None:
        from .closed_form import REQUIRED_NAMES

        missing = [k for k in REQUIRED_NAMES[closed_form] if k not in known]
        if missing:
            raise fail("closed_form", f"{closed_form} needs the names {', '.join(missing)}{KEY_HINT}")
    unused = [u.name for u in unknowns if u.name not in used]
    if unused:
        raise fail(f"unknowns.{unused[0]}", "appears in no loop")
    if drv_name not in used:
        raise fail("driver.name", f"{drv_name!r} appears in no loop")
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
        mechanism = _at_driver_value(mechanism, drawn, source)
    if closed_form is not None:
        from .closed_form import verify

        why = verify(mechanism)
        if why:
            raise fail("closed_form", f"{closed_form!r} does not describe this file: {why}{KEY_HINT}")
        if not mechanism.derivation.complete:
            raise fail("closed_form", f"{closed_form!r} does not describe this file: "
                                      f"{mechanism.derivation.summary}{KEY_HINT}")
    return mechanism


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
        internal = math.radians(v) if driver.kind == "angle" else v
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


_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]")
"""Control characters (ESC, CR, NUL, tab, newline, DEL, C1) and the bidirectional ones
(U+202E and its kin): printed raw they would drive the terminal, break a line, or make
text read in an order other than the one it is in."""
_PROSE = ("description", "notes", "note")
"""Keys whose text may have tabs and newlines."""


def _check_printable(doc: Mapping[str, Any], fail: Any) -> None:
    """Refuse a control character in any key or string (tab and newline are allowed in the
    prose of _PROSE): everything read may be printed."""
    stack: list[tuple[str, str, Any]] = [("", "", doc)]
    while stack:
        where, last, value = stack.pop()
        if isinstance(value, str):
            bad = _CONTROL.search(value.replace("\n", "").replace("\t", "") if last in _PROSE
                                  else value)
            if bad:
                raise fail(where, f"contains the control character {bad.group()!r}; use "
                                  "printable text")
        elif isinstance(value, Mapping):
            for k, v in value.items():
                key = f"{where}.{k}" if where else str(k)
                if isinstance(k, str) and _CONTROL.search(k):
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
        internal = math.radians(v) if kind == "angle" else v
        why = magnitude_problem(internal, kind, "")
        if why:
            raise fail(key, why)
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


# --- equations ----------------------------------------------------------------------------

DRIVER = -2
"""Index marking a term that refers to the driver (``-1``: a fixed value)."""


def drawn_ground(m: Mechanism, values: Mapping[str, Any]) -> dict[str, tuple[float, float]]:
    """A drawing's fixed joints at their drawn (x, y), when ``values`` (the parameters a
    model is compiled with) give every vector that turns with nothing (the ground's: no
    unknown, no driver) its drawn length and angle; else none (a --set or a scan moved a
    ground joint, and the vectors place it)."""
    drawing = m.extra.get("drawing")
    as_drawn = m.extra.get("drawn_parameters")
    if drawing is None or as_drawn is None:
        return {}
    moving = {u.name for u in m.unknowns} | {m.driver.name}
    for loop in m.loops:
        for t in loop.vectors:
            refs = (t.length, t.angle)
            if any(isinstance(r, str) and r in moving for r in refs):
                continue
            for r in refs:
                if isinstance(r, str) and not (type(values[r]) is float and values[r] == as_drawn.get(r)):
                    return {}
    return {j: drawing.xy[j] for j in drawing.ground}


@dataclass(frozen=True)
class LoopModel:
    """The loops compiled once: each term is (sign, length constant, length index, angle
    constant, angle index, offset); an index >= 0 is an unknown, DRIVER the driver."""

    mechanism: Mechanism
    terms: tuple[tuple[tuple[float, float, int, float, int, float], ...], ...]
    n: int
    point_terms: dict[str, tuple[str, tuple[tuple[float, float, int, float, int, float], ...]]] = field(
        default_factory=dict)
    drawn: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Joints that do not move, each exactly where it was drawn: a drawing's fixed joints,
    while the ground's lengths and angles are the drawn ones (:func:`drawn_ground`). The
    placing rule (kinematics.rates._walk) reports them as drawn, not as the sum of
    vectors that reaches them (a pivot drawn at 45.0 came out 44.99999999999999)."""

    @classmethod
    def compile(cls, m: Mechanism, values: Mapping[str, Any] | None = None) -> LoopModel:
        """``values``: parameters (internal units) to use instead of the file's, numbers or
        numpy arrays (one per position: a scan's designs); a model with arrays is for the
        numpy twins (kinematics.rates.place_motion_np), not for :attr:`factory`."""
        index = {u.name: i for i, u in enumerate(m.unknowns)}
        fixed = {k: q.value for k, q in m.parameters.items()}
        fixed.update(values or {})

        def resolve(ref: str | float) -> tuple[float, int]:
            if isinstance(ref, str):
                if ref in index:
                    return 0.0, index[ref]
                if ref == m.driver.name:
                    return 0.0, DRIVER
                return fixed[ref], -1
            return ref, -1

        loops = []
        for loop in m.loops:
            terms = []
            for t in loop.vectors:
                lc, li = resolve(t.length)
                ac, ai = resolve(t.angle)
                terms.append((t.sign, lc, li, ac, ai, t.offset))
            loops.append(tuple(terms))
        points = {name: (origin, tuple((t.sign, *resolve(t.length), *resolve(t.angle), t.offset)
                                       for t in vecs))
                  for name, (origin, vecs) in m.points.items()}
        return cls(m, tuple(loops), len(m.unknowns), points, drawn_ground(m, fixed))

    @functools.cached_property
    def factory(self) -> Any:
        """The compiled model: ``factory(driver) -> (F, J, V)`` (see :mod:`linkage.codegen`)."""
        from ..codegen import build

        return build(self.terms, self.n)

    @property
    def source(self) -> str:
        """The generated code of the compiled model, for inspection."""
        from ..codegen import source

        return source(self.terms, self.n)

    def functions(self, driver: float) -> tuple[Any, Any]:
        """Phi(q) and J(q) at one driver value (internal units), compiled."""
        F, J, _ = self.factory(driver)
        return F, J

    def driver_derivative(self, driver: float) -> Any:
        """dPhi/d(driver)(q) at one driver value, compiled."""
        return self.factory(driver)[2]

    def interpreted_functions(self, driver: float) -> tuple[Any, Any]:
        """Phi(q) and J(q) by walking the terms: the definition the compiled code is
        tested against."""
        n = self.n
        # Resolve the driver into constants once, so the closures see only fixed terms.
        loops = [[(s, driver if li == DRIVER else lc, -1 if li == DRIVER else li,
                   driver if ai == DRIVER else ac, -1 if ai == DRIVER else ai, off)
                  for s, lc, li, ac, ai, off in terms] for terms in self.terms]
        cos, sin = math.cos, math.sin

        def F(q: Any) -> list[float]:
            out = []
            for terms in loops:
                x = y = 0.0
                for sign, lc, li, ac, ai, off in terms:
                    r = q[li] if li >= 0 else lc
                    th = (q[ai] if ai >= 0 else ac) + off
                    x += sign * r * cos(th)
                    y += sign * r * sin(th)
                out.append(x)
                out.append(y)
            return out

        def J(q: Any) -> list[list[float]]:
            rows = []
            for terms in loops:
                jx = [0.0] * n
                jy = [0.0] * n
                for sign, lc, li, ac, ai, off in terms:
                    r = q[li] if li >= 0 else lc
                    th = (q[ai] if ai >= 0 else ac) + off
                    c, s = cos(th), sin(th)
                    if ai >= 0:
                        jx[ai] -= sign * r * s
                        jy[ai] += sign * r * c
                    if li >= 0:
                        jx[li] += sign * c
                        jy[li] += sign * s
                rows.append(jx)
                rows.append(jy)
            return rows

        return F, J

    def points(self, q: Any, driver: float) -> list[list[complex]]:
        """Cumulative vector sums along each loop, the joints to draw: the first loop from
        the file's origin, a later loop from its first joint where an earlier loop placed it (a
        six-bar's second loop at the rocker pivot), else from the origin too."""
        out = []
        placed: dict[str, complex] = {}
        for loop, terms in zip(self.mechanism.loops, self.terms):
            names = loop.joints
            start = complex(*self.mechanism.origin)
            p = placed.get(names[0], start) if names and names[0] else start
            pts = [p]
            for sign, lc, li, ac, ai, off in terms:
                r = q[li] if li >= 0 else (driver if li == DRIVER else lc)
                th = (q[ai] if ai >= 0 else (driver if ai == DRIVER else ac)) + off
                p += sign * r * complex(math.cos(th), math.sin(th))
                pts.append(p)
            for name, point in zip(names, pts):
                if name:
                    placed.setdefault(name, point)
            out.append(pts)
        return out

    def problem_at(self, driver: float, x0: tuple[float, ...] | None = None) -> SystemProblem:
        m = self.mechanism
        F, J = self.functions(driver)
        eq_names = []
        for loop in m.loops:
            eq_names += [f"{loop.name}.x", f"{loop.name}.y"]
        shown = driver / ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else driver
        # the value as typed: degrees -> radians -> degrees leaves 59.99999999999999 for 60
        shown = float(f"{shown:.12g}")
        reference = branch_of = None
        if m.derivation.complete:
            # any parameter names, any driver, any number of loops: what the loops give
            reference, branch_of = derived_reference(m, driver)
        return SystemProblem(
            F=F, J=J,
            names=tuple(u.name for u in m.unknowns),
            kinds=tuple(u.kind for u in m.unknowns),
            length_unit=m.length_unit,
            equation_names=tuple(eq_names),
            x0=x0 if x0 is not None else tuple(u.value for u in m.unknowns),
            title=f"{m.name}: {m.driver.name} = {shown:g} {m.driver.unit}",
            reference=reference,
            branch_of=branch_of,
            meta={"driver": m.driver.name, "driver_value": shown, "driver_unit": m.driver.unit,
                  "source": m.source, "mechanism": m.name},
            length_scale=m.length_scale,
        )


ONLY = "only"
"""The name of the one assembly of a closed form with no two-way step (every step linear)."""


def derived_reference(m: Mechanism, driver: float) -> tuple[Callable[[], dict[str, dict[str, float]] | None],
                                                            Callable[[dict[str, float]], str]]:
    """The closed form derived from the loops (:attr:`Mechanism.derivation`, complete) at a
    driver value (internal units): ``reference()`` gives every assembly in display units,
    keyed by its branch name ({} where it cannot be assembled, None at a change point);
    ``branch_of(solution in display units)`` names a configuration's branch.

    Angles are shown in (-180, 180], as solve's true error compares them (the difference
    brought within a turn): a crossed slider-crank's theta3 = -171.24 is the same angle
    as 188.76, and no false 360 appears."""
    from .closed_form import wrap_degrees
    from .derive import Indeterminate

    derivation = m.derivation
    names = tuple(u.name for u in m.unknowns)
    angles = tuple(u.kind == "angle" for u in m.unknowns)

    def reference() -> dict[str, dict[str, float]] | None:
        # built when read: sweeps create several problems per position and rarely ask for
        # the closed form. At the driver value the loops are solved at, not the 12-digit
        # one shown: near a limit the answer moves like the square root of the distance
        try:
            named = derivation.named_solutions(driver)
        except (Indeterminate, ArithmeticError):
            return None
        return {key or ONLY: {n: wrap_degrees(math.degrees(v)) if a else v
                              for n, a, v in zip(names, angles, q)}
                for key, (_, q) in named.items()}

    def branch_of(solution: dict[str, float]) -> str:
        q = [math.radians(solution[n]) if a else solution[n] for n, a in zip(names, angles)]
        return derivation.name_of(q, driver) or ONLY

    return reference, branch_of


def build_problem(m: Mechanism) -> SystemProblem:
    """Phi(q) and its exact Jacobian at the mechanism's own driver value."""
    return m.model.problem_at(m.driver.value)


def _display(q: Quantity) -> float:
    return q.value / ANGLE_UNITS[q.unit] if q.kind == "angle" else q.value
