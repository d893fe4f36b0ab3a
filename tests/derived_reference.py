"""Independent references for tests/test_derived_closed_forms.py: random mechanisms written
as TOML, and their positions worked out in mpmath (50 digits) from formulas written out
here, never from linkage.problems.derive or dyads.

Every reference reads the mechanism's *parsed* inputs (the doubles the code under test
reads: parameters, driver, numbers and offsets in radians), so a comparison measures the
closed form's own error, not the rounding of degrees to radians.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import mpmath
from mpmath import mpc, mpf

from linkage.errors import InputError
from linkage.kinematics.loading import from_text
from linkage.problems.loops import Mechanism

DPS = 50

# A closed form with only a linear step: s along x, t along y, closing on r e^(i theta)
# (s = r cos(theta), t = r sin(theta)): one assembly, nothing for --branch to choose.
XY = """name = "xy"
length_unit = "mm"
[parameters]
r = { value = 50, unit = "mm" }
[driver]
name = "theta"
value = 30
unit = "deg"
[unknowns]
s = { guess = 10, unit = "mm" }
t = { guess = 10, unit = "mm" }
[[loops]]
name = "L"
vectors = [{ length = "s", angle = 0 }, { length = "t", angle = 90 },
           { length = "r", angle = "theta", sign = -1 }]
"""


def abcd_text(links: tuple[float, float, float, float], driver: str, value: float,
              guesses: dict[str, float], *, unit: str = "mm", name: str = "abcd four-bar",
              key: str = "") -> str:
    """A four-bar with the textbook's names (a crank, b coupler, c rocker, d ground), no
    closed_form key unless ``key`` gives one, driven by ``driver`` (theta2, theta3 or
    theta4); ``guesses`` for the other two angles."""
    a, b, c, d = links
    unknowns = "\n".join(f'{k} = {{ guess = {v!r}, unit = "deg" }}' for k, v in guesses.items())
    return f"""name = "{name}"
length_unit = "{unit}"
{key}
[parameters]
a = {{ value = {a!r}, unit = "{unit}" }}
b = {{ value = {b!r}, unit = "{unit}" }}
c = {{ value = {c!r}, unit = "{unit}" }}
d = {{ value = {d!r}, unit = "{unit}" }}
[driver]
name = "{driver}"
value = {value!r}
unit = "deg"
[unknowns]
{unknowns}
[[loops]]
name = "O2-A-B-O4"
vectors = [
  {{ length = "a", angle = "theta2" }},
  {{ length = "b", angle = "theta3" }},
  {{ length = "c", angle = "theta4", sign = -1 }},
  {{ length = "d", angle = 0, sign = -1 }},
]
"""


# --- random mechanisms as TOML ---------------------------------------------------------------

@dataclass
class Case:
    """A generated mechanism: its TOML pieces and the roles its reference formula reads."""

    family: str  # "fourbar", "slider", "inverted", "watt", "pair"
    params: dict[str, tuple[float, str]]  # name -> (value, unit: "mm", "deg")
    driver: tuple[str, float]  # name, degrees (or mm for a length driver)
    unknowns: list[tuple[str, str]]  # (name, unit)
    loops: list[list[dict[str, Any]]]  # each vector as a TOML inline table's keys
    roles: dict[str, Any] = field(default_factory=dict)
    signed: tuple[str, ...] = ()

    def toml(self) -> str:
        out = ['name = "random mechanism"', 'length_unit = "mm"', "", "[parameters]"]
        for n, (v, u) in self.params.items():
            extra = ", signed = true" if n in self.signed else ""
            out.append(f'{n} = {{ value = {v!r}, unit = "{u}"{extra} }}')
        name, value = self.driver
        unit = "mm" if self.roles.get("length_driver") else "deg"
        out += ["", "[driver]", f'name = "{name}"', f"value = {value!r}", f'unit = "{unit}"',
                "", "[unknowns]"]
        out += [f'{n} = {{ guess = 0, unit = "{u}" }}' for n, u in self.unknowns]
        for vectors in self.loops:
            out += ["", "[[loops]]", "vectors = ["]
            for v in vectors:
                body = ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items())
                out.append(f"  {{ {body} }},")
            out.append("]")
        return "\n".join(out) + "\n"

    def mechanism(self) -> Mechanism:
        return from_text(self.toml(), f"<{self.family}>")

    def with_driver(self, name: str, value: float) -> Case:
        """The same mechanism driven by another of its angles (``name``, now known)."""
        old, _ = self.driver
        unknowns = [(n, u) for n, u in self.unknowns if n != name] + [(old, "deg")]
        roles = dict(self.roles, driven=next(k for k, v in self.roles["angles"].items() if v == name))
        return Case(self.family, dict(self.params), (name, value), unknowns, self.loops, roles, self.signed)


def toml_value(x: Any) -> str:
    return f'"{x}"' if isinstance(x, str) else repr(x)


_CONSONANTS = "bcdfghjklmnpqrvwxz"
_VOWELS = "aeiouy"


def random_names(rng: random.Random, count: int) -> list[str]:
    """``count`` distinct random identifiers, never the textbook's r1..r4 or theta1..4."""
    names: list[str] = []
    while len(names) < count:
        n = rng.choice(_CONSONANTS) + rng.choice(_VOWELS) + rng.choice(_CONSONANTS)
        if rng.random() < 0.5:
            n += str(rng.randrange(10, 99))
        if n not in names:
            names.append(n)
    return names


