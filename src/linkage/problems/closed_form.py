"""The old named closed forms (``closed_form = "fourbar"`` or ``"slider_crank"``), kept for
their check and their remaining readers, and the four-bar facts of any mechanism.

What solve shows (the reference, branch names, --branch) now comes from the closed form
derived from the loops (:mod:`.derive`, :attr:`~.loops.Mechanism.derivation`), whatever
the names and the driver: :func:`fourbar_facts` reads every four-bar loop from it. A file's
``closed_form`` key is still read and checked (:func:`verify`, REQUIRED_NAMES) as a claim
about its loops (DRIVERS: the driver each claim can take). The formulas below serve that
check, the stress checks and the tests; no engine labels or follows a branch by them.

Four-bar (names r1..r4, theta1..theta4; loop r2 e^(i t2) + r3 e^(i t3) = r1 e^(i t1) +
r4 e^(i t4)): with theta2 or theta4 given, the free joint lies on one circle at a
fixed distance from a known point, so it is a circle-circle intersection with two
solutions, each labelled by the configuration rule whatever the driver: open where
sin(theta4 - theta3) > 0 (as in worked example P3, docs/worked_examples.md), crossed otherwise. With
theta4 driving,
the two solutions are the mirror images of A across the line O2-B and may carry the same
label; the second is then keyed "open (mirror)" or "crossed (mirror)". No real
intersection: the linkage cannot be assembled at that input. The formulas and the rules
live in :mod:`linkage.problems.assembly` (scalar and numpy side by side).

Slider-crank (names r2, r3, e, theta2, theta3, s; loop r2 e^(i t2) + r3 e^(i t3) =
s + i e): sin(theta3) = (e - r2 sin(theta2)) / r3, s = r2 cos(theta2) + r3 cos(theta3);
open where cos(theta3) > 0 (the slider on the far side of the crank pivot from the
coupler's turn), crossed otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..units import degrees
from .assembly import (
    MIRROR,
    Indeterminate,
    fourbar_by_crank,
    fourbar_by_rocker,
    is_open,
    label,
    slider_crank,
    triangle,
)

REQUIRED_NAMES = {
    "fourbar": ("r1", "r2", "r3", "r4", "theta1", "theta2", "theta3", "theta4"),
    "slider_crank": ("r2", "r3", "e", "theta2", "theta3", "s"),
}

Solutions = dict[str, dict[str, float]]

def circle_points(center: complex, radius: float, other: complex, distance: float) -> list[complex]:
    """Points X with |X - center| = radius and |X - other| = distance (0, 1 or 2 of them);
    raises Indeterminate when the two circles coincide. The half-chord comes from
    :func:`~.assembly.triangle` (no cancellation near tangency)."""
    d = abs(other - center)
    if d == 0.0:
        if radius == distance:
            raise Indeterminate("the two circles coincide")
        return []
    got = triangle(d, radius, distance)
    if got is None:
        return []
    a, h = got
    u = (other - center) / d
    base = center + a * u
    return [base + h * 1j * u, base - h * 1j * u]


def fourbar_positions(r1: float, r2: float, r3: float, r4: float, theta1: float,
                      theta2: float | None = None, theta4: float | None = None) -> Solutions:
    """Both assembly branches, angles in radians; {} when it cannot be assembled.
    Raises Indeterminate at a change point where a joint lies on the opposite pivot.

    Every solution is labelled by the configuration rule (:func:`~.assembly.is_open`),
    whatever drives it. Driven by theta2 the two solutions always differ in label. Driven
    by theta4 they are the mirror images of A across O2-B and may share one: the one with
    sin(theta3 - theta2) < 0 (A on the right of O2 -> B) takes the plain label, the other
    the label plus :data:`MIRROR`."""
    out: Solutions = {}
    if theta2 is not None:
        crank = fourbar_by_crank(r1, r2, r3, r4, theta1, theta2)
        if crank is None:
            raise Indeterminate("A lies on O4 and r3 = r4")
        for t3, t4 in crank:
            out.setdefault(label(is_open(t3, t4)), {"theta2": theta2, "theta3": t3, "theta4": t4})
        return out
    if theta4 is None:
        raise ValueError("give theta2 or theta4")
    rocker = fourbar_by_rocker(r1, r2, r3, r4, theta1, theta4)
    if rocker is None:
        raise Indeterminate("B lies on O2 and r2 = r3")
    if len(rocker) == 2 and rocker[0] == rocker[1]:
        rocker = rocker[:1]  # tangent circles: one assembly
    for t2, t3 in sorted(rocker, key=lambda s: math.sin(s[1] - s[0]) >= 0.0):
        key = label(is_open(t3, theta4))
        out[key + MIRROR if key in out else key] = {"theta2": t2, "theta3": t3, "theta4": theta4}
    return out


def slider_crank_positions(r2: float, r3: float, e: float, theta2: float) -> Solutions:
    """Both branches (rad): open where cos(theta3) > 0; {} when it cannot be assembled."""
    return {branch: {"theta3": t3, "s": s}
            for branch, (t3, s) in zip(("open", "crossed"), slider_crank(r2, r3, e, theta2))}


def wrap_degrees(a: float) -> float:
    """An angle in degrees brought to (-180, 180]; NaN for a non-finite angle."""
    if not math.isfinite(a):
        return math.nan
    w = math.fmod(a, 360.0)
    if w <= -180.0:
        w += 360.0
    elif w > 180.0:
        w -= 360.0
    return w


TRANSMISSION = "transmission angle 0..90"
"""The transmission angle's name in every table (its unit deg beside it): folded, see
:func:`~.steps.folded_transmission`."""


def transmission(t3_deg: float, t4_deg: float) -> float:
    """The transmission angle between coupler and output link (deg, in [0, 90]):
    |theta4 - theta3| wrapped, then folded (:func:`~.steps.folded_transmission`); NaN for
    a non-finite angle."""
    from .steps import folded_transmission

    return folded_transmission(abs(wrap_degrees(t4_deg - t3_deg)))


def transmission_np(t3_deg: Any, t4_deg: Any) -> Any:
    """:func:`transmission` over arrays: the same operations as wrap_degrees."""
    import numpy as np

    w = np.fmod(np.asarray(t4_deg, float) - t3_deg, 360.0)
    from .steps import folded_transmission_np

    w = np.where(w <= -180.0, w + 360.0, np.where(w > 180.0, w - 360.0, w))
    return folded_transmission_np(np.abs(w))


DRIVERS = {"fourbar": ("theta2", "theta4"), "slider_crank": ("theta2",)}
"""The driver each closed form can be given."""


def claimed_loop(name: str, v: dict[str, float]) -> complex:
    """The loop a closed form stands for, at the values ``v`` (internal units):
    r2 e^(i t2) + r3 e^(i t3) - r4 e^(i t4) - r1 e^(i t1) for a four-bar,
    r2 e^(i t2) + r3 e^(i t3) - s - i e for a slider-crank."""
    def vec(r: float, t: float) -> complex:
        return complex(r * math.cos(t), r * math.sin(t))

    head = vec(v["r2"], v["theta2"]) + vec(v["r3"], v["theta3"])
    if name == "fourbar":
        return head - vec(v["r4"], v["theta4"]) - vec(v["r1"], v["theta1"])
    return head - complex(v["s"], v["e"])


IDENTITY_POINTS = 8
"""Configurations at which a closed_form claim is checked as an identity."""
_IRRATIONALS = (math.sqrt(2.0), math.sqrt(3.0), math.sqrt(5.0))


def verify(m: Any) -> str | None:
    """Why the mechanism's loops are not the closed form it names, or None when they are.

    The closed form is a claim about the loops: its loop (:func:`claimed_loop`, with the
    file's named parameters) must be the file's loop, up to its orientation (the sign of
    the whole loop). That is checked as an identity at scattered configurations of the
    driver and the unknowns (the same points every time: a file loads the same way), to 1e-9
    of the loop's size, not only where the linkage assembles: a claim whose linkage
    cannot be assembled where the file's can is refused.
    """
    name = m.closed_form
    drivers = DRIVERS[name]
    if m.driver.name not in drivers:
        return (f"{name} takes {' or '.join(drivers)} as its driver, and the file drives "
                f"{m.driver.name}")
    unknowns = {u.name for u in m.unknowns}
    expected = set(REQUIRED_NAMES[name]) - set(m.parameters) - {m.driver.name}
    if unknowns != expected:
        return (f"{name} solves for {', '.join(sorted(expected))}; the file's unknowns are "
                f"{', '.join(sorted(unknowns))}")
    if len(m.loops) != 1:
        return f"{name} is one loop; the file has {len(m.loops)}"
    values = {k: q.value for k, q in m.parameters.items()}
    size = max([abs(values[k]) for k in ("r1", "r2", "r3", "r4", "e") if k in values] + [m.length_scale])
    model = m.model
    sign = 0.0
    worst, where = 0.0, ""
    for k in range(1, IDENTITY_POINTS + 1):
        # scattered, reproducible points: k times an irrational per coordinate, mod 1
        u0, u1, u2 = ((k * a) % 1.0 * 2.0 - 1.0 for a in _IRRATIONALS)
        point = dict(values)
        point[m.driver.name] = math.pi * u0
        q = [math.pi * c if u.kind == "angle" else 2.0 * size * c for u, c in zip(m.unknowns, (u1, u2))]
        point.update({u.name: x for u, x in zip(m.unknowns, q)})
        try:
            fx, fy = model.functions(point[m.driver.name])[0](q)
            claim = claimed_loop(name, point)
        except (ArithmeticError, ValueError, KeyError) as exc:
            return f"the closed form cannot be evaluated: {exc}"
        got = complex(fx, fy)
        if sign == 0.0:
            sign = 1.0 if abs(got - claim) <= abs(got + claim) else -1.0
        gap = abs(got - sign * claim)
        if not gap <= worst:  # NaN included
            worst = gap
            where = ", ".join(f"{k} = {degrees(point[k]) if k.startswith('theta') else point[k]:.6g}"
                              for k in (m.driver.name, *(u.name for u in m.unknowns)))
    if not worst <= 1e-9 * size:
        return (f"its loop differs from the file's by {worst:.3g} {m.length_unit} at scattered positions "
                f"(e.g. {where}): the loops are not that mechanism")
    return None


# --- assembly: classification ------------------------------------------------------------
# (the feasible driver ranges and limit positions of every mechanism with a derived closed
# form come from its steps' margins: :mod:`linkage.problems.derive_limits`)

GRASHOF_KINDS = ("double crank", "crank-rocker", "double rocker", "rocker-crank")
"""The Grashof kind by the shortest link: ground, input, coupler, output."""


def grashof(r1: float, r2: float, r3: float, r4: float) -> str:
    """The class of a four-bar (r1 ground, r2 input, r3 coupler, r4 output; Norton 2.8):
    "change point" (s + l = p + q to 1e-12 relative), "triple rocker" (non-Grashof), or
    the Grashof kind named by the shortest link (the first of equals)."""
    links = (r1, r2, r3, r4)
    ordered = sorted(links)
    total, p_q = ordered[0] + ordered[3], ordered[1] + ordered[2]
    if abs(total - p_q) <= 1e-12 * max(abs(total), abs(p_q)):
        return "change point"
    if total > p_q:
        return "triple rocker"
    return GRASHOF_KINDS[links.index(ordered[0])]


def grashof_np(r1: Any, r2: Any, r3: Any, r4: Any) -> Any:
    """:func:`grashof` over arrays (an object array of class names)."""
    import numpy as np

    links = np.stack(np.broadcast_arrays(*(np.asarray(x, float) for x in (r1, r2, r3, r4))), axis=-1)
    ordered = np.sort(links, axis=-1)
    total, p_q = ordered[..., 0] + ordered[..., 3], ordered[..., 1] + ordered[..., 2]
    change = np.abs(total - p_q) <= 1e-12 * np.maximum(np.abs(total), np.abs(p_q))
    kinds = np.array(GRASHOF_KINDS, dtype=object)[np.argmin(links, axis=-1)]
    return np.where(change, "change point", np.where(total > p_q, "triple rocker", kinds)).astype(object)


def fourbar_class(r1: float, r2: float, r3: float, r4: float) -> dict[str, Any]:
    """Grashof classification with r1 ground, r2 input, r3 coupler, r4 output (Norton 2.8),
    as :func:`grashof` decides it, with the sums it compares."""
    links = {"ground": r1, "input": r2, "coupler": r3, "output": r4}
    ordered = sorted(links.values())
    total, p_q = ordered[0] + ordered[3], ordered[1] + ordered[2]
    kind = grashof(r1, r2, r3, r4)
    if kind == "change point":
        return {"grashof": True, "type": "change point", "s_plus_l": total, "p_plus_q": p_q}
    if kind == "triple rocker":
        return {"grashof": False, "type": "non-Grashof triple rocker", "s_plus_l": total, "p_plus_q": p_q}
    s_name = min(links, key=links.__getitem__)
    return {"grashof": True, "type": f"Grashof {kind}", "shortest": s_name, "s_plus_l": total,
            "p_plus_q": p_q}


def fourbar_facts(m: Any, q: Sequence[float] | None = None,
                  driver: float | None = None) -> list[dict[str, Any]]:
    """For every loop of the mechanism that is a four-bar (``m.derivation.fourbars``,
    whatever its parameter names and whichever joint drives): the loop's name, its links'
    lengths, its Grashof class (:func:`fourbar_class`, with the loop's ground, input,
    coupler and output read as written with the ground last) and, given a configuration
    ``q`` (internal units) at ``driver`` (default the file's), its transmission angle in
    degrees (:func:`~.steps.fourbar_transmission`, folded into [0, 90])."""
    from .find_steps import loop_terms
    from .steps import fourbar_transmission

    derivation = m.derivation
    if not derivation.fourbars:
        return []
    params = {k: p.value for k, p in m.parameters.items()}
    d = m.driver.value if driver is None else driver
    loops = loop_terms(m)
    out = []
    for view in derivation.fourbars:
        terms = loops[view.loop]
        # a four-bar's links are fixed: each length a parameter's name or a number
        ground, inp, coupler, output = (abs(params[r] if isinstance(r, str) else r) for r in
                                        (terms[i][1] for i in (view.ground, view.input,
                                                               view.coupler, view.output)))
        fact: dict[str, Any] = {"loop": m.loops[view.loop].name,
                                "links": {"ground": ground, "input": inp, "coupler": coupler,
                                          "output": output},
                                **fourbar_class(ground, inp, coupler, output)}
        if q is not None:
            fact["transmission_deg"] = degrees(fourbar_transmission(view, terms, params, d, q))
        out.append(fact)
    return out


Arc = tuple[float, float]


def cos_band_arcs(c_lo: float, c_hi: float, shift: float) -> list[Arc] | None:
    """Angles phi (deg, as phi + shift) with c_lo <= cos(phi) <= c_hi: arcs, [] if none,
    None for the whole circle."""
    if c_lo > c_hi or c_hi < -1.0 or c_lo > 1.0:
        return []
    if c_lo <= -1.0 and c_hi >= 1.0:
        return None
    a_hi = degrees(math.acos(min(c_hi, 1.0)))  # smallest |phi|
    a_lo = degrees(math.acos(max(c_lo, -1.0)))  # largest |phi|
    if c_hi >= 1.0:
        return [(shift - a_lo, shift + a_lo)]
    if c_lo <= -1.0:
        return [(shift + a_hi, shift + 360.0 - a_hi)]
    return [(shift - a_lo, shift - a_hi), (shift + a_hi, shift + a_lo)]
