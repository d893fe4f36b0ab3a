"""The loads a joints-form mechanism file gives (``[loads]`` and ``[mass]``), read and checked
against its drawing; kinematics.forces solves for the forces they cause."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any

from ..errors import InputError
from ..records import frozen


@frozen
class Mass:
    mass: float
    """kg"""
    cg: tuple[float, float]
    """In the drawn pose, the file's length unit."""
    inertia: float
    """kg m^2, about the centre of mass."""


@frozen
class Loads:
    forces: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Joint or point -> (Fx, Fy) in N, fixed in the ground frame."""
    torques: dict[str, float] = field(default_factory=dict)
    """Link -> N m, counterclockwise positive."""
    masses: dict[str, Mass] = field(default_factory=dict)
    gravity: tuple[float, float] | None = None
    """m/s^2, or None."""
    on: dict[str, str] = field(default_factory=dict)
    """Joint -> the link its force acts on, where one is named (``on = "coupler"``); a force
    at a joint two links share otherwise acts on the first link listing it (:func:`load_link`).
    The pin forces there depend on it; the input does not."""

    def merged(self, other: Loads) -> Loads:
        """These loads with ``other``'s added or overriding (the command line's: a force it
        gives at a joint keeps the link this one names there)."""
        if not isinstance(other, Loads):
            from ..arguments import describe

            raise InputError(f"other: give a linkage.Loads to merge, got {describe(other)}")
        return Loads(
            {**self.forces, **other.forces},
            {**self.torques, **other.torques},
            {**self.masses, **other.masses},
            other.gravity if other.gravity is not None else self.gravity,
            {**self.on, **other.on},
        )

    @property
    def empty(self) -> bool:
        return not (self.forces or self.torques or self.masses)


def load_link(drawing: Any, joint: str, on: str | None = None) -> str:
    """The link a force at ``joint`` acts on: ``on`` where the load names one, else the first
    moving link (in the order of [links]) that lists the joint (the ground if none does)."""
    if on is not None:
        return on
    return next((b for b, js in drawing.bodies.items() if b != "ground" and joint in js), "ground")


def applied_rows(loads: Loads, drawing: Any) -> list[tuple[str, str, str, float | None, float | None,
                                                           float | None]]:
    """Each force and torque as a report shows it: (name, kind, the link it acts on, Fx and
    Fy in N, T in N m), the force's link by :func:`load_link`."""
    rows: list[tuple[str, str, str, float | None, float | None, float | None]] = [
        (j, "force", load_link(drawing, j, loads.on.get(j)), f[0], f[1], None)
        for j, f in loads.forces.items()]
    rows += [(b, "torque", b, None, None, t) for b, t in loads.torques.items()]
    return rows


# --- the loads of a file ---------------------------------------------------------------------


MAX_LOAD = 1e100
"""The largest magnitude of a load, a torque or a drive (N, N m): beyond it a number means
nothing physical, and its products with lengths and speeds overflow."""


def _finite(key: str, v: Any) -> float:
    """A load's number: a number by the one rule (arguments.finite_real: not a bool, not a
    string, finite), within MAX_LOAD."""
    from ..arguments import describe, finite_real

    x = finite_real(v)
    if x is None or abs(x) > MAX_LOAD:
        raise InputError(f"{key}: must be a finite number (within {MAX_LOAD:g}), got {describe(v)}")
    return x


def _pair(key: str, v: Any) -> tuple[float, float]:
    if not isinstance(v, list) or len(v) != 2:
        raise InputError(f"{key}: must be [x, y], two numbers")
    return _finite(key, v[0]), _finite(key, v[1])


LBF, LB, INCH = 4.4482216152605, 0.45359237, 0.0254
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "mN": 1e-3, "lbf": LBF}
TORQUE_UNITS = {"N m": 1.0, "N mm": 1e-3, "kN m": 1e3, "lbf in": LBF * INCH, "lbf ft": LBF * 12 * INCH}
MASS_UNITS = {"kg": 1.0, "g": 1e-3, "lb": LB}
INERTIA_UNITS = {"kg m^2": 1.0, "kg mm^2": 1e-6, "g cm^2": 1e-7, "lb in^2": LB * INCH * INCH}
"""Units a load may name (``unit``, ``inertia_unit``), each to SI, exactly as
defined (1 lbf = 4.4482216152605 N, 1 lb = 0.45359237 kg)."""


def _unit(key: str, spec: Mapping[str, Any], field_name: str, units: Mapping[str, float]) -> float:
    if field_name not in spec:
        return 1.0
    name = spec[field_name]
    if name not in units:
        raise InputError(f"{key}.{field_name}: {name!r} is not one of {', '.join(units)}")
    return units[name]