def _build(rng: random.Random, make: Callable[[list[str]], Case]) -> tuple[Case, Mechanism]:
    """A case whose random names the file format accepts (a name may clash with a scan
    column; then draw again)."""
    for _ in range(20):
        case = make(random_names(rng, 12))
        try:
            return case, case.mechanism()
        except InputError:
            continue
    raise AssertionError("no acceptable names in 20 draws")


def fourbar(rng: random.Random, lengths: tuple[float, float, float, float] | None = None
            ) -> Case:
    """A four-bar loop in_len e^(i t_in) + cp e^(i t_cp) - out e^(i t_out) - g e^(i t_g) = 0
    with random names, written with the ground first or last and possibly negated as a
    whole, driven by its input angle (the driver value is set by the caller)."""
    a, b, c, g = lengths or tuple(round(rng.uniform(5.0, 100.0), 3) for _ in range(4))

    def make(nm: list[str]) -> Case:
        la, lb, lc, lg, ti, tc, to, tg = nm[:8]
        ground_is_name = rng.random() < 0.6
        tg_deg = round(rng.uniform(-60.0, 60.0), 4)
        params = {la: (a, "mm"), lb: (b, "mm"), lc: (c, "mm"), lg: (g, "mm")}
        if ground_is_name:
            params[tg] = (tg_deg, "deg")
        flip = -1 if rng.random() < 0.3 else 1
        vec = [
            {"length": la, "angle": ti, "sign": flip},
            {"length": lb, "angle": tc, "sign": flip},
            {"length": lc, "angle": to, "sign": -flip},
            {"length": lg, "angle": tg if ground_is_name else tg_deg, "sign": -flip},
        ]
        order = [3, 0, 1, 2] if rng.random() < 0.4 else [0, 1, 2, 3]
        loop = [vec[i] for i in order]
        unknowns = [(tc, "deg"), (to, "deg")]
        rng.shuffle(unknowns)
        roles = {"terms": {"in": order.index(0), "cp": order.index(1), "out": order.index(2),
                           "g": order.index(3)},
                 "angles": {"in": ti, "cp": tc, "out": to}, "driven": "in"}
        return Case("fourbar", params, (ti, 0.0), unknowns, [loop], roles)

    return make  # type: ignore[return-value]


def make_fourbar(rng: random.Random, lengths: tuple[float, float, float, float] | None = None
                 ) -> tuple[Case, Mechanism]:
    return _build(rng, fourbar(rng, lengths))  # type: ignore[arg-type]


