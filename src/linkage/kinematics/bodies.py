"""The drawing's bodies as the matrix method (kinematics.forces) needs them, and the loads
checked against them: a file's, the command line's and Python's, one definition
(problems.loads.parse_loads) for all three; SI units from the file's length unit."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..errors import InputError
from ..problems.loads import Loads, parse_loads
from ..records import frozen


def metre(length_unit: str) -> float:
    """Metres per unit of ``length_unit`` (the files' one conversion, loops.length_factor)."""
    from ..problems.loops import length_factor

    return length_factor(length_unit, "m")


def command_loads(mechanism: Any, load: Sequence[str], torque: Sequence[str], gravity: str | None) -> Loads:
    """The file's loads with the command line's added or overriding: ``--load P=FX,FY``
    (N), ``--torque LINK=T`` (N m), ``--gravity G`` (m/s^2 in -y) or ``GX,GY``. A force or
    torque may carry a unit as --speed does (:func:`~linkage.numbers.parse_quantity`), one
    of the file's ``unit =`` names (problems.loads): ``--torque rocker=-2Nm``,
    ``--load P=0,-20N`` (the unit after FY is FX's too)."""
    from ..numbers import parse_number, parse_quantity
    from ..problems.loads import TORQUE_UNITS

    base: Loads = mechanism.extra.get("loads") or Loads()
    spec: dict[str, Any] = {}
    named: dict[str, str] = {}
    in_n_m = {"": 1.0, **TORQUE_UNITS}  # a bare number in N m
    for option, items in (("--load", load), ("--torque", torque)):
        for item in items:
            name, eq, value = item.partition("=")
            name = name.strip()
            named[name] = f"{option} {name}"
            if not eq or not name:
                raise InputError(f"{option} {item!r}: write NAME=" + ("FX,FY" if option == "--load" else "T"))
            if option == "--load":
                parts = value.split(",")
                if len(parts) != 2:
                    raise InputError(f"{option} {item!r}: the force is FX,FY in N (or FX,FY with a unit)")
                spec[name] = {"force": _force(f"{option} {name}", item, parts)}
            else:
                spec[name] = {"torque": parse_quantity(f"{option} {name}", value, in_n_m)[0]}
    g: tuple[float, float] | None = None
    if gravity is not None:
        parts = gravity.split(",")
        if len(parts) == 1:
            g = (0.0, -abs(parse_number("--gravity", parts[0])))
        elif len(parts) == 2:
            g = (parse_number("--gravity", parts[0]), parse_number("--gravity", parts[1]))
        else:
            raise InputError(f"--gravity {gravity!r}: give G (m/s^2, in -y) or GX,GY")
        if not all(math.isfinite(v) and abs(v) <= 1e6 for v in g):
            raise InputError(f"--gravity {gravity!r}: must be finite, within 1e6 m/s^2")
    drawing = mechanism.extra.get("drawing")
    if (spec or g is not None) and drawing is None:
        Frame.of(mechanism)  # says why: loads need the joints form
    extra = parse_loads({"loads": spec}, drawing, "the command line", named) if spec else Loads()
    out = base.merged(Loads(extra.forces, extra.torques, {}, g))
    if g is not None and not out.masses:
        raise InputError(f"--gravity: it acts on the links' masses, and {mechanism.source} gives none: add "
                         "[mass] LINK = { mass = KG, cg = [x, y] } to the file")
    return out


def _force(label: str, item: str, parts: Sequence[str]) -> list[float]:
    """--load's FX,FY in N: a unit typed after either is both's (``0,-20N``, ``5lbf,0``),
    two different units refused."""
    from ..numbers import parse_quantity, unit_key
    from ..problems.loads import FORCE_UNITS

    units = {"": 1.0, **FORCE_UNITS}
    (fx, ux), (fy, uy) = (parse_quantity(label, p, units) for p in parts)
    if ux and uy and unit_key(ux) != unit_key(uy):
        raise InputError(f"--load {item!r}: FX in {ux} and FY in {uy}: give one unit, after FY")
    unit = ux or uy
    return [v if own or not unit else parse_quantity(label, f"{p} {unit}", units)[0]
            for p, v, own in zip(parts, (fx, fy), (ux, uy))]


# --- one position ------------------------------------------------------------------------------


@frozen
class Frame:
    """The drawing's bodies as the matrix method needs them."""

    drawing: Any
    driver_link: str | None
    driver_slider: str | None
    length_unit: str
    size: float = 1.0
    """The mechanism's length scale in m: the force matrix's moment rows and torque
    columns are scaled by it, so its condition number does not depend on the unit."""
    reshaped: tuple[tuple[str, str, float, float], ...] = ()
    """(body, length, value, drawn value) for each moving body's length that is not the
    drawing's (a --set or with_values): a mass given for the drawn shape cannot ride on it."""

    @classmethod
    def of(cls, mechanism: Any) -> Frame:
        drawing = mechanism.extra.get("drawing")
        if drawing is None:
            raise InputError(
                f"{mechanism.source}: loads need links as bodies: give the mechanism in the "
                "joints form (linkage convert --form joints FILE writes it)"
            )
        from ..problems.loops import LENGTH_UNITS

        unit = mechanism.length_unit
        if unit not in LENGTH_UNITS:
            raise InputError(f"{mechanism.source}: length_unit {unit!r}: loads are in SI, so the lengths "
                             f"need a known unit: {', '.join(LENGTH_UNITS)}")
        doc = mechanism.extra.get("drawing_driver", {})
        reshaped = []
        for name, (body, drawn) in drawn_lengths(drawing).items():
            q = mechanism.parameters.get(name)
            if q is not None and not abs(q.value - drawn) <= 1e-9 * max(abs(drawn), 1e-300):
                reshaped.append((body, name, q.value, drawn))
        return cls(drawing, doc.get("link"), doc.get("slider"), unit, force_size(mechanism), tuple(reshaped))

    def check_masses(self, loads: Loads, varied: Sequence[str] = ()) -> None:
        """A mass is given for its link's drawn shape (cg in the drawn pose, inertia): refuse
        loads whose massive link has other lengths here (``varied``: lengths a scan varies)."""
        owner = {name: body for name, (body, _) in drawn_lengths(self.drawing).items()}
        for name in varied:
            if owner.get(name) in loads.masses:
                body = owner[name]
                raise InputError(f"--vary {name} changes the shape of {body}, which has a [mass] given for "
                                 f"its drawn lengths (cg, inertia); scan {body}'s lengths without its mass, "
                                 "or vary other links")
        for body, name, value, drawn in self.reshaped:
            if body in loads.masses:
                raise InputError(f"{name} = {value:.10g} here, {drawn:.10g} as drawn: {body} has a [mass] "
                                 "given for its drawn lengths (cg, inertia); draw the link at its new "
                                 "lengths, or drop its mass")


def force_size(mechanism: Any, values: Mapping[str, Any] | None = None) -> Any:
    """The size the force matrix is scaled by (m): the longest length parameter, from
    ``values`` (file units, arrays over positions: a scan's designs) where they give it.
    Not the driver's value: a sliding driver's position must not change the scale."""
    import numpy as np

    size: Any = 0.0
    for name, q in mechanism.parameters.items():
        if q.kind == "length":
            size = np.maximum(size, np.abs((values or {}).get(name, q.value)))
    size = np.where(np.isfinite(size) & (size > 0.0), size, 1.0) * metre(mechanism.length_unit)
    return float(size) if np.ndim(size) == 0 else size


def drawn_lengths(drawing: Any) -> dict[str, tuple[str, float]]:
    """Each moving body's length parameter as the joints form derives it (problems.joints:
    ``<link>`` for its first two joints, ``<link>_<P>_<Q>`` for the others, from its first
    joint), with its body and its drawn value (the file's unit)."""
    out: dict[str, tuple[str, float]] = {}
    for b, js in drawing.bodies.items():
        if b == "ground" or all(j in drawing.points for j in js):
            continue
        c = drawing.center(b)
        for j in js:
            if j != c:
                name = b if (c, j) == tuple(js[:2]) else f"{b}_{c}_{j}"
                out[name] = (b, math.dist(drawing.xy[c], drawing.xy[j]))
    return out


def checked_loads(loads: Any, mechanism: Any) -> Loads:
    """A :class:`Loads` from Python checked as a file's are, by the file's one definition
    (problems.loads.parse_loads: names, shapes, finite values, units) and its gravity as
    the command line's; an InputError naming ``loads`` otherwise."""
    from ..arguments import describe, finite_real
    from ..problems.loads import Mass

    if not isinstance(loads, Loads):
        raise InputError(f"loads: give a linkage.Loads, got {type(loads).__name__}")
    frame = Frame.of(mechanism)
    for field in ("forces", "torques", "masses", "on"):
        if not isinstance(getattr(loads, field), Mapping):
            raise InputError(f"loads: {field} must be a dict, got {type(getattr(loads, field)).__name__}")
    for k in loads.on:
        if k not in loads.forces:
            raise InputError(f"loads: on[{k!r}]: there is no force at {k!r} (on names the link a force "
                             "acts on)")
    table: dict[Any, Any] = {}
    for k, f in loads.forces.items():
        table[k] = {"force": list(f) if isinstance(f, (tuple, list)) else f}
        if k in loads.on:
            table[k]["on"] = loads.on[k]
    for k, t in loads.torques.items():
        if k in table:
            raise InputError(f"loads: {k!r} has a force and a torque: a name is a joint or a link")
        table[k] = {"torque": t}
    masses: dict[Any, Any] = {}
    for k, mm in loads.masses.items():
        if not isinstance(mm, Mass):
            raise InputError(f"loads: masses[{k!r}]: give a linkage.Mass, got {type(mm).__name__}")
        masses[k] = {"mass": mm.mass, "cg": list(mm.cg) if isinstance(mm.cg, (tuple, list)) else mm.cg,
                     "inertia": mm.inertia}
    parsed = parse_loads({"loads": table, "mass": masses}, frame.drawing, "loads")
    g = loads.gravity
    if g is not None:
        ok = isinstance(g, (tuple, list)) and len(g) == 2 and all(
            finite_real(v) is not None and abs(float(v)) <= 1e6 for v in g)
        if not ok:
            raise InputError(f"loads: gravity {describe(g)}: give (gx, gy) in m/s^2, finite, within 1e6")
        g = (float(g[0]), float(g[1]))
    out = Loads(parsed.forces, parsed.torques, parsed.masses, g, parsed.on)
    frame.check_masses(out)
    return out