def parse_loads(doc: Mapping[str, Any], drawing: Any, source: str,
                named: Mapping[str, str] | None = None) -> Loads:
    """``[loads]`` and ``[mass]`` of a joints-form document, checked against its drawing, in SI:
    a force in N, a torque in N m and a mass in kg unless its ``unit`` says otherwise (a
    mass's also ``mass_unit``, its older name), an inertia in kg m^2 unless ``inertia_unit``
    says; a cg in the file's length unit (the drawing's). ``named``: how a message names an
    entry of ``[loads]`` (the command line's option, ``--torque rocker``) instead of
    ``source: loads.NAME``."""
    forces: dict[str, tuple[float, float]] = {}
    torques: dict[str, float] = {}
    masses: dict[str, Mass] = {}
    acting: dict[str, str] = {}
    links = {b for b in drawing.bodies if b != "ground"}
    loads = doc.get("loads", {})
    if not isinstance(loads, Mapping):
        raise InputError(f"{source}: loads: must be a table of NAME = {{ force = [Fx, Fy] }} or "
                         "{ torque = T }")
    for name, spec in loads.items():
        key = (named or {}).get(name) or f"{source}: loads.{name}"
        part = "" if name in (named or {}) else "."  # an option names its value itself
        if (not isinstance(spec, Mapping) or set(spec) - {"force", "torque", "unit", "note", "on"}
                or len(set(spec) & {"force", "torque"}) != 1):
            raise InputError(f"{key}: give {{ force = [Fx, Fy] }} (N, at a joint or point; on = LINK "
                             "where two links share it) or { torque = T } (N m, on a link), with "
                             "unit = ... for another unit")
        if "force" in spec:
            if name not in drawing.xy:
                raise InputError(f"{key}: a force acts at a joint or point; joints: {', '.join(drawing.xy)}")
            if name in drawing.ground:
                raise InputError(f"{key}: {name} is a fixed joint: a force there goes straight into the "
                                 "ground and loads nothing; put it at a moving joint or point")
            scale = _unit(key, spec, "unit", FORCE_UNITS)
            fx, fy = _pair(f"{key}{part and '.force'}", spec["force"])
            forces[str(name)] = (fx * scale, fy * scale)
            if "on" in spec:
                acting[str(name)] = _acting(f"{key}{part and '.on'}", spec["on"], str(name), drawing)
        elif "on" in spec:
            raise InputError(f"{key}: a torque acts on the link it is named after: drop on = ...")
        else:
            if name not in links:
                raise InputError(f"{key}: a torque acts on a moving link; links: {', '.join(sorted(links))}")
            torque = _finite(f"{key}{part and '.torque'}", spec["torque"])
            torques[str(name)] = torque * _unit(key, spec, "unit", TORQUE_UNITS)
    mass = doc.get("mass", {})
    if not isinstance(mass, Mapping):
        raise InputError(f"{source}: mass: must be a table of LINK = {{ mass, cg, inertia }}")
    for name, spec in mass.items():
        key = f"{source}: mass.{name}"
        if name not in links:
            raise InputError(f"{key}: not a moving link; links: {', '.join(sorted(links))}")
        if (not isinstance(spec, Mapping) or "mass" not in spec
                or set(spec) - {"mass", "cg", "inertia", "unit", "mass_unit", "inertia_unit", "note"}):
            raise InputError(f"{key}: give {{ mass = KG, cg = [x, y], inertia = KG_M2 }} (cg in the "
                             "drawn pose, the file's length unit; inertia about the cg; unit = ... for "
                             "another mass unit, inertia_unit for the inertia's)")
        if "unit" in spec and "mass_unit" in spec:
            raise InputError(f"{key}: give unit (the mass's), not unit and mass_unit (its older name)")
        # unit, as [loads] names a force's or a torque's; mass_unit, its older name, still read
        which = "mass_unit" if "mass_unit" in spec else "unit"
        m = _finite(f"{key}.mass", spec["mass"]) * _unit(key, spec, which, MASS_UNITS)
        inertia = _finite(f"{key}.inertia", spec.get("inertia", 0.0)) * _unit(key, spec, "inertia_unit",
                                                                             INERTIA_UNITS)
        if m < 0.0 or inertia < 0.0:
            raise InputError(f"{key}: mass and inertia must be >= 0")
        if "cg" not in spec:
            raise InputError(f"{key}.cg: give the centre of mass [x, y] in the drawn pose")
        masses[str(name)] = Mass(m, _pair(f"{key}.cg", spec["cg"]), inertia)
    return Loads(forces, torques, masses, None, acting)


def _acting(key: str, on: Any, joint: str, drawing: Any) -> str:
    """``on = LINK`` of a force at ``joint``: a moving link that holds the joint."""
    holders = [b for b, js in drawing.bodies.items() if b != "ground" and joint in js]
    if not isinstance(on, str) or on not in holders:
        from ..arguments import describe

        raise InputError(f"{key}: {describe(on)} does not hold {joint}; a force there acts on one of the "
                         f"links at it: {', '.join(holders)}")
    return on