def make_slider(rng: random.Random) -> tuple[Case, Mechanism]:
    """An offset slider-crank: a e^(i t2) + b e^(i t3) - s e^(i phi) - e e^(i (phi + 90)) = 0
    (the slide along phi, offset e perpendicular to it, e of either sign)."""
    a = round(rng.uniform(5.0, 50.0), 3)
    b = round(rng.uniform(a * 0.6, a * 3.0), 3)
    e = round(rng.uniform(-0.8, 0.8) * b, 3) or 1.0

    def make(nm: list[str]) -> Case:
        la, lb, le, t2, t3, s, phi = nm[:7]
        inline = rng.random() < 0.4  # the slide along the number 0, the offset at 90 deg
        phi_deg = round(rng.uniform(-90.0, 90.0), 4)
        params = {la: (a, "mm"), lb: (b, "mm"), le: (e, "mm")}
        if not inline:
            params[phi] = (phi_deg, "deg")
        loop = [
            {"length": la, "angle": t2},
            {"length": lb, "angle": t3},
            {"length": s, "angle": 0.0 if inline else phi, "sign": -1},
            ({"length": le, "angle": 90.0, "sign": -1} if inline
             else {"length": le, "angle": phi, "offset": 90.0, "sign": -1}),
        ]
        unknowns = [(t3, "deg"), (s, "mm")]
        rng.shuffle(unknowns)
        roles = {"angles": {"in": t2, "cp": t3}, "s": s}
        return Case("slider", params, (t2, 0.0), unknowns, [loop], roles, (le,))

    return _build(rng, make)


def make_inverted(rng: random.Random, offset: bool) -> tuple[Case, Mechanism]:
    """An inverted slider-crank, the block at A sliding along a link turning about O4:
    a e^(i t2) - s e^(i t4) [+- e e^(i (t4 + 90))] - g e^(i tg) = 0."""
    a = round(rng.uniform(5.0, 60.0), 3)
    g = round(rng.uniform(5.0, 60.0), 3)
    e = round(rng.uniform(-0.5, 0.5) * abs(a - g), 3) or 0.5

    def make(nm: list[str]) -> Case:
        la, lg, le, t2, t4, s, tg = nm[:7]
        params = {la: (a, "mm"), lg: (g, "mm"), tg: (round(rng.uniform(-180.0, 180.0), 4), "deg")}
        loop: list[dict[str, Any]] = [{"length": la, "angle": t2},
                                      {"length": s, "angle": t4, "sign": -1}]
        if offset:
            params[le] = (e, "mm")
            loop.append({"length": le, "angle": t4, "offset": 90.0, "sign": rng.choice((1, -1))})
        loop.append({"length": lg, "angle": tg, "sign": -1})
        unknowns = [(s, "mm"), (t4, "deg")]
        rng.shuffle(unknowns)
        return Case("inverted", params, (t2, 0.0), unknowns, [loop], {"s": s, "t4": t4},
                    (le,) if offset else ())

    return _build(rng, make)


def make_watt(rng: random.Random) -> tuple[Case, Mechanism]:
    """A Watt six-bar like sample_inputs/watt_sixbar.toml with random lengths: loop 1 a
    four-bar O2-A-B-O4, loop 2 from O4 along the rocker's extension (offset) to C, then
    D, then the second ground pivot O6."""
    def make(nm: list[str]) -> Case:
        l1, l2, l3, l4, l5, l6, l7, lg, t2, t3, t4, t6 = nm[:12]
        t7, gam = t2 + "w", t3 + "w"
        p = {l1: 100.0, l2: round(rng.uniform(20, 50), 3), l3: round(rng.uniform(90, 140), 3),
             l4: round(rng.uniform(60, 100), 3), l5: round(rng.uniform(40, 90), 3),
             l6: round(rng.uniform(70, 140), 3), l7: round(rng.uniform(50, 110), 3),
             lg: round(rng.uniform(80, 150), 3)}
        params = {k: (v, "mm") for k, v in p.items()}
        params[gam] = (round(rng.uniform(20, 100), 4), "deg")
        loops = [
            [{"length": l2, "angle": t2}, {"length": l3, "angle": t3},
             {"length": l4, "angle": t4, "sign": -1}, {"length": l1, "angle": 0.0, "sign": -1}],
            [{"length": l5, "angle": t4, "offset": round(rng.uniform(-60, 60), 3)},
             {"length": l6, "angle": t6}, {"length": l7, "angle": t7, "sign": -1},
             {"length": lg, "angle": gam, "sign": -1}],
        ]
        unknowns = [(t3, "deg"), (t4, "deg"), (t6, "deg"), (t7, "deg")]
        roles = {"angles": {"in": t2, "cp": t3, "out": t4, "cp2": t6, "out2": t7}, "driven": "in"}
        return Case("watt", params, (t2, 0.0), unknowns, loops, roles)

    return _build(rng, make)


