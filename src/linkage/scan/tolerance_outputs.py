"""A tolerance study's outputs: the unknowns and the named points' coordinates, and how a
design's values are read and kept in the nominal's turn (docs/tolerance.md)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..problems.loops import Mechanism
from ..records import frozen


@frozen
class Output:
    """One output: an unknown (``index`` into the unknowns) or a named point's x or y."""

    name: str
    unit: str
    kind: str  # "angle" (deg), "length", or "point"
    index: int = -1
    point: str = ""
    axis: str = ""


def outputs_of(m: Mechanism) -> tuple[Output, ...]:
    out = [Output(u.name, "deg" if u.kind == "angle" else m.length_unit, u.kind, i)
           for i, u in enumerate(m.unknowns)]
    out += [Output(f"{p}.{a}", m.length_unit, "point", -1, p, a) for p in m.points for a in ("x", "y")]
    return tuple(out)


def design_outputs(m: Mechanism, sol: Any) -> np.ndarray:
    """Every output of solved designs, (designs, positions, outputs) in display units (deg,
    length unit), NaN where not solved."""
    cols = []
    for o in outputs_of(m):
        if o.point:
            z = sol.paths[o.point]
            cols.append(z.real if o.axis == "x" else z.imag)
        else:
            cols.append(sol.solution[:, :, o.index])
    n, k = sol.status.shape
    return np.stack(cols, axis=-1) if cols else np.empty((n, k, 0))


def wrap_near(x: np.ndarray, reference: np.ndarray, outputs: Sequence[Output], copy: bool = True
              ) -> np.ndarray:
    """Angle outputs (deg) brought within half a turn of ``reference`` (the nominal): a
    sample at -179 deg beside a nominal 179 deg is 181 deg (in place unless ``copy``)."""
    x = np.array(x, dtype=float, copy=True) if copy else x
    for j, o in enumerate(outputs):
        if o.kind == "angle":
            x[..., j] = reference[..., j] + (x[..., j] - reference[..., j] + 180.0) % 360.0 - 180.0
    return x


# --- one task of the Monte Carlo (and the linear check's designs) -----------------------------
