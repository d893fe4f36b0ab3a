"""Mechanisms as data: vector loops (read from TOML by :mod:`.read_loops`) turned into loop
equations and Jacobians.

A loop is a list of planar vectors that sums to zero. Each vector is
``sign * length * e^(i * angle)``; ``length`` and ``angle`` each name a parameter,
the driver or an unknown, or give a number; an angle may add a fixed ``offset``
(rigid ternary links). Each loop gives two real equations (x and y). Derivatives are
exact: d/d(angle) of r e^(i t) is i r e^(i t), d/d(length) is e^(i t).

File layout (see sample_inputs/ for complete, commented examples)::

    name = "..."
    length_unit = "cm"                      # every length shares it
    closed_form = "fourbar"                 # no longer needed (derived from the loops);
                                            # still read and checked: "fourbar", "slider_crank"
    [parameters]                            # fixed values; angles in deg unless unit = "rad"
    r1 = { value = 90, unit = "cm" }        # a link: must be > 0
    e = { value = 0, unit = "cm", signed = true }   # an offset: any sign
    theta1 = { value = 0, unit = "deg" }
    [driver]                                # the input: a name and a value
    name = "theta2"
    value = 65
    unit = "deg"
    [unknowns]                              # each with its kind and initial guess
    theta3 = { guess = 0, unit = "deg" }
    [[loops]]
    name = "ABCD"
    vectors = [ { length = "r2", angle = "theta2" }, { length = "r4", angle = "theta4", sign = -1 } ]
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import field
from typing import TYPE_CHECKING, Any

from ..errors import InputError, ParseError
from ..records import NamedTuple, frozen
from ..units import RAD_PER_DEG, degrees, radians
from .system import SystemProblem

if TYPE_CHECKING:
    from .derive import Derivation

ANGLE_UNITS = {"deg": RAD_PER_DEG, "rad": 1.0}
"""Radians per unit of each angle unit a file may give."""

LENGTH_RANGE = (1e-100, 1e100)
"""Magnitudes a nonzero length may have: squares and products of two stay normal doubles."""

LENGTH_UNITS = {"mm": 10, "cm": 100, "m": 10_000, "in": 254, "ft": 3048}
"""Lengths a file may give in another of these units than its length_unit, converted on
read: each in tenths of a millimetre, exactly (an inch is 25.4 mm by definition)."""


def length_factor(unit: str, length_unit: str) -> float:
    """The double nearest the exact ratio of two LENGTH_UNITS (in to mm: 25.4): a true
    division of integers is correctly rounded."""
    return LENGTH_UNITS[unit] / LENGTH_UNITS[length_unit]


ANGLE_LIMIT_DEG = 1e6
"""Largest |angle| in degrees: beyond it a degree has too few bits to follow a sweep."""

MAX_LOOPS = 12
"""Most loops in a file, so at most 24 unknowns: a real mechanism has 1 to 5 loops, and the
dense LU of each Newton step costs the cube of the unknowns in pure Python."""
MAX_VECTORS = 24
"""Most vectors in one loop or one point's path."""
MAX_POINTS = 24
"""Most ``[points]``: each is a column of every position of a sweep or a scan."""


def magnitude_problem(value: float, kind: str, unit: str, signed: bool = False) -> str | None:
    """Why a finite value is out of the range this engine can represent faithfully, or None.
    A signed length (an offset) may be as small as it likes: it only adds to others."""
    if kind == "angle":
        deg = degrees(value)
        if abs(deg) > ANGLE_LIMIT_DEG:
            return f"an angle must be within +-{ANGLE_LIMIT_DEG:g} deg, got {deg:g} deg"
        return None
    lo, hi = LENGTH_RANGE
    if signed:
        lo = 0.0
    if value != 0.0 and not lo <= abs(value) <= hi:
        return (f"a length must be 0 or between {lo:g} and {hi:g} {unit} in magnitude, got {value!r} "
                "(change length_unit to rescale)")
    return None