def make_pair(rng: random.Random) -> tuple[Case, Mechanism]:
    """The two-loop example where no loop has two unknowns but their difference does:
    a e^(i td) + s e^(i tx) - b e^(i ty) - g = 0 and a e^(i td) + s e^(i tx) - c e^(i tz)
    - h e^(i 90 deg) = 0."""
    def make(nm: list[str]) -> Case:
        la, lb, lc, lg, lh, td, s, tx, ty, tz = nm[:10]
        p = {la: round(rng.uniform(10, 40), 3), lb: round(rng.uniform(40, 90), 3),
             lc: round(rng.uniform(40, 90), 3), lg: round(rng.uniform(30, 80), 3),
             lh: round(rng.uniform(5, 40), 3)}
        loops = [
            [{"length": la, "angle": td}, {"length": s, "angle": tx},
             {"length": lb, "angle": ty, "sign": -1}, {"length": lg, "angle": 0.0, "sign": -1}],
            [{"length": la, "angle": td}, {"length": s, "angle": tx},
             {"length": lc, "angle": tz, "sign": -1}, {"length": lh, "angle": 90.0, "sign": -1}],
        ]
        unknowns = [(s, "mm"), (tx, "deg"), (ty, "deg"), (tz, "deg")]
        return Case("pair", {k: (v, "mm") for k, v in p.items()}, (td, 0.0), unknowns, loops,
                    {"names": (la, lb, lc, lg, lh, s, tx, ty, tz)})

    return _build(rng, make)


def with_driver_value(case: Case, value_deg: float) -> tuple[Case, Mechanism]:
    c = Case(case.family, case.params, (case.driver[0], value_deg), case.unknowns, case.loops,
             case.roles, case.signed)
    return c, c.mechanism()


# --- mpmath: the loops, Newton, the explicit formulas ----------------------------------------

Sol = dict[str, Any]  # unknown name -> mpf


def cis(x: Any) -> Any:
    """e^(ix) (mpmath.expj would raise inside findroot, which traps complex results)."""
    return mpc(mpmath.cos(x), mpmath.sin(x))


