"""Closed-form position solutions, the independent reference for the iterative solvers.

Four-bar (names r1..r4, theta1..theta4; loop r2 e^(i t2) + r3 e^(i t3) = r1 e^(i t1) +
r4 e^(i t4)): with theta2 or theta4 given, the free joint lies on one circle at a
fixed distance from a known point, so it is a circle-circle intersection with two
solutions, labelled by assembly branch: open where sin(theta4 - theta3) > 0 (as in
PROBLEMS.md P3), crossed where it is < 0. With theta4 driving, the two solutions are the
mirror images of A across the line O2-B, which that sign need not tell apart; there open
is where sin(theta3 - theta2) < 0 (det J < 0, PROBLEMS.md P3's alternative driver: the
same label at P3's open position). No real intersection: the linkage cannot be assembled
at that input.

Slider-crank (names r2, r3, e, theta2, theta3, s; loop r2 e^(i t2) + r3 e^(i t3) =
s + i e): sin(theta3) = (e - r2 sin(theta2)) / r3, s = r2 cos(theta2) + r3 cos(theta3);
open where cos(theta3) > 0 (the slider on the far side of the crank pivot from the
coupler's turn), crossed otherwise.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from typing import Any

REQUIRED_NAMES = {
    "fourbar": ("r1", "r2", "r3", "r4", "theta1", "theta2", "theta3", "theta4"),
    "slider_crank": ("r2", "r3", "e", "theta2", "theta3", "s"),
}

Solutions = dict[str, dict[str, float]]


class Indeterminate(ValueError):
    """Coincident circles: every point of the circle is a solution (a change point)."""


def circle_points(center: complex, radius: float, other: complex, distance: float) -> list[complex]:
    """Points X with |X - center| = radius and |X - other| = distance (0, 1 or 2 of them);
    raises Indeterminate when the two circles coincide."""
    d = abs(other - center)
    if d == 0.0:
        if radius == distance:
            raise Indeterminate("the two circles coincide")
        return []
    if d > radius + distance or d < abs(radius - distance):
        return []
    a = (radius * radius - distance * distance + d * d) / (2.0 * d)
    h2 = radius * radius - a * a
    h = math.sqrt(max(h2, 0.0))
    u = (other - center) / d
    base = center + a * u
    return [base + h * 1j * u, base - h * 1j * u]


def fourbar_positions(r1: float, r2: float, r3: float, r4: float, theta1: float,
                      theta2: float | None = None, theta4: float | None = None) -> Solutions:
    """Both assembly branches, angles in radians; {} when it cannot be assembled.
    Raises Indeterminate at a change point where a joint lies on the opposite pivot."""
    o4 = r1 * cmath.exp(1j * theta1)
    out: Solutions = {}
    if theta2 is not None:
        a = r2 * cmath.exp(1j * theta2)
        for b in circle_points(o4, r4, a, r3):
            t3 = cmath.phase(b - a)
            t4 = cmath.phase(b - o4)
            out[_fourbar_branch(t3, t4)] = {"theta2": theta2, "theta3": t3, "theta4": t4}
    elif theta4 is not None:
        b = o4 + r4 * cmath.exp(1j * theta4)
        for a in circle_points(0j, r2, b, r3):
            t2 = cmath.phase(a)
            t3 = cmath.phase(b - a)
            out[_rocker_driven_branch(t2, t3)] = {"theta2": t2, "theta3": t3, "theta4": theta4}
    else:
        raise ValueError("give theta2 or theta4")
    return out


def _fourbar_branch(t3: float, t4: float) -> str:
    return "open" if math.sin(t4 - t3) > 0.0 else "crossed"


def _rocker_driven_branch(t2: float, t3: float) -> str:
    return "open" if math.sin(t3 - t2) < 0.0 else "crossed"


def slider_crank_positions(r2: float, r3: float, e: float, theta2: float) -> Solutions:
    v = (e - r2 * math.sin(theta2)) / r3
    if abs(v) > 1.0:
        return {}
    out: Solutions = {}
    for branch, t3 in (("open", math.asin(v)), ("crossed", math.pi - math.asin(v))):
        out[branch] = {"theta3": t3, "s": r2 * math.cos(theta2) + r3 * math.cos(t3)}
    return out


def reference_for(m: Any) -> Callable[[], Solutions | None]:
    """A function giving the closed-form solutions for a mechanism's current values,
    in display units (degrees for angles), keyed by branch, restricted to its unknowns;
    None where the closed form is indeterminate."""
    values = {k: q.value for k, q in m.parameters.items()}
    values[m.driver.name] = m.driver.value
    unknown_names = [u.name for u in m.unknowns]
    kinds = {u.name: u.kind for u in m.unknowns}

    def solve() -> Solutions | None:
        if m.closed_form == "fourbar":
            given = {k: values.get(k) for k in ("theta2", "theta4")}
            try:
                sols = fourbar_positions(values["r1"], values["r2"], values["r3"], values["r4"],
                                         values["theta1"], theta2=given["theta2"],
                                         theta4=given["theta4"] if given["theta2"] is None else None)
            except Indeterminate:
                return None
        else:
            sols = slider_crank_positions(values["r2"], values["r3"], values["e"], values["theta2"])
        return {branch: {k: (math.degrees(v) if kinds[k] == "angle" else v)
                         for k, v in sol.items() if k in unknown_names}
                for branch, sol in sols.items()}

    return solve


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


DRIVERS = {"fourbar": ("theta2", "theta4"), "slider_crank": ("theta2",)}
"""The driver each closed form can be given."""


def verify(m: Any) -> str | None:
    """Why the mechanism's loops are not the closed form it names, or None when they are.

    The closed form is a claim about the loops: its solutions must close them. It is
    checked at the file's driver value and, where that cannot be assembled, at every
    30 degrees (a length driver: at its value only), to 1e-9 of the mechanism's size.
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
    from .loops import ANGLE_UNITS

    model = m.model
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    shown0 = m.driver.value / scale
    tries = [shown0] + ([shown0 + 30.0 * k for k in range(1, 12)] if m.driver.kind == "angle" else [])
    limit = 1e-9 * m.length_scale
    for shown in tries:
        try:
            sols = reference_for(m.with_values({m.driver.name: shown}, {}))()
        except (ArithmeticError, ValueError, KeyError) as exc:
            return f"the closed form cannot be evaluated: {exc}"
        if not sols:
            continue
        F = model.functions(shown * scale)[0]
        for branch, sol in sols.items():
            q = [math.radians(sol[u.name]) if u.kind == "angle" else sol[u.name] for u in m.unknowns]
            worst = max(abs(v) for v in F(q))
            if not worst <= limit:
                return (f"its {branch} solution at {m.driver.name} = {shown:g} leaves the loops open by "
                        f"{worst:.3g} {m.length_unit}: the loops are not that mechanism")
        return None
    return None


