"""A loops-form mechanism drawn as joints and links (``linkage convert --form joints``):
its loops solved at the file's driver value, its named points placed there, and the
drawing read from them (:mod:`linkage.problems.to_joints`). The drawing is checked by
deriving its loops again and solving them at the drawn value: one that does not
reproduce the placed joints is refused, never printed."""

from __future__ import annotations

import math
from typing import Any

from ..problems.to_joints import check_joints_named, drawing_doc, drawing_text, refusal, shown_driver

CHECK_TOLERANCE = 1e-9
"""How closely the drawing's own solve must reproduce the placed joints (of the size)."""


def joints_doc(m: Any) -> dict[str, Any]:
    """The joints-form document of the loops-form mechanism ``m``, drawn where its loops
    solve at its driver value (from its guesses) and checked by solving it again."""
    from ..solve import solve_system
    from .rates import rates_at

    check_joints_named(m)
    result = solve_system(m.problem(), tol=1e-12)
    if not result.converged:
        raise refusal(m, f"its loops do not solve at {m.driver.name} = {shown_driver(m)} from its "
                         f"guesses ({result.status.value}): change the guesses or the driver value")
    placed = rates_at(m, list(result.x)).joints
    doc = drawing_doc(m, list(result.x), placed)
    named = [j for loop in m.loops for j in loop.joints if j] + list(m.points)
    _check(doc, {j: placed[j] for j in named}, m)
    return doc


def _check(doc: dict[str, Any], coords: dict[str, tuple[float, float]], m: Any) -> None:
    """The drawing's own loops, solved at the drawn value from the drawing, give back the
    placed joints: otherwise the reading of the loops was wrong and nothing is printed."""
    from ..errors import ParseError
    from ..solve import solve_system
    from .loading import parse_mechanism
    from .rates import rates_at

    try:
        drawn = parse_mechanism(doc, m.source)
    except ParseError as exc:
        raise refusal(m, str(exc).removeprefix(f"{m.source}: ")) from None
    result = solve_system(drawn.problem(), tol=1e-12)
    size = max((math.hypot(x, y) for x, y in coords.values()), default=1.0) or 1.0
    again = rates_at(drawn, result.x).joints if result.converged else {}
    off = [j for j, xy in coords.items()
           if j not in again or math.dist(again[j], xy) > CHECK_TOLERANCE * size]
    if off:
        raise refusal(m, f"the drawing read from its loops does not close at {', '.join(off[:3])}")


def joints_text(m: Any, source: str) -> str:
    """The joints form of ``m`` as a commented TOML file."""
    return drawing_text(m, joints_doc(m), source)