class Inputs:
    """The parsed inputs as mpf, by name, with an optional relative perturbation of one
    input (for the condition number): ``bump = (key, factor)``, key a name or
    ("num", loop, vector) or ("off", loop, vector)."""

    def __init__(self, m: Mechanism, bump: tuple[Any, Any] | None = None,
                 driver: float | None = None) -> None:
        self.m = m
        self.vals: dict[Any, Any] = {n: mpf(q.value) for n, q in m.parameters.items()}
        self.vals[m.driver.name] = mpf(m.driver.value if driver is None else driver)
        for li, loop in enumerate(m.loops):
            for vi, t in enumerate(loop.vectors):
                for part, x in (("len", t.length), ("ang", t.angle)):
                    if not isinstance(x, str):
                        self.vals[(part, li, vi)] = mpf(x)
                self.vals[("off", li, vi)] = mpf(t.offset)
        if bump is not None:
            key, factor = bump
            self.vals[key] = self.vals[key] * factor

    def keys(self) -> list[Any]:
        """Every input that a perturbation moves (nonzero ones: 0 relative is 0)."""
        return [k for k, v in self.vals.items() if v != 0]

    def term(self, li: int, vi: int, sol: Sol) -> tuple[Any, Any]:
        """(length, angle) of vector vi of loop li, offset included, sign included in length."""
        t = self.m.loops[li].vectors[vi]
        length = self._get(t.length, ("len", li, vi), sol)
        angle = self._get(t.angle, ("ang", li, vi), sol) + self.vals[("off", li, vi)]
        return t.sign * length, angle

    def length(self, li: int, vi: int) -> Any:
        """|length| of vector vi of loop li (a known length)."""
        t = self.m.loops[li].vectors[vi]
        return abs(self._get(t.length, ("len", li, vi), {}))

    def _get(self, ref: Any, key: Any, sol: Sol) -> Any:
        if isinstance(ref, str):
            return sol[ref] if ref in sol else self.vals[ref]
        return self.vals[key]

    def vector(self, li: int, vi: int, sol: Sol | None = None) -> Any:
        length, angle = self.term(li, vi, sol or {})
        return length * cis(angle)

    def residual(self, li: int, sol: Sol) -> Any:
        return mpmath.fsum(self.vector(li, vi, sol) for vi in range(len(self.m.loops[li].vectors)))

    def size(self, li: int, sol: Sol) -> Any:
        return mpmath.fsum(abs(self.term(li, vi, sol)[0]) for vi in range(len(self.m.loops[li].vectors)))


def polish(inputs: Inputs, start: Sol) -> Sol:
    """Newton (mpmath.findroot, analytic Jacobian) on the loop equations from ``start``."""
    m = inputs.m
    names = [u.name for u in m.unknowns]

    def f(*x: Any) -> list[Any]:
        sol = dict(zip(names, x))
        out = []
        for li in range(len(m.loops)):
            r = inputs.residual(li, sol)
            out += [r.real, r.imag]
        return out

    def jac(*x: Any) -> Any:
        sol = dict(zip(names, x))
        rows = []
        for li, loop in enumerate(m.loops):
            d = [mpc(0)] * len(names)
            for vi, t in enumerate(loop.vectors):
                length, angle = inputs.term(li, vi, sol)
                for j, n in enumerate(names):
                    if t.angle == n:
                        d[j] += 1j * length * cis(angle)
                    if t.length == n:
                        d[j] += t.sign * cis(angle)
            rows += [[z.real for z in d], [z.imag for z in d]]
        return mpmath.matrix(rows)

    x0 = [mpf(start[n]) for n in names]
    got = mpmath.findroot(f, x0, J=jac, tol=mpf(10) ** (-2 * DPS + 10), verify=False, maxsteps=60)
    root = dict(zip(names, (got[i] for i in range(len(names))))) if len(names) > 1 else {names[0]: got}
    scale = max(inputs.size(li, root) for li in range(len(m.loops)))
    worst = max(abs(inputs.residual(li, root)) for li in range(len(m.loops)))
    assert worst <= scale * mpf(10) ** (-DPS + 5), f"Newton did not converge: {worst}"
    return root


def circles(c1: Any, r1: Any, c2: Any, r2: Any) -> tuple[list[Any], Any]:
    """The points at r1 from c1 and r2 from c2 (left of c1 -> c2 first), and the squared
    half-chord over r1^2 (the law of cosines' discriminant: negative where they miss)."""
    d = abs(c2 - c1)
    if d == 0:
        return [], mpf(-1)
    along = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h2 = r1 * r1 - along * along
    if h2 < 0:
        return [], h2 / (r1 * r1)
    u = (c2 - c1) / d
    h = mpmath.sqrt(h2)
    return [c1 + (along + 1j * h) * u, c1 + (along - 1j * h) * u], h2 / (r1 * r1)


def line_circle(z: Any, r: Any) -> tuple[list[Any], Any]:
    """The real s with |s + z| = r (larger first), and (r^2 - Im z^2) / r^2."""
    disc = r * r - z.imag * z.imag
    if disc < 0:
        return [], disc / (r * r)
    root = mpmath.sqrt(disc)
    return [-z.real + root, -z.real - root], disc / (r * r)