def branch_rule(m: Any) -> Callable[[dict[str, float]], str]:
    """The branch label of a solution given in display units (degrees)."""
    values = {k: q.value for k, q in m.parameters.items()}

    if m.closed_form == "fourbar" and m.driver.name == "theta4":
        def rocker_driven(sol: dict[str, float]) -> str:
            return _rocker_driven_branch(math.radians(sol["theta2"]), math.radians(sol["theta3"]))
        return rocker_driven

    if m.closed_form == "fourbar":
        def fourbar(sol: dict[str, float]) -> str:
            t3 = math.radians(sol["theta3"]) if "theta3" in sol else values["theta3"]
            t4 = math.radians(sol["theta4"]) if "theta4" in sol else (
                m.driver.value if m.driver.name == "theta4" else values["theta4"])
            return _fourbar_branch(t3, t4)
        return fourbar

    def slider(sol: dict[str, float]) -> str:
        return "open" if math.cos(math.radians(sol["theta3"])) > 0.0 else "crossed"
    return slider


# --- assembly: classification and feasible driver ranges ---------------------------------

def fourbar_class(r1: float, r2: float, r3: float, r4: float) -> dict[str, Any]:
    """Grashof classification with r1 ground, r2 input, r3 coupler, r4 output (Norton 2.8)."""
    links = {"ground": r1, "input": r2, "coupler": r3, "output": r4}
    s_name = min(links, key=links.__getitem__)
    s, longest = min(links.values()), max(links.values())
    others = sorted(links.values())[1:3]
    p_q = sum(others)
    total = s + longest
    if math.isclose(total, p_q, rel_tol=1e-12):
        return {"grashof": True, "type": "change point", "s_plus_l": total, "p_plus_q": p_q}
    if total > p_q:
        return {"grashof": False, "type": "non-Grashof triple rocker", "s_plus_l": total, "p_plus_q": p_q}
    kind = {"ground": "double crank", "input": "crank-rocker", "coupler": "double rocker",
            "output": "rocker-crank"}[s_name]
    return {"grashof": True, "type": f"Grashof {kind}", "shortest": s_name, "s_plus_l": total,
            "p_plus_q": p_q}