def as_float(value: Any) -> float | None:
    """A TOML or CLI number as a finite float; None for booleans, non-numbers, overflow, NaN."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        v = float(value)
    except OverflowError:
        return None
    return v if math.isfinite(v) else None


# Quantity, VectorTerm and Loop are NamedTuples, not frozen dataclasses: built once per
# class at import, one costs 0.1 ms against 0.7 ms, and every mechanism command's start
# pays for its classes.
class Quantity(NamedTuple):
    name: str
    kind: str  # "angle" or "length"
    value: float  # internal units (rad for angles)
    unit: str  # as written in the file
    signed: bool = False  # an offset: may be zero or negative (links must be > 0)


class VectorTerm(NamedTuple):
    sign: float
    length: str | float  # a name or a number (in the file's length unit)
    angle: str | float  # a name or a number (internal: rad)
    offset: float = 0.0  # rad


class Loop(NamedTuple):
    name: str
    vectors: tuple[VectorTerm, ...]
    joints: tuple[str, ...] = ()  # the start point of each vector ("" unnamed), for drawings


@frozen
class Mechanism:
    """A mechanism read from a file: parameters, driver, unknowns and vector loops."""

    name: str
    source: str
    length_unit: str
    parameters: dict[str, Quantity]
    driver: Quantity
    unknowns: tuple[Quantity, ...]  # value = initial guess
    loops: tuple[Loop, ...]
    closed_form: str | None = None
    description: str = ""
    extra: dict[str, Any] = field(default_factory=dict)
    points: dict[str, tuple[str, tuple[VectorTerm, ...]]] = field(default_factory=dict)
    """Named points on links: name -> (the joint it starts from, its vectors)."""
    origin: tuple[float, float] = (0.0, 0.0)
    """Where the first loop's first joint is (length unit): a drawing's joints are placed
    where they were drawn."""
    driver_range: tuple[float, float] | None = None
    """``[driver] range = [LO, HI]``, in the driver's unit: what a sweep, a scan and an
    animation run over unless told otherwise."""

    def value_of(self, name: str) -> Quantity:
        if name == self.driver.name:
            return self.driver
        return self.parameters[name]

    def with_values(self, overrides: Mapping[str, float], guesses: Mapping[str, float]) -> Mechanism:
        """Override parameters/driver (``--set``) and guesses (``--guess``), in file units:
        each a mapping of name to number (arguments.check_number: not a bool, not a string)."""
        from ..arguments import check_number, describe

        checked = []
        for label, given in (("overrides", overrides), ("guesses", guesses)):
            if not isinstance(given, Mapping):
                raise InputError(f"{label}: give a dict of name -> number, got {describe(given)}")
            checked.append({k: check_number(f"{label}[{k!r}]", v) for k, v in given.items()})
        overrides, guesses = checked
        params = dict(self.parameters)
        driver = self.driver
        for key, v in overrides.items():
            if key == driver.name:
                driver = _requantify(driver, v)
            elif key in params:
                params[key] = _requantify(params[key], v)
                if params[key].kind == "length" and not params[key].signed and params[key].value <= 0.0:
                    raise ParseError(f"--set {key}: a length must be > 0, got {v!r} "
                                     "(declare signed = true for an offset)")
            else:
                known = ", ".join([driver.name, *params])
                raise ParseError(f"--set {key}: no parameter or driver named {key!r} in "
                                 f"{self.source} (known: {known})")
        unknowns = list(self.unknowns)
        for key, v in guesses.items():
            idx = next((i for i, u in enumerate(unknowns) if u.name == key), None)
            if idx is None:
                raise ParseError(f"--guess {key}: no unknown named {key!r} in {self.source} "
                                 f"(unknowns: {', '.join(u.name for u in unknowns)})")
            unknowns[idx] = _requantify(unknowns[idx], v)
        return Mechanism(self.name, self.source, self.length_unit, params, driver, tuple(unknowns),
                         self.loops, self.closed_form, self.description, self.extra, self.points,
                         self.origin, self.driver_range)

    def problem(self) -> SystemProblem:
        return build_problem(self)

    @property
    def closed_form_note(self) -> str | None:
        """What to tell the reader of a file that still says ``closed_form = ...`` (None
        for one that does not): the key is read and checked, but the closed form now comes
        from the loops (:attr:`derivation`). A program prints it; the library does not."""
        if self.closed_form is None:
            return None
        return f"{self.source}: closed_form is no longer needed: the closed form is derived from the loops"

    @property
    def drawing_note(self) -> str | None:
        """Where a drawing was drawn when its [driver] value is elsewhere (None otherwise):
        a program prints it beside its output, as :attr:`closed_form_note`."""
        return self.extra.get("drawing_note")

    @functools.cached_property
    def derivation(self) -> Derivation:
        """The stepwise closed form derived from the loops (:mod:`.derive`), or why there
        is none (``.complete`` is False)."""
        from .find_steps import derive

        return derive(self)

    @functools.cached_property
    def model(self) -> LoopModel:
        """The loop model, compiled once per mechanism (its generated functions with it)."""
        return LoopModel.compile(self)

    def __getstate__(self) -> dict[str, Any]:
        # the compiled model holds generated functions, which do not pickle (scans send
        # mechanisms to worker processes): a worker compiles its own
        state = dict(self.__dict__)
        state.pop("model", None)
        return state

    @functools.cached_property
    def length_scale(self) -> float:
        """The longest length in the loops (parameters, numbers, a length driver): the
        size that residual tolerances are relative to."""
        sizes = [abs(q.value) for q in self.parameters.values() if q.kind == "length"]
        if self.driver.kind == "length":
            sizes.append(abs(self.driver.value))
        sizes += [abs(t.length) for loop in self.loops for t in loop.vectors
                  if isinstance(t.length, float)]
        big = max(sizes, default=0.0)
        return big if big > 0.0 else 1.0


def _requantify(q: Quantity, value: float) -> Quantity:
    if not math.isfinite(value):
        raise ParseError(f"{q.name} must be finite, got {value!r}")
    scale = ANGLE_UNITS[q.unit] if q.kind == "angle" else 1.0
    internal = value * scale
    why = magnitude_problem(internal, q.kind, q.unit, q.signed)
    if why:
        raise ParseError(f"{q.name}: {why}")
    return Quantity(q.name, q.kind, internal, q.unit, q.signed)


# --- equations ----------------------------------------------------------------------------

DRIVER = -2
"""Index marking a term that refers to the driver (``-1``: a fixed value)."""


def drawn_ground(m: Mechanism, values: Mapping[str, Any]) -> dict[str, tuple[float, float]]:
    """A drawing's fixed joints at their drawn (x, y), when ``values`` (the parameters a
    model is compiled with) give every vector that turns with nothing (the ground's: no
    unknown, no driver) its drawn length and angle; else none (a --set or a scan moved a
    ground joint, and the vectors place it)."""
    drawing = m.extra.get("drawing")
    as_drawn = m.extra.get("drawn_parameters")
    if drawing is None or as_drawn is None:
        return {}
    moving = {u.name for u in m.unknowns} | {m.driver.name}
    for loop in m.loops:
        for t in loop.vectors:
            refs = (t.length, t.angle)
            if any(isinstance(r, str) and r in moving for r in refs):
                continue
            for r in refs:
                if isinstance(r, str) and not (type(values[r]) is float and values[r] == as_drawn.get(r)):
                    return {}
    return {j: drawing.xy[j] for j in drawing.ground}


@frozen
class LoopModel:
    """The loops compiled once: each term is (sign, length constant, length index, angle
    constant, angle index, offset); an index >= 0 is an unknown, DRIVER the driver."""

    mechanism: Mechanism
    terms: tuple[tuple[tuple[float, float, int, float, int, float], ...], ...]
    n: int
    point_terms: dict[str, tuple[str, tuple[tuple[float, float, int, float, int, float], ...]]] = field(
        default_factory=dict)
    drawn: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Joints that do not move, each exactly where it was drawn: a drawing's fixed joints,
    while the ground's lengths and angles are the drawn ones (:func:`drawn_ground`). The
    placing rule (kinematics.placing.walk) reports them as drawn, not as the sum of
    vectors that reaches them (a pivot drawn at 45.0 came out 44.99999999999999)."""

    @classmethod
    def compile(cls, m: Mechanism, values: Mapping[str, Any] | None = None) -> LoopModel:
        """``values``: parameters (internal units) to use instead of the file's, numbers or
        numpy arrays (one per position: a scan's designs); a model with arrays is for the
        numpy twins (kinematics.rates.place_motion_np), not for :attr:`factory`."""
        index = {u.name: i for i, u in enumerate(m.unknowns)}
        fixed = {k: q.value for k, q in m.parameters.items()}
        fixed.update(values or {})

        def resolve(ref: str | float) -> tuple[float, int]:
            if isinstance(ref, str):
                if ref in index:
                    return 0.0, index[ref]
                if ref == m.driver.name:
                    return 0.0, DRIVER
                return fixed[ref], -1
            return ref, -1

        loops = []
        for loop in m.loops:
            terms = []
            for t in loop.vectors:
                lc, li = resolve(t.length)
                ac, ai = resolve(t.angle)
                terms.append((t.sign, lc, li, ac, ai, t.offset))
            loops.append(tuple(terms))
        points = {name: (origin, tuple((t.sign, *resolve(t.length), *resolve(t.angle), t.offset)
                                       for t in vecs))
                  for name, (origin, vecs) in m.points.items()}
        return cls(m, tuple(loops), len(m.unknowns), points, drawn_ground(m, fixed))

    @functools.cached_property
    def factory(self) -> Any:
        """The compiled model: ``factory(driver) -> (F, J, V)`` (see :mod:`linkage.codegen`)."""
        from ..codegen import build

        return build(self.terms, self.n)

    @property
    def source(self) -> str:
        """The generated code of the compiled model, for inspection."""
        from ..codegen import source

        return source(self.terms, self.n)

    def functions(self, driver: float) -> tuple[Any, Any]:
        """Phi(q) and J(q) at one driver value (internal units), compiled."""
        F, J, _ = self.factory(driver)
        return F, J

    def driver_derivative(self, driver: float) -> Any:
        """dPhi/d(driver)(q) at one driver value, compiled."""
        return self.factory(driver)[2]

    def interpreted_functions(self, driver: float) -> tuple[Any, Any]:
        """Phi(q) and J(q) by walking the terms: the definition the compiled code is
        tested against."""
        n = self.n
        # Resolve the driver into constants once, so the closures see only fixed terms.
        loops = [[(s, driver if li == DRIVER else lc, -1 if li == DRIVER else li,
                   driver if ai == DRIVER else ac, -1 if ai == DRIVER else ai, off)
                  for s, lc, li, ac, ai, off in terms] for terms in self.terms]
        cos, sin = math.cos, math.sin

        def F(q: Any) -> list[float]:
            out = []
            for terms in loops:
                x = y = 0.0
                for sign, lc, li, ac, ai, off in terms:
                    r = q[li] if li >= 0 else lc
                    th = (q[ai] if ai >= 0 else ac) + off
                    x += sign * r * cos(th)
                    y += sign * r * sin(th)
                out.append(x)
                out.append(y)
            return out

        def J(q: Any) -> list[list[float]]:
            rows = []
            for terms in loops:
                jx = [0.0] * n
                jy = [0.0] * n
                for sign, lc, li, ac, ai, off in terms:
                    r = q[li] if li >= 0 else lc
                    th = (q[ai] if ai >= 0 else ac) + off
                    c, s = cos(th), sin(th)
                    if ai >= 0:
                        jx[ai] -= sign * r * s
                        jy[ai] += sign * r * c
                    if li >= 0:
                        jx[li] += sign * c
                        jy[li] += sign * s
                rows.append(jx)
                rows.append(jy)
            return rows

        return F, J

    def points(self, q: Any, driver: float) -> list[list[complex]]:
        """Cumulative vector sums along each loop, the joints to draw: the first loop from
        the file's origin, a later loop from its first joint where an earlier loop placed it (a
        six-bar's second loop at the rocker pivot), else from the origin too."""
        out = []
        placed: dict[str, complex] = {}
        for loop, terms in zip(self.mechanism.loops, self.terms):
            names = loop.joints
            start = complex(*self.mechanism.origin)
            p = placed.get(names[0], start) if names and names[0] else start
            pts = [p]
            for sign, lc, li, ac, ai, off in terms:
                r = q[li] if li >= 0 else (driver if li == DRIVER else lc)
                th = (q[ai] if ai >= 0 else (driver if ai == DRIVER else ac)) + off
                p += sign * r * complex(math.cos(th), math.sin(th))
                pts.append(p)
            for name, point in zip(names, pts):
                if name:
                    placed.setdefault(name, point)
            out.append(pts)
        return out

    def problem_at(self, driver: float, x0: tuple[float, ...] | None = None) -> SystemProblem:
        m = self.mechanism
        F, J = self.functions(driver)
        eq_names = []
        for loop in m.loops:
            eq_names += [f"{loop.name}.x", f"{loop.name}.y"]
        shown = driver / ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else driver
        # the value as typed: degrees -> radians -> degrees leaves 59.99999999999999 for 60
        shown = float(f"{shown:.12g}")
        reference = branch_of = None
        if m.derivation.complete:
            # any parameter names, any driver, any number of loops: what the loops give
            reference, branch_of = derived_reference(m, driver)
        return SystemProblem(
            F=F, J=J,
            names=tuple(u.name for u in m.unknowns),
            kinds=tuple(u.kind for u in m.unknowns),
            length_unit=m.length_unit,
            equation_names=tuple(eq_names),
            x0=x0 if x0 is not None else tuple(u.value for u in m.unknowns),
            title=f"{m.name}: {m.driver.name} = {shown:g} {m.driver.unit}",
            reference=reference,
            branch_of=branch_of,
            meta={"driver": m.driver.name, "driver_value": shown, "driver_unit": m.driver.unit,
                  "source": m.source, "mechanism": m.name},
            length_scale=m.length_scale,
        )