def reference(case: Case, inputs: Inputs) -> tuple[list[Sol], Any]:
    """Every real solution from the explicit formulas, and the smallest discriminant
    (relative; near 0 near a limit)."""
    fam = case.family
    if fam == "fourbar":
        return _fourbar(case, inputs)
    if fam == "slider":
        return _slider(case, inputs)
    if fam == "inverted":
        return _inverted(case, inputs)
    if fam == "watt":
        return _watt(case, inputs)
    return _pair(case, inputs)


def _fourbar(case: Case, inp: Inputs, li: int = 0, terms: dict[str, int] | None = None,
             known: Sol | None = None) -> tuple[list[Sol], Any]:
    """Four-bar in*e^(i t_in) + cp e^(i t_cp) - out e^(i t_out) - G = 0, any one angle
    known: the free joint is where two circles meet."""
    t = terms or case.roles["terms"]
    ang = case.roles["angles"]
    sol: Sol = dict(known or {})
    driven = case.roles["driven"]
    sol[ang[driven]] = inp.vals[inp.m.driver.name] if ang[driven] == inp.m.driver.name else sol[ang[driven]]
    loop = inp.m.loops[li].vectors
    flip = loop[t["in"]].sign  # +1 as written, -1 when the whole loop is negated

    def length(role: str) -> Any:
        return inp.length(li, t[role])

    a, b, c = length("in"), length("cp"), length("out")
    g_vec = -flip * inp.vector(li, t["g"])  # O2 -> O4 (the ground as the loop subtracts it)
    offs = {r: inp.vals[("off", li, t[r])] for r in ("in", "cp", "out")}
    out: list[Sol] = []
    if driven == "in":
        pa = a * cis(sol[ang["in"]] + offs["in"])
        pts, disc = circles(pa, b, g_vec, c)
        for pb in pts:
            out.append({ang["cp"]: mpmath.arg(pb - pa) - offs["cp"],
                        ang["out"]: mpmath.arg(pb - g_vec) - offs["out"]})
    elif driven == "out":
        pb = g_vec + c * cis(sol[ang["out"]] + offs["out"])
        pts, disc = circles(mpc(0), a, pb, b)
        for pa in pts:
            out.append({ang["in"]: mpmath.arg(pa) - offs["in"], ang["cp"]: mpmath.arg(pb - pa) - offs["cp"]})
    else:
        w = g_vec - b * cis(sol[ang["cp"]] + offs["cp"])
        pts, disc = circles(mpc(0), a, w, c)
        for pa in pts:
            out.append({ang["in"]: mpmath.arg(pa) - offs["in"], ang["out"]: mpmath.arg(pa - w) - offs["out"]})
    return [dict(sol, **s) for s in out], disc


def _slider(case: Case, inp: Inputs) -> tuple[list[Sol], Any]:
    """K + b e^(i t3) - s u = 0 with K the known vectors, u the slide's direction:
    |s - K/u| = b, then t3 = arg(s u - K)."""
    ang, s = case.roles["angles"], case.roles["s"]
    d = {ang["in"]: inp.vals[inp.m.driver.name]}
    k = inp.vector(0, 0, d) + inp.vector(0, 3)
    _, phi = inp.term(0, 2, {s: 1})
    u = cis(phi)
    b = inp.length(0, 1)
    roots, disc = line_circle(-k / u, b)
    return [{**d, s: x, ang["cp"]: mpmath.arg(x * u - k)} for x in roots], disc


def _inverted(case: Case, inp: Inputs) -> tuple[list[Sol], Any]:
    """K + e^(i t4) (-s + P) = 0, P the offset term's coefficient: |s - P| = |K|, then
    t4 = arg(K / (s - P))."""
    s, t4 = case.roles["s"], case.roles["t4"]
    vecs = inp.m.loops[0].vectors
    k = inp.vector(0, 0, {}) + inp.vector(0, len(vecs) - 1)
    p = mpc(0)
    if len(vecs) == 4:
        length, angle = inp.term(0, 2, {t4: mpf(0)})
        p = length * cis(angle)
    roots, disc = line_circle(-p, abs(k))
    return [{s: x, t4: mpmath.arg(k / (x - p))} for x in roots], disc