Arc = tuple[float, float]


def cos_band_arcs(c_lo: float, c_hi: float, shift: float) -> list[Arc] | None:
    """Angles phi (deg, as phi + shift) with c_lo <= cos(phi) <= c_hi: arcs, [] if none,
    None for the whole circle."""
    if c_lo > c_hi or c_hi < -1.0 or c_lo > 1.0:
        return []
    if c_lo <= -1.0 and c_hi >= 1.0:
        return None
    a_hi = math.degrees(math.acos(min(c_hi, 1.0)))  # smallest |phi|
    a_lo = math.degrees(math.acos(max(c_lo, -1.0)))  # largest |phi|
    if c_hi >= 1.0:
        return [(shift - a_lo, shift + a_lo)]
    if c_lo <= -1.0:
        return [(shift + a_hi, shift + 360.0 - a_hi)]
    return [(shift - a_lo, shift - a_hi), (shift + a_hi, shift + a_lo)]


def feasible_arcs(m: Any) -> list[Arc] | None:
    """Driver values (deg) where the mechanism can be assembled, from its closed form.

    Four-bar driven by theta2: |A - O4|^2 = r1^2 + r2^2 - 2 r1 r2 cos(theta2 - theta1)
    must lie in [(r3 - r4)^2, (r3 + r4)^2]; driven by theta4, the same with r2 and r4
    exchanged and the sign of the cosine flipped. Slider-crank:
    |e - r2 sin(theta2)| <= r3. None: the whole circle.
    """
    v = {k: q.value for k, q in m.parameters.items()}
    drv = m.driver.name
    if m.closed_form == "fourbar":
        r1, r2, r3, r4, t1 = v["r1"], v["r2"], v["r3"], v["r4"], math.degrees(v["theta1"])
        if drv == "theta2":
            lo, hi = (r3 - r4) ** 2, (r3 + r4) ** 2
            # cos(phi) = (r1^2 + r2^2 - d^2) / (2 r1 r2): decreasing in d
            return cos_band_arcs((r1 * r1 + r2 * r2 - hi) / (2 * r1 * r2),
                                 (r1 * r1 + r2 * r2 - lo) / (2 * r1 * r2), t1)
        if drv == "theta4":
            lo, hi = (r2 - r3) ** 2, (r2 + r3) ** 2
            return cos_band_arcs((lo - r1 * r1 - r4 * r4) / (2 * r1 * r4),
                                 (hi - r1 * r1 - r4 * r4) / (2 * r1 * r4), t1)
        return None
    if m.closed_form == "slider_crank" and drv == "theta2":
        r2, r3, e = v["r2"], v["r3"], v["e"]
        # sin(theta2) = cos(theta2 - 90) in [(e - r3)/r2, (e + r3)/r2]
        return cos_band_arcs((e - r3) / r2, (e + r3) / r2, 90.0)
    return None


def arcs_within(arcs: list[Arc] | None, lo: float, hi: float) -> list[Arc]:
    """Intersect circle arcs (deg) with the interval [lo, hi], unwrapping by 360s."""
    if arcs is None:
        return [(lo, hi)]
    out: list[Arc] = []
    for a, b in arcs:
        k = math.floor((lo - b) / 360.0)
        while a + 360.0 * k <= hi:
            s, t = max(a + 360.0 * k, lo), min(b + 360.0 * k, hi)
            if s <= t:
                out.append((s, t))
            k += 1
    return sorted(out)


def arc_limits(arcs: list[Arc] | None, lo: float, hi: float) -> list[float]:
    """Ends of the feasible arcs (limit positions) that fall inside [lo, hi]."""
    if not arcs:
        return []
    out = []
    for a, b in arcs:
        for end in (a, b):
            k = math.ceil((lo - end) / 360.0)
            while end + 360.0 * k <= hi:
                out.append(end + 360.0 * k)
                k += 1
    return sorted(set(out))
