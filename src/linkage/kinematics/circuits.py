"""Circuits: which assemblies a mechanism can reach from one another by moving.

Every real assembly at the driver's value lies on a closed curve of configurations, the
solutions (q, driver) of the loop equations Phi(q, driver) = 0: the mechanism's circuit.
Two assemblies are on one circuit when the mechanism can move from one to the other
without taking it apart; it then passes through limit positions, where the driver turns
back (Chase and Mirth 1993, "Circuits and branches of single-degree-of-freedom planar
linkages", J. Mech. Des. 115(2):223-230). A sweep over the driver cannot follow a circuit
past a limit position; this follows the curve itself, by its arc length (pseudo-arclength
continuation: Allgower and Georg, "Introduction to Numerical Continuation Methods",
SIAM 2003, chapter 2):

- the tangent t spans the null space of [J | dPhi/d(driver)], oriented as the last one;
- predict y + h t, correct by Newton's method on Phi = 0 with t . (y - y_pred) = 0;
- a step whose corrector needs more than CORRECTOR_STEPS iterations, or moves more than
  half the step, is halved (so it cannot jump to a neighbouring curve);
- where the tangent's driver part changes sign, the driver turns back: a limit position,
  refined by fitting the driver along the arc;
- where the curve crosses the starting driver value, the configuration is solved at that
  value exactly and matched against the assemblies; meeting the first one again closes the
  circuit;
- a start at a limit position (to rounding) only touches the start value: the trace leaves
  the limit, refined, counts it once and closes on meeting it again; wherever a limit
  touches the start value, the assemblies there join the circuit.

Variables are in units of the mechanism's size (angles in radians), so that a step's
length means the same for a crank angle and a slide.
"""

from __future__ import annotations

import math

import numpy as np

from ..problems.loops import Mechanism
from ..records import frozen
from .assemblies import Assemblies, assemblies, branch_names, same_configuration

MAX_STEP = 0.05
"""Largest arc step (rad, or of the mechanism's size): a picture needs about 1/20 rad."""
MIN_STEP = 1e-9
CORRECTOR_STEPS = 5
MAX_STEPS = 40_000
"""A circuit longer than this many steps is reported as unfinished, with its rows."""
TOLERANCE = 1e-13
"""A corrected point: max|Phi| at most this, relative to the mechanism's size."""
MATCH = 1e-7
"""Configurations closer than this (rad, or of the size) are the same assembly."""


@frozen
class Circuit:
    """One closed curve of configurations, and the assemblies at the start value on it."""

    members: tuple[int, ...]  # indices into Assemblies.real (0-based)
    status: str  # "closed", "unfinished" (MAX_STEPS), "failed" (steps below MIN_STEP), "unbounded",
    # "unlocated" (a crossing of the start value beside a limit position not placed: CrossingNotLocated)
    driver_low: float  # internal units: the smallest and largest driver value on the curve
    driver_high: float
    full_turn: bool  # an angle driver turns a full revolution on this circuit
    limits: tuple[float, ...]  # driver values (internal units) where the driver turns back
    crossings: int  # singular points passed (det of the augmented Jacobian changes sign)
    steps: int
    rejected: int
    drivers: tuple[float, ...]  # the curve, for a picture (internal units, unwrapped)
    configurations: tuple[tuple[float, ...], ...]
    branches: tuple[str, ...]  # the branches it passes at the start value (:func:`_branches`)


@frozen
class Circuits:
    assemblies: Assemblies
    circuits: tuple[Circuit, ...]

    def circuit_of(self, member: int) -> int:
        """The circuit (0-based) that assembly ``member`` (0-based) lies on."""
        for k, c in enumerate(self.circuits):
            if member in c.members:
                return k
        raise KeyError(member)


def _scales(m: Mechanism) -> np.ndarray:
    """The unit of each variable (unknowns, then the driver): 1 for an angle, the size for
    a length."""
    size = m.length_scale
    return np.array([1.0 if u.kind == "angle" else size for u in m.unknowns]
                    + [1.0 if m.driver.kind == "angle" else size])