def _watt(case: Case, inp: Inputs) -> tuple[list[Sol], Any]:
    """Loop 1 a crank-driven four-bar; then loop 2 a four-bar driven by theta4 (plus its
    offset) through O4: D where the circles about C and O6 meet."""
    first, disc = _fourbar(case, inp, 0, {"in": 0, "cp": 1, "out": 2, "g": 3})
    ang = case.roles["angles"]
    out: list[Sol] = []
    worst = disc
    for sol in first:
        pc = inp.vector(1, 0, sol)
        o6 = -inp.vector(1, 3)
        r6, r7 = inp.length(1, 1), inp.length(1, 2)
        pts, d2 = circles(pc, r6, o6, r7)
        worst = min(worst, d2)
        for pd in pts:
            out.append(dict(sol, **{ang["cp2"]: mpmath.arg(pd - pc), ang["out2"]: mpmath.arg(pd - o6)}))
    return out, worst


def _pair(case: Case, inp: Inputs) -> tuple[list[Sol], Any]:
    """Loop 1 minus loop 2: -b e^(i ty) + c e^(i tz) - g + i h = 0 (two circles); then
    loop 1: s e^(i tx) = g + b e^(i ty) - a e^(i td) (s = +-its modulus)."""
    la, lb, lc, _, _, s, tx, ty, tz = case.roles["names"]
    v = inp.vals
    td = v[inp.m.driver.name]
    gv, hv = inp.vector(0, 3), inp.vector(1, 3)  # -g, -h i (as the loops add them)
    # X = b e^(i ty): |X| = b and |X - (gv - hv)| = c  (c e^(i tz) = X - gv + hv)
    pts, disc = circles(mpc(0), v[lb], gv - hv, v[lc])
    out: list[Sol] = []
    for x in pts:
        w = x - gv - v[la] * cis(td)  # s e^(i tx)
        for sign in (1, -1):
            out.append({ty: mpmath.arg(x), tz: mpmath.arg(x - gv + hv), s: sign * abs(w),
                        tx: mpmath.arg(sign * w)})
    return out, disc


def wrap(x: Any) -> Any:
    """An angle difference in (-pi, pi]."""
    return mpmath.atan2(mpmath.sin(x), mpmath.cos(x))


def distance(m: Mechanism, a: Sol, b: Sequence[float] | Sol, scale: float) -> Any:
    """The largest difference between two solutions: angles wrapped (rad), lengths
    relative to ``scale``."""
    worst = mpf(0)
    for i, u in enumerate(m.unknowns):
        y = b[u.name] if isinstance(b, dict) else mpf(b[i])
        diff = abs(wrap(a[u.name] - y)) if u.kind == "angle" else abs(a[u.name] - y) / scale
        worst = max(worst, diff)
    return worst


def as_sol(m: Mechanism, q: Sequence[float]) -> Sol:
    return {u.name: mpf(x) for u, x in zip(m.unknowns, q)}