ONLY = "only"
"""The name of the one assembly of a closed form with no two-way step (every step linear)."""


def derived_reference(m: Mechanism, driver: float) -> tuple[Callable[[], dict[str, dict[str, float]] | None],
                                                            Callable[[dict[str, float]], str]]:
    """The closed form derived from the loops (:attr:`Mechanism.derivation`, complete) at a
    driver value (internal units): ``reference()`` gives every assembly in display units,
    keyed by its branch name ({} where it cannot be assembled, None at a change point);
    ``branch_of(solution in display units)`` names a configuration's branch.

    Angles are shown in (-180, 180], as solve's true error compares them (the difference
    brought within a turn): a crossed slider-crank's theta3 = -171.24 is the same angle
    as 188.76, and no false 360 appears."""
    from .closed_form import wrap_degrees
    from .derive import Indeterminate

    derivation = m.derivation
    names = tuple(u.name for u in m.unknowns)
    angles = tuple(u.kind == "angle" for u in m.unknowns)

    def reference() -> dict[str, dict[str, float]] | None:
        # built when read: sweeps create several problems per position and rarely ask for
        # the closed form. At the driver value the loops are solved at, not the 12-digit
        # one shown: near a limit the answer moves like the square root of the distance
        try:
            named = derivation.named_solutions(driver)
        except (Indeterminate, ArithmeticError):
            return None
        return {key or ONLY: {n: wrap_degrees(degrees(v)) if a else v
                              for n, a, v in zip(names, angles, q)}
                for key, (_, q) in named.items()}

    def branch_of(solution: dict[str, float]) -> str:
        q = [radians(solution[n]) if a else solution[n] for n, a in zip(names, angles)]
        return derivation.name_of(q, driver) or ONLY

    return reference, branch_of


def build_problem(m: Mechanism) -> SystemProblem:
    """Phi(q) and its exact Jacobian at the mechanism's own driver value."""
    return m.model.problem_at(m.driver.value)


def shown_value(q: Quantity) -> float:
    """A quantity in the unit its file gave it (degrees for an angle in deg)."""
    return q.value / ANGLE_UNITS[q.unit] if q.kind == "angle" else q.value