class _Curve:
    """Phi and its full Jacobian [J | dPhi/dd] in scaled variables y = (q, d) / scales."""

    def __init__(self, m: Mechanism) -> None:
        self.m = m
        self.scale = _scales(m)
        self.size = m.length_scale

    def at(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = y * self.scale
        F, J, V = self.m.model.factory(float(x[-1]))
        q = [float(v) for v in x[:-1]]
        jac = np.empty((len(q), len(q) + 1))
        jac[:, :-1] = np.array(J(q), dtype=float)
        jac[:, -1] = np.array(V(q), dtype=float)
        return np.array(F(q), dtype=float) / self.size, jac * self.scale / self.size


def _tangent(jac: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """The unit null vector of the n x (n+1) Jacobian, pointing along ``previous``."""
    t = np.linalg.svd(jac)[2][-1]
    if previous is not None and float(t @ previous) < 0.0:
        t = -t
    return t


def _correct(curve: _Curve, y: np.ndarray, t: np.ndarray) -> tuple[np.ndarray | None, int]:
    """Newton's method on Phi(y) = 0, t . (y - y_pred) = 0, from the prediction ``y``."""
    y0 = y.copy()
    for k in range(1, CORRECTOR_STEPS + 1):
        f, jac = curve.at(y)
        if not np.all(np.isfinite(f)):
            return None, k
        a = np.vstack([jac, t])
        rhs = np.concatenate([f, [float(t @ (y - y0))]])
        try:
            dy = np.linalg.solve(a, rhs)
        except np.linalg.LinAlgError:
            return None, k
        y = y - dy
        if float(np.max(np.abs(dy))) <= 1e-14 * max(1.0, float(np.max(np.abs(y)))):
            f, _ = curve.at(y)
            return (y, k) if float(np.max(np.abs(f))) <= TOLERANCE * 10 else (None, k)
    f, _ = curve.at(y)
    return (y, CORRECTOR_STEPS) if float(np.max(np.abs(f))) <= TOLERANCE else (None, CORRECTOR_STEPS)


def _solve_at(curve: _Curve, y: np.ndarray, d: float) -> np.ndarray | None:
    """The configuration at driver ``d`` (scaled) near ``y``: Newton on Phi with d fixed."""
    y = y.copy()
    y[-1] = d
    for _ in range(8):
        f, jac = curve.at(y)
        try:
            dq = np.linalg.solve(jac[:, :-1], f)
        except np.linalg.LinAlgError:
            return None
        y[:-1] -= dq
        if float(np.max(np.abs(dq))) <= 1e-15 * max(1.0, float(np.max(np.abs(y)))):
            break
    f, _ = curve.at(y)
    return y if float(np.max(np.abs(f))) <= 1e-12 else None


def _limit(curve: _Curve, a: np.ndarray, ta: np.ndarray, h: float,
           slope_end: float) -> tuple[np.ndarray, float]:
    """The driver (scaled) at the limit position within the arc step of length ``h`` from
    ``a``: where the driver's slope along the arc (the tangent's last part) is zero,
    found by the Illinois method on the arc coordinate s along ``ta``, each trial point
    corrected onto the curve. Near its extremum the driver is quadratic in s, so an error
    e in s is an error of order e^2 in the driver. Returns the point (scaled) and its s."""
    s_lo, g_lo, s_hi, g_hi = 0.0, float(ta[-1]), h, slope_end
    best, s_best = a, 0.0
    side = 0
    for _ in range(40):
        s = s_lo - g_lo * (s_hi - s_lo) / (g_hi - g_lo)
        y, _k = _correct(curve, a + s * ta, ta)
        if y is None:
            break
        best, s_best = y, s
        g = float(_tangent(curve.at(y)[1], ta)[-1])
        if abs(g) <= 1e-14 or s_hi - s_lo <= 1e-15 * max(1.0, h):
            break
        if (g > 0) == (g_lo > 0):
            s_lo, g_lo = s, g
            if side == -1:
                g_hi *= 0.5
            side = -1
        else:
            s_hi, g_hi = s, g
            if side == 1:
                g_lo *= 0.5
            side = 1
    return best, s_best


def _phase(m: Mechanism, d: float, d0: float) -> float:
    """Where ``d`` is relative to the start value: a signed distance, folded into one turn
    for an angle driver (so that a crank meets its start again after 2 pi)."""
    if m.driver.kind == "angle":
        return (d - d0 + math.pi) % (2.0 * math.pi) - math.pi
    return d - d0


def _start_crossings(curve: _Curve, start: Assemblies, a: np.ndarray, ta: np.ndarray, b: np.ndarray,
                     fold: tuple[np.ndarray, float] | None) -> list[tuple[float, np.ndarray]]:
    """Where the arc step from ``a`` (tangent ``ta``) to ``b`` crosses the start value, in
    order along the step: (arc coordinate, the configuration solved at the start value).
    A step through a limit position (``fold``) is two pieces, on each of which the driver
    is monotone: started near a limit, a step can pass the start value on both sides of
    the fold, and each crossing is located on its own piece (bisection on the arc) so it
    is matched to the assembly of its own side, never to the other's."""
    m = start.mechanism
    knots = [(0.0, a), *([] if fold is None else [(fold[1], fold[0])]), (float((b - a) @ ta), b)]
    phase = [_phase(m, float(y[-1] * curve.scale[-1]), float(start.driver)) for _, y in knots]
    out = []
    for j in range(len(knots) - 1):
        p0, p1 = phase[j], phase[j + 1]
        if not ((p0 <= 0.0 < p1 or p1 <= 0.0 < p0) and abs(p1 - p0) < math.pi):
            continue
        s_cross, near = knots[j + 1]
        if fold is not None:
            s_cross, near = _crossing_on_arc(curve, start, a, ta, knots[j][0], knots[j + 1][0], p0)
        p = _phase(m, float(near[-1] * curve.scale[-1]), float(start.driver))
        at = _solve_at(curve, near, float(near[-1]) - p / curve.scale[-1])
        if at is not None:
            out.append((s_cross, at))
    return out


class CrossingNotLocated(ArithmeticError):
    """No point inside a monotone piece of an arc step through a limit position corrected
    onto the curve, so the crossing of the start value on that piece has no point of its own
    side to be solved from. The piece's fold end is no substitute: both sides meet there and
    the Jacobian at a fixed driver is singular, so solved at the start value from it, Newton
    may reach the other side's assembly. Reached only where the corrector fails inside a step
    whose end it corrected (no sample mechanism does: tests/test_circuit_crossing_unlocated.py
    makes it fail); the circuit is then reported "unlocated", never matched by a guess."""


def _crossing_on_arc(curve: _Curve, start: Assemblies, a: np.ndarray, ta: np.ndarray, s_lo: float,
                     s_hi: float, p_lo: float) -> tuple[float, np.ndarray]:
    """The point of the arc from ``a`` along ``ta`` nearest the start value between arc
    coordinates ``s_lo`` (start-relative driver ``p_lo``) and ``s_hi``, the driver monotone
    between them: bisection on s, each trial corrected onto the curve (the first trial is
    the piece's midpoint; :class:`CrossingNotLocated` if it does not correct)."""
    m = start.mechanism
    s_best, best = s_hi, None
    for _ in range(64):
        s = 0.5 * (s_lo + s_hi)
        if s in (s_lo, s_hi):
            break
        y, _k = _correct(curve, a + s * ta, ta)
        if y is None:
            break
        s_best, best = s, y
        p = _phase(m, float(y[-1] * curve.scale[-1]), float(start.driver))
        if (p <= 0.0) == (p_lo <= 0.0):
            s_lo = s
        else:
            s_hi = s
    if best is None:
        raise CrossingNotLocated(f"no point of the arc from s = {s_lo!r} to {s_hi!r} corrects onto the curve")
    return s_best, best


def _fold_start(curve: _Curve, y: np.ndarray,
                t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """A start at a limit position to rounding (a double assembly, where the two assemblies
    meet): the limit position itself, refined as every limit is (:func:`_limit`) between two
    points of the curve on either side of it along ``t``, and the point past it to leave
    from, with its tangent oriented along ``t``. None where no such pair brackets a turn of
    the driver (the curve does not turn back here: a change point, where curves cross)."""
    h = MAX_STEP / 4
    while h >= 1e-6:
        a, _ka = _correct(curve, y - h * t, t)
        b, _kb = _correct(curve, y + h * t, t)
        if a is not None and b is not None:
            ta, tb = _tangent(curve.at(a)[1], t), _tangent(curve.at(b)[1], t)
            if ta[-1] * tb[-1] < 0.0 and float(ta @ t) >= 0.9 and float(tb @ t) >= 0.9:
                fold, _s = _limit(curve, a, ta, float((b - a) @ ta), float(tb[-1]))
                return fold, b, tb
        h *= 0.5
    return None


def _double(start: Assemblies, member: int) -> bool:
    """Whether the assembly is double (two that meet, to rounding: :mod:`.assemblies`): at a
    limit position, or beside one closer than the two assemblies' own uncertainty."""
    return member < len(start.multiplicity) and start.multiplicity[member] >= 2


def _at_limit(curve: _Curve, start: Assemblies, point: np.ndarray) -> list[int]:
    """The assemblies at the start value that are the limit position ``point`` (scaled),
    to MATCH, driver included: where the curve touches the start value without crossing it
    (the start within rounding of a limit, where the two assemblies that meet are one)."""
    m = start.mechanism
    x = point * curve.scale
    if abs(_phase(m, float(x[-1]), float(start.driver))) > MATCH * float(curve.scale[-1]):
        return []
    q = [float(v) for v in x[:-1]]
    return [i for i, a in enumerate(start.real) if same_configuration(q, a.q, m, MATCH)]


def _meet(curve: _Curve, start: Assemblies, first: int, crossed: list[tuple[float, np.ndarray]],
          members: set[int], closing: bool) -> tuple[float, np.ndarray] | None:
    """The assemblies the step's crossings of the start value meet, in order, join
    ``members``, up to the crossing that meets ``first`` again when ``closing``: that one
    (arc coordinate, configuration), or None."""
    m = start.mechanism
    for s_cross, at in crossed:
        q = list(at[:-1] * curve.scale[:-1])
        i = next((i for i, a in enumerate(start.real) if same_configuration(q, a.q, m, MATCH)), None)
        if i is None:
            continue
        members.add(i)
        if i == first and closing:
            return s_cross, at
    return None


def _branches(curve: _Curve, start: Assemblies, members: set[int], first: int,
              sides: tuple[np.ndarray, ...]) -> tuple[str, ...]:
    """The branches a circuit passes at the start value: its assemblies' names. Started at
    a limit position (or a double assembly beside one), where two branches meet and the
    start's own name is a matter of rounding, the two met there instead: each named (as
    sweeps name it, by :func:`.assemblies.branch_names`) at the curve's point next to the
    start on its side, ``sides`` (scaled)."""
    m = start.mechanism
    names = {start.real[i].branch for i in members if i != first or not sides}
    for y in sides:
        x = y * curve.scale
        names.add(branch_names(m, float(x[-1]), [[float(v) for v in x[:-1]]])[0][0])
    return tuple(sorted(n for n in names if n))


def _trace(curve: _Curve, start: Assemblies, first: int) -> Circuit:
    y = np.array([*list(start.real[first].q), start.driver]) / curve.scale
    _f, jac = curve.at(y)
    t = _tangent(jac, None)
    if t[-1] < 0:
        t = -t  # leave with the driver increasing
    ys, ts = [y], [t]
    members, limits = {first}, []
    h, steps, rejected, crossings = MAX_STEP / 4, 0, 0, 0
    # a start at a limit position to rounding is that limit, counted once: the curve leaves it
    # and comes back to it from the other side, touching the start value without crossing it
    at_fold = _fold_start(curve, y, t) if _double(start, first) or start.real[first].singular else None
    if at_fold is not None and first not in _at_limit(curve, start, at_fold[0]):
        at_fold = None  # near a limit, not at it: its start value is crossed, not touched
    if at_fold is not None:
        members.update(_at_limit(curve, start, at_fold[0]))
        ys, ts = [at_fold[0], at_fold[1]], [t, at_fold[2]]
        limits.append(float(at_fold[0][-1] * curve.scale[-1]))
        jac, t = curve.at(at_fold[1])[1], at_fold[2]
    sign = np.sign(np.linalg.det(np.vstack([jac, t])))
    travelled = 0.0
    size_bound = 1e4 * max(1.0, float(np.max(np.abs(y[:-1]))))
    status = "unfinished"
    while steps < MAX_STEPS:
        predicted = ys[-1] + h * ts[-1]
        y_new, k = _correct(curve, predicted, ts[-1])
        if y_new is not None:
            t_new = _tangent(curve.at(y_new)[1], ts[-1])
        if (y_new is None or float(np.linalg.norm(y_new - predicted)) > 0.5 * h
                or float(t_new @ ts[-1]) < 0.9):
            rejected += 1
            h *= 0.5
            if h < MIN_STEP:
                status = "failed"
                break
            continue
        _f, jac = curve.at(y_new)
        steps += 1
        travelled += float(np.linalg.norm(y_new - ys[-1]))
        new_sign = np.sign(np.linalg.det(np.vstack([jac, t_new])))
        if new_sign != sign and new_sign != 0:
            crossings += 1
            sign = new_sign
        ys.append(y_new)
        ts.append(t_new)
        fold = None  # (the limit position's point, its arc coordinate) within this step
        if ts[-2][-1] * t_new[-1] < 0:
            h_step = float((y_new - ys[-2]) @ ts[-2])
            fold = _limit(curve, ys[-2], ts[-2], h_step, float(t_new[-1]))
        if float(np.max(np.abs(y_new[:-1]))) > size_bound:
            limits.extend(float(f[0][-1] * curve.scale[-1]) for f in (fold,) if f is not None)
            status = "unbounded"
            break
        try:
            crossed = _start_crossings(curve, start, ys[-2], ts[-2], y_new, fold)
        except CrossingNotLocated:
            limits.extend(float(f[0][-1] * curve.scale[-1]) for f in (fold,) if f is not None)
            status = "unlocated"
            break
        closing = travelled > 4.0 * MAX_STEP
        met = _meet(curve, start, first, crossed, members, closing)
        touched = _at_limit(curve, start, fold[0]) if fold is not None else []
        members.update(touched)
        back = at_fold is not None and first in touched
        if met is not None:
            status = "closed"
            ys[-1] = met[1]  # end on the start configuration, not past it
            if fold is not None and (met[0] < fold[1] or back):
                fold = None  # closed before this step's limit: the first step's, met again
        elif closing and back:
            status = "closed"  # back at the limit position started from, from its other side
            ys[-1], fold = at_fold[0], None
        if fold is not None:
            limits.append(float(fold[0][-1] * curve.scale[-1]))
        if status == "closed":
            break
        h = min(MAX_STEP, h * (1.5 if k <= 2 else 1.0))
    # a limit position started from, or a double start beside one: one curve point either side
    sides = (ys[1], ys[-2]) if (at_fold is not None or _double(start, first)) and status == "closed" else ()
    return _circuit(curve, start.mechanism, members, status, limits, (crossings, steps, rejected), ys,
                    _branches(curve, start, members, first, sides))


def _circuit(curve: _Curve, m: Mechanism, members: set[int], status: str, limits: list[float],
             counts: tuple[int, int, int], ys: list[np.ndarray], branches: tuple[str, ...]) -> Circuit:
    """The traced curve ``ys`` (scaled) as a Circuit; ``counts``: crossings, steps, rejected."""
    drivers = [float(v[-1] * curve.scale[-1]) for v in ys]
    configurations = [tuple(float(x) for x in v[:-1] * curve.scale[:-1]) for v in ys]
    full = m.driver.kind == "angle" and max(drivers) - min(drivers) >= 2.0 * math.pi - 1e-9
    low, high = min(drivers + limits), max(drivers + limits)  # a limit is refined, a sample is not
    return Circuit(tuple(sorted(members)), status, low, high, full, tuple(limits), *counts,
                   tuple(drivers), tuple(configurations), branches)

def circuits(m: Mechanism, driver: float | None = None, seed: int = 0,
             found: Assemblies | None = None) -> Circuits:
    """Every real assembly at ``driver`` (internal units; the file's by default) and the
    circuit each lies on (module docstring)."""
    start = found if found is not None else assemblies(m, driver, seed=seed)
    curve = _Curve(start.mechanism)
    out: list[Circuit] = []
    for i in range(len(start.real)):
        if any(i in c.members for c in out):
            continue
        out.append(_trace(curve, start, i))
    return Circuits(start, tuple(out))


