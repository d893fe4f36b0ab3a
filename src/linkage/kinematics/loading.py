"""Mechanism files loaded: read (:func:`linkage.problems.read_loops.read_mechanism`) and, for a
drawing whose [driver] value is not where it is drawn, posed there on the drawing's branch.
Posing may take a Newton solve, so it lives here, above :mod:`linkage.solve`, and every
front door (the API's and the commands') loads through this module."""

from __future__ import annotations

import math
from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from ..errors import InputError, ParseError
from ..problems.loops import ANGLE_UNITS, Mechanism, shown_value
from ..problems.read_loops import is_joints_doc, read_mechanism
from ..units import degrees


def load(path: str | Path) -> Mechanism:
    """Read and validate a mechanism file; every error names the file and the key."""
    from ..arguments import check_path
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


def parse_mechanism(doc: Mapping[str, Any], source: str = "<mechanism>") -> Mechanism:
    """The mechanism a parsed file describes (:func:`~linkage.problems.read_loops.read_mechanism`),
    a drawing posed at its [driver] value (:func:`at_driver_value`)."""
    m = read_mechanism(doc, source)
    if is_joints_doc(doc):
        m = at_driver_value(m, doc, source)
    return m


def at_driver_value(m: Mechanism, doc: Mapping[str, Any], source: str) -> Mechanism:
    """A drawing whose [driver] value is not where it is drawn (problems.joints.off_drawing):
    its guesses moved to that value on the drawing's branch - the drawn pose's signs, the
    branch a sweep follows unless told (kinematics.pose.file_branch), solved there by the
    derived closed form (:meth:`~linkage.problems.derive.Derivation.solve`) - so that solve,
    sweep and scan take the drawing's assembly there; the note :attr:`Mechanism.drawing_note`
    says where it was drawn. Loops without a closed form are solved there from the drawn
    pose and must keep its sign of det J. A value the drawing's branch does not reach is
    refused."""
    from ..problems.closed_form import wrap_degrees
    from ..problems.joints import off_drawing

    driver = doc["driver"]
    value = shown_value(m.driver)
    drawn = off_drawing(m.extra["drawing"], driver, value)
    if drawn is None:
        return m
    angle = m.driver.kind == "angle"
    scale = ANGLE_UNITS[m.driver.unit] if angle else 1.0
    what = f"{driver['link']} is drawn at {drawn:.9g} deg" if angle else \
        f"{driver['slider']} is drawn at travel {drawn:.9g} {m.length_unit}"
    unit = " deg" if angle else f" {m.length_unit}"
    to = (drawn + wrap_degrees(value - drawn) if angle else value) * scale  # an angle: the same turn
    q = on_drawn_branch(m, [u.value for u in m.unknowns], drawn * scale, to)
    if q is None:
        raise ParseError(f"{source}: driver.value: {value:g}{unit} is not reached from the drawing ({what}) "
                         "on its branch: the linkage does not assemble there that way; leave value out to "
                         "solve where it is drawn")
    moved = m.with_values({}, {u.name: degrees(v) if u.kind == "angle" else v
                               for u, v in zip(m.unknowns, q)})
    moved.extra["drawing_note"] = (f"{source}: {what}; solved at [driver] value = {value:g}{unit}, on the "
                                   "drawing's branch")
    return moved


def on_drawn_branch(m: Mechanism, q0: list[float], start: float, to: float) -> list[float] | None:
    """The configuration at driver ``to`` on the branch of ``q0`` (the drawn pose, exact
    at ``start``), internal units; None where that branch has no assembly there."""
    from ..linalg import SingularMatrix, det_from_lu, lu
    from ..problems.derive import Indeterminate
    from ..solve import solve_system

    d = m.derivation
    if d.complete:
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
