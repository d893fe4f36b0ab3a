"""A joints file's ground joints moved by a scan (``--vary O4.x``): how a design's
coordinates become the derived loops' parameters."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import InputError, ParseError
from ..problems.loops import Mechanism
from ..records import frozen
from ..units import degrees
from .designs import Vary


def coordinate_column(joint: str, axis: str) -> str:
    """The record column of a varied coordinate (``--vary O4.x`` -> ``O4_x``): a name
    --where and --sort read (a dot would be an attribute there)."""
    return f"{joint}_{axis}"


@frozen
class GroundMove:
    """A ground joint a scan moves: where it is drawn, the plan's columns giving its x and
    y (-1: as drawn) and the derived parameters that place it from the ground's first
    joint (its distance and its angle, deg)."""

    joint: str
    drawn: tuple[float, float]
    columns: tuple[int, int]
    length: str
    angle: str


@frozen
class JointMoves:
    """The coordinates of a joints file's ground joints that a scan varies, and how each
    design's coordinates become the derived loops' parameters: the ground is a star from
    its first joint ``root``, so a ground joint at (x, y) is a vector of length
    hypot(x - x0, y - y0) at atan2(y - y0, x - x0) from it. The one home of that rule."""

    root: tuple[float, float]
    moves: tuple[GroundMove, ...]

    @property
    def columns(self) -> frozenset[int]:
        return frozenset(c for g in self.moves for c in g.columns if c >= 0)

    def parameters(self, names: Sequence[str], designs: np.ndarray) -> dict[str, np.ndarray]:
        """The parameter columns (file units) of a chunk of designs (rows of ``names``)."""
        out = {n: designs[:, j] for j, n in enumerate(names) if j not in self.columns}
        rows = designs.shape[0]
        for g in self.moves:
            x, y = (designs[:, c] if c >= 0 else np.full(rows, v) for c, v in zip(g.columns, g.drawn))
            dx, dy = x - self.root[0], y - self.root[1]
            out[g.length] = np.hypot(dx, dy)
            out[g.angle] = degrees(np.arctan2(dy, dx))
        return out


def joint_moves(m: Mechanism, doc: Mapping[str, Any] | None, varies: Sequence[Vary],
                fixed: Sequence[str] = ()) -> tuple[list[Vary], JointMoves | None]:
    """``varies`` with each ``JOINT.x``/``JOINT.y`` (a ground joint's coordinate in the
    joints file ``doc``) renamed to its column, and how they move the joints; None when no
    coordinate is varied. ``fixed``: the names given by --set. InputError, one line, for a
    coordinate that cannot be varied."""
    coords = [(k, v) for k, v in enumerate(varies) if v.name not in m.parameters and "." in v.name]
    if not coords:
        return list(varies), None
    from ..problems.read_loops import is_joints_doc

    first = coords[0][1].name
    if doc is None:  # the Python API given a Mechanism: its drawing is gone
        raise InputError(f"vary {first!r}: a joint's coordinate is read from a joints file: give "
                         "its path, not a Mechanism")
    if not is_joints_doc(doc):
        raise InputError(f"--vary {first}: a joint's coordinate is varied in a joints file; "
                         f"{m.source} is in the loops form: vary its parameters "
                         f"({', '.join(m.parameters)})")
    xy = {str(k): (float(p[0]), float(p[1])) for k, p in doc["joints"].items()}
    ground = [str(g) for g in doc["ground"]]
    root, movable = ground[0], ground[1:]
    can = (f"the fixed joints after {root} can move: " + ", ".join(f"{g}.x, {g}.y" for g in movable)
           if movable else f"{root} is this drawing's only fixed joint")
    where = _ground_vectors(m, root)
    names = [v.name for v in varies]
    moved: dict[str, list[int]] = {}
    out = list(varies)
    for k, v in coords:
        if names.index(v.name) != k:
            raise InputError(f"--vary {v.name} is given twice")
        joint, _, axis = v.name.rpartition(".")
        if joint not in xy:
            raise InputError(f"--vary {v.name}: no joint {joint!r} in {m.source}; {can}")
        if axis not in ("x", "y"):
            raise InputError(f"--vary {v.name}: a joint's coordinates are x and y, not {axis!r}")
        if joint == root:
            raise InputError(f"--vary {v.name}: {root} is where the drawing is placed (the ground's "
                             f"first joint): moving it moves the whole drawing; {can}")
        if joint not in ground:
            links = [str(k) for k, js in doc["links"].items() if joint in js]
            lengths = [p for p in m.parameters if p in links or any(p.startswith(f"{k}_") for k in links)]
            raise InputError(f"--vary {v.name}: {joint} moves with {', '.join(links)}: where it is "
                             f"follows from the link lengths; vary those instead ({', '.join(lengths)})")
        if joint not in where:
            raise InputError(f"--vary {v.name}: {joint} is on no loop of {m.source}: moving it "
                             "changes nothing")
        col = coordinate_column(joint, axis)
        if col in m.parameters:
            raise InputError(f"--vary {v.name}: its column {col} is also a parameter of "
                             f"{m.source}; rename that link")
        for other in where[joint]:
            if other in names or other in fixed:
                raise InputError(f"--vary {v.name}: {other} is {joint}'s place too (derived from "
                                 f"it); vary {joint}.x/{joint}.y or {other}, not both")
        out[k] = Vary(col, v.lo, v.hi, v.n)
        moved.setdefault(joint, [-1, -1])[0 if axis == "x" else 1] = k
    moves = JointMoves(xy[root], tuple(GroundMove(j, xy[j], (c[0], c[1]), *where[j])
                                       for j, c in moved.items()))
    _check_moves(m, moves, out, root)
    return out, moves


def _check_moves(m: Mechanism, moves: JointMoves, varies: Sequence[Vary], root: str) -> None:
    """Every design's ground valid, found at the corners of each joint's box (its farthest
    places); a box holding ``root`` would put a joint on it (a ground vector of no length)."""
    for g in moves.moves:
        ranges = [(varies[c].lo, varies[c].hi) if c >= 0 else (v, v) for c, v in zip(g.columns, g.drawn)]
        named = " and ".join(f"{g.joint}.{a}" for a, c in zip("xy", g.columns) if c >= 0)
        if all(lo <= r <= hi for (lo, hi), r in zip(ranges, moves.root)):
            raise InputError(f"--vary {named}: the range puts {g.joint} on {root}, the ground's first "
                             "joint (no ground length); keep it off")
        corners = np.array([(x, y) for x in ranges[0] for y in ranges[1]])
        one = JointMoves(moves.root, (GroundMove(g.joint, g.drawn, (0, 1), g.length, g.angle),))
        for row in range(len(corners)):
            values = {k: float(v[row]) for k, v in one.parameters(("x", "y"), corners).items()}
            try:
                m.with_values(values, {})
            except ParseError as exc:
                raise InputError(f"--vary {named}: {str(exc).removeprefix('--set ')}") from None


def _ground_vectors(m: Mechanism, root: str) -> dict[str, tuple[str, str]]:
    """Each ground joint's (length, angle) parameters, read from the derived loops: the
    vector between ``root`` and it whose angle is a parameter."""
    out: dict[str, tuple[str, str]] = {}
    for loop in m.loops:
        js = loop.joints
        for i, t in enumerate(loop.vectors):
            if not js or not isinstance(t.length, str) or not isinstance(t.angle, str):
                continue
            a, b = js[i], js[(i + 1) % len(js)]
            if t.angle in m.parameters and root in (a, b):
                out[b if a == root else a] = (t.length, t.angle)
    return out