def limits(case: Case, inp: Inputs) -> list[Any]:
    """The driver values (rad) where a discriminant of the case's formula vanishes (limit
    positions), from the law of cosines solved for the driver."""
    out: list[Any] = []

    def both(centre: Any, x: Any) -> None:
        if abs(x) < 1:
            out.extend((centre + mpmath.acos(x), centre - mpmath.acos(x)))

    if case.family == "fourbar":
        t = case.roles["terms"]
        flip = inp.m.loops[0].vectors[t["in"]].sign
        g = -flip * inp.vector(0, t["g"])
        gm, ga = abs(g), mpmath.arg(g)
        a, b, c = inp.length(0, t["in"]), inp.length(0, t["cp"]), inp.length(0, t["out"])
        driven = case.roles["driven"]
        for plus in (True, False):
            if driven == "in":
                r = b + c if plus else abs(b - c)
                both(ga, (a * a + gm * gm - r * r) / (2 * a * gm))
            elif driven == "out":
                r = a + b if plus else abs(a - b)
                both(ga, (r * r - gm * gm - c * c) / (2 * gm * c))
            else:
                r = a + c if plus else abs(a - c)
                both(ga, (gm * gm + b * b - r * r) / (2 * gm * b))
    elif case.family == "slider":
        e = inp.vector(0, 3)
        _, phi = inp.term(0, 2, {case.roles["s"]: 1})
        a, b = inp.length(0, 0), inp.length(0, 1)
        im = (e / cis(phi)).imag
        for side in (1, -1):
            y = (side * b - im) / a
            if abs(y) < 1:
                out.extend((phi + mpmath.asin(y), phi + mpmath.pi - mpmath.asin(y)))
    elif case.family == "inverted" and len(inp.m.loops[0].vectors) == 4:
        gv = inp.vector(0, 3)
        a, gm = inp.length(0, 0), abs(gv)
        p = inp.term(0, 2, {case.roles["t4"]: mpf(0)})
        im = p[0] * mpmath.sin(p[1])
        both(mpmath.arg(gv), (im * im - a * a - gm * gm) / (2 * a * gm))
    return out


def redrive(case: Case, name: str, value: float, family: str) -> Case:
    """The same loops driven by ``name`` (an angle in degrees or a length in mm), the old
    driver now unknown; ``family`` picks the reference formula."""
    old, _ = case.driver
    units = dict(case.unknowns)
    unit = units.pop(name)
    unknowns = [*units.items(), (old, "deg")]
    roles = dict(case.roles, length_driver=unit == "mm")
    return Case(family, dict(case.params), (name, value), unknowns, case.loops, roles, case.signed)


def reference_redriven(case: Case, inp: Inputs) -> tuple[list[Sol], Any]:
    """The solutions of :func:`redrive`'s cases, from formulas written out here."""
    drv = inp.m.driver.name
    dv = inp.vals[drv]
    if case.family == "slider_by_s":
        # a e^(i t2) + b e^(i t3) = B := s u - E: A on the circles about 0 (a) and B (b)
        ang = case.roles["angles"]
        _, phi = inp.term(0, 2, {drv: dv})
        pb = dv * cis(phi) - inp.vector(0, 3)
        pts, disc = circles(mpc(0), inp.length(0, 0), pb, inp.length(0, 1))
        return [{ang["in"]: mpmath.arg(pa), ang["cp"]: mpmath.arg(pb - pa)} for pa in pts], disc
    if case.family == "inverted_by_t4":
        # a e^(i t2) = s u - W, W = the offset term + the ground term: |s - W/u| = a
        s, t2 = case.roles["s"], inp.m.loops[0].vectors[0].angle
        vecs = inp.m.loops[0].vectors
        u = cis(dv)
        w = inp.vector(0, len(vecs) - 1, {}) + (inp.vector(0, 2, {}) if len(vecs) == 4 else 0)
        roots, disc = line_circle(-w / u, inp.length(0, 0))
        return [{s: x, t2: mpmath.arg(x * u - w)} for x in roots], disc
    # a Watt six-bar driven by its last link: loop 2 gives theta4 and theta6, then loop 1
    # is a four-bar driven by its output
    ang = case.roles["angles"]
    off = inp.vals[("off", 1, 0)]
    pd = -inp.vector(1, 3) + inp.length(1, 2) * cis(dv)
    pts, disc = circles(mpc(0), inp.length(1, 0), pd, inp.length(1, 1))
    out: list[Sol] = []
    sub = Case("fourbar", case.params, case.driver, case.unknowns, case.loops,
               {"angles": ang, "driven": "out"})
    for pc in pts:
        known = {ang["out"]: mpmath.arg(pc) - off, ang["cp2"]: mpmath.arg(pd - pc)}
        sols, d1 = _fourbar(sub, inp, 0, {"in": 0, "cp": 1, "out": 2, "g": 3}, known)
        disc = min(disc, d1)
        out += sols
    return out, disc
