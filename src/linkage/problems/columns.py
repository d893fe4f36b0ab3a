"""The columns of a scan's records, named from a mechanism: the one list of them.

`linkage scan` (:func:`linkage.scan.columns_of`, :func:`linkage.scan.design_metrics`)
names its columns here, and the file parser (:func:`linkage.problems.read_loops.read_mechanism`)
refuses a file whose names would give two columns the same name (a parameter called
``design`` or ``full_cycle``, an unknown ``P_x`` beside a point ``P``): one record would
overwrite or duplicate another, or put millimetres under a (deg) heading. Every parameter
counts, since any may be varied. No numpy here: every file load reads this.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

# ``m`` below is a linkage.problems.loops.Mechanism; not imported, even for typing, since
# loops reads this module (no import cycle)

DESIGN = "design"
SUMMARY = (("feasible_fraction", "number", ""), ("solved_fraction", "number", ""),
           ("full_cycle", "bool", ""))
MEETINGS = ("meetings", "int", "")
"""A mechanism with two-way closed-form steps: how many solved positions are where two
assemblies meet to rounding (a change point, or a limit on the grid): the branch there is
a matter of rounding (linkage.kinematics.designs.meeting_counts)."""


def has_meetings(m: Any) -> bool:
    """Whether ``m``'s scan has the :data:`MEETINGS` column."""
    return bool(m.derivation.complete and m.derivation.two_way)


FOURBAR = (("grashof", "text", ""), ("min_transmission_deg", "number", "deg"),
           ("max_transmission_deg", "number", "deg"))
"""A four-bar loop's columns: its Grashof class and the extremes of its transmission angle
(folded into [0, 90] deg)."""


def fourbar_loops(m: Any) -> list[tuple[Any, str]]:
    """Each four-bar loop of the mechanism's derivation (``m.derivation.fourbars``) with
    the suffix of its columns: none for the first (a four-bar's columns keep their plain
    names), ``_N`` for any other, N its loop's number as ``solve``'s header counts loops
    (a Watt six-bar's second four-bar gives ``min_transmission_deg_2``)."""
    return [(v, "" if i == 0 else f"_{v.loop + 1}") for i, v in enumerate(m.derivation.fourbars)]


def fourbar_columns(suffix: str) -> tuple[tuple[str, str, str], ...]:
    """The columns of one four-bar loop, as FOURBAR names them, with its suffix."""
    return tuple((f"{c}{suffix}", t, u) for c, t, u in FOURBAR)


LOADS = (("peak_input", "number", "N m"), ("max_pin_force", "number", "N"),
         ("max_shaking_force", "number", "N"), ("forces_flagged", "int", ""))
"""A scan's columns with loads (kinematics.forces.force_peaks over each design's cycle): the
largest |input torque| (N for a sliding driver) and pin force among the positions whose
forces are ok, the largest force on the ground, and how many positions' forces are
flagged (near a toggle: not counted)."""


def load_columns(m: Any) -> tuple[tuple[str, str, str], ...]:
    """:data:`LOADS` with the input's unit: N m, or N for a sliding driver."""
    sliding = bool(getattr(m, "extra", {}).get("drawing_driver", {}).get("slider"))
    return tuple((c, t, "N" if c == "peak_input" and sliding else u) for c, t, u in LOADS)


def extent_columns(name: str) -> tuple[str, str, str]:
    """An unknown's columns: its min, max and range."""
    return f"{name}_min", f"{name}_max", f"{name}_range"


def path_columns(point: str, axis: str) -> tuple[str, str]:
    """A point's columns on one axis (x or y): the min and max of its path."""
    return f"{point}_{axis}_min", f"{point}_{axis}_max"


def sourced_columns(m: Any, names: Sequence[str], loads: bool = False
                    ) -> list[tuple[str, str, str, str, str]]:
    """Every record column of a scan varying ``names`` (with ``loads``, :func:`load_columns`
    too), in order, as (name, type, unit, where it comes from, the file key that named it
    or "")."""
    unit = {k: (q.unit if q.kind == "angle" else m.length_unit) for k, q in m.parameters.items()}
    own = "a column every scan writes"
    cols = [(DESIGN, "int", "", own, "")]
    # a varied name that is no parameter is a joint's coordinate (scan.coordinate_column)
    cols += [(n, "number", unit.get(n, m.length_unit), f"parameter {n}", f"parameters.{n}") for n in names]
    cols += [(c, t, u, own, "") for c, t, u in SUMMARY]
    if has_meetings(m):
        cols.append((*MEETINGS, own, ""))
    for q in m.unknowns:
        uu = "deg" if q.kind == "angle" else m.length_unit
        cols += [(c, "number", uu, f"unknown {q.name}", f"unknowns.{q.name}") for c in extent_columns(q.name)]
    for view, suffix in fourbar_loops(m):
        origin = f"a column of four-bar loop {view.loop + 1} ({m.loops[view.loop].name})"
        cols += [(c, t, u, origin, "") for c, t, u in fourbar_columns(suffix)]
    for p in m.points:
        cols += [(c, "number", m.length_unit, f"point {p}", f"points.{p}")
                 for axis in "xy" for c in path_columns(p, axis)]
    if loads:
        cols += [(c, t, u, "a column of a scan with loads", "") for c, t, u in load_columns(m)]
    return cols


def columns_of(m: Any, names: Sequence[str], loads: bool = False) -> list[tuple[str, str, str]]:
    """Every record column: (name, type: number, bool, int or text, unit or "")."""
    return [c[:3] for c in sourced_columns(m, names, loads)]


def column_clash(m: Any) -> tuple[str, str] | None:
    """The first name that would give two scan columns one name, as (the file key to
    blame, the clash in one line), or None."""
    seen: dict[str, tuple[str, str]] = {}
    for name, _type, _unit, origin, key in sourced_columns(m, tuple(m.parameters), loads=True):
        if name not in seen:
            seen[name] = (origin, key)
            continue
        (a, a_key), (b, b_key) = seen[name], (origin, key)
        if not a_key or not b_key:  # one of them is a column the scan always writes
            user, user_key, fixed = (b, b_key, a) if not a_key else (a, a_key, b)
            return user_key, f"{user} gives the scan column {name!r}, which is {fixed}; rename it"
        blame = a_key if a_key.startswith("parameters.") else b_key  # the name that is the column
        return blame, f"{a} and {b} both give the scan column {name!r}; rename one of them"
    return None
