"""Tolerance analysis: how manufacturing tolerances on a mechanism's lengths (and a
drawing's fixed joints) spread its outputs over the cycle (docs/tolerance.md).

Two answers, side by side, at every driver value:

- **Linear**: the sensitivity of every unknown and named point to each toleranced
  parameter, dq/dp = -J^-1 dPhi/dp. That is the velocity equation of
  :mod:`linkage.kinematics.rates` with the parameter as the driver (its numpy twin,
  :func:`~linkage.kinematics.rates.solve_rates_np`, with the parameter moving at unit
  rate), so no second rule exists for it. From the contributions c_i = (dq/dp_i) D_i:
  the worst case sum |c_i| and the RSS sqrt(sum c_i^2). A tolerance ±D is read as the
  3-sigma limit of a normal spread (99.73% of parts inside): the RSS is then the output's
  3-sigma band, and ``linear_sigma`` the output's standard deviation under the
  distribution the Monte Carlo draws (RSS / 3 for normal, RSS / sqrt(3) for uniform
  within ±D).
- **Monte Carlo**: ``samples`` designs, each parameter drawn from its distribution, run
  as a scan (:func:`linkage.scan.engine.run_chunks`: on dask like any scan), every design
  following the nominal assembly. Per driver value: the 0.135, 50 and 99.865 percentiles
  (the normal model's -3 sigma, median and +3 sigma) and standard deviation of each
  output over the samples that assemble there, and the share that do not.

A linear band is only as good as the mechanism is linear over ±D. Each position's band
is checked against the exact solutions at +D and -D of every tolerance: where one of them
does not assemble, or the linear prediction misses it by more than ``NONLINEAR_LIMIT``
of the worst-case band, the position's status is ``near_limit`` (a limit or toggle
position within the tolerances' reach), never a bare number; ``undefined`` where J is
singular.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import InputError, ParseError
from ..kinematics.designs import CONVERGED, solve_designs
from ..problems.loops import ANGLE_UNITS, LoopModel, Mechanism
from ..records import frozen
from ..units import degrees, radians
from .designs import MAX_SCAN_POSITIONS, Vary
from .moves import JointMoves, joint_moves
from .task import ScanJob, job_mechanism
from .tolerance_outputs import Output, design_outputs, outputs_of, wrap_near

DISTRIBUTIONS = ("normal", "uniform")
"""How ±D is drawn: normal with sigma D/3 (default), or uniform within ±D."""
PERCENTILES = (0.135, 50.0, 99.865)
"""The Monte Carlo's percentiles: a normal output's -3 sigma, median and +3 sigma."""
NONLINEAR_LIMIT = 0.1
"""A position's linear band is ``near_limit`` where the exact solution at a tolerance's
+D or -D differs from the linear prediction by more than this share of the worst-case band."""
MAX_TOLERANCES = 100
MAX_SAMPLES = 10_000_000
MAX_HELD = 20_000_000
"""Samples x positions x (outputs + 1) the Monte Carlo holds at once (160 MB; the
percentiles sort a copy)."""
DEFAULT_SAMPLES = 1000


@frozen
class Tolerance:
    """One ``--tol NAME=±D``: a parameter (or ``JOINT.x``/``JOINT.y``) and its D > 0,
    in the file's units."""

    name: str
    plus_minus: float


def parse_tolerance(text: str) -> Tolerance:
    """``NAME=±D``, ``NAME=+-D`` or ``NAME=D`` (D > 0, finite)."""
    from ..numbers import parse_number

    name, eq, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    if not eq or not name or not spec:
        raise InputError(f"--tol {text!r}: write NAME=±D (or NAME=D), D in the file's units")
    for sign in ("±", "+/-", "+-"):
        if spec.startswith(sign):
            spec = spec[len(sign):].strip()
            break
    d = parse_number(f"--tol {name}", spec)
    return check_tolerance(name, d, OPTION)


OPTION = "--tol {}"
"""How the command line names a tolerance in a message; the API names it ``API``."""
API = "tolerances[{!r}]"


def check_tolerance(name: str, d: Any, label: str = API) -> Tolerance:
    from ..arguments import check_number

    d = check_number(label.format(name), d)
    if not d > 0.0:
        raise InputError(f"{label.format(name)}: a tolerance ±D needs D > 0, got {d:g}")
    return Tolerance(name, d)


# --- what each tolerance moves ------------------------------------------------------------------

@frozen
class Direction:
    """What one tolerance moves: ``column`` (the scan's column: the name, or ``O4_x`` for a
    joint's coordinate), its nominal value (file units), and d(parameter)/d(tolerance) of
    each parameter it moves (internal units: rad for an angle)."""

    tolerance: Tolerance
    column: str
    nominal: float
    rates: tuple[tuple[str, float], ...]


@frozen
class Plan:
    """The checked tolerances: their directions, and how a joints file's coordinates
    become parameters (None: no coordinate is toleranced)."""

    directions: tuple[Direction, ...]
    moves: JointMoves | None

    @property
    def columns(self) -> tuple[str, ...]:
        return tuple(d.column for d in self.directions)

    @property
    def nominal(self) -> np.ndarray:
        return np.array([d.nominal for d in self.directions])

    def parameters(self, designs: np.ndarray) -> dict[str, np.ndarray]:
        """The parameter columns (file units) of designs given as rows of :attr:`columns`."""
        if self.moves is not None:
            return self.moves.parameters(self.columns, designs)
        return {c: designs[:, j] for j, c in enumerate(self.columns)}


def plan_tolerances(m: Mechanism, tolerances: Sequence[Tolerance], doc: Mapping[str, Any] | None,
                    fixed: Sequence[str] = (), label: str = OPTION) -> Plan:
    """Each tolerance checked (one InputError naming it by ``label``): a length parameter of
    ``m``, or a fixed joint's coordinate of a joints file (``doc``) as ``--vary`` takes it;
    given once; D smaller than the length it is on."""
    if not tolerances:
        raise InputError("give at least one tolerance, --tol NAME=±D")
    if len(tolerances) > MAX_TOLERANCES:
        raise InputError(f"{len(tolerances)} tolerances; at most {MAX_TOLERANCES}")
    seen: set[str] = set()
    for t in tolerances:
        if t.name in seen:
            raise InputError(f"{label.format(t.name)} is given twice")
        seen.add(t.name)
    lengths = [p for p, q in m.parameters.items() if q.kind == "length"]
    for t in tolerances:
        if t.name in m.parameters:
            q = m.parameters[t.name]
            if q.kind != "length":
                raise InputError(f"{label.format(t.name)}: not a length (an {q.kind}); a tolerance is on a "
                                 f"length or a fixed joint's coordinate; the lengths of {m.source} are "
                                 f"{', '.join(lengths)}")
            if not q.signed and not t.plus_minus < q.value:
                raise InputError(f"{label.format(t.name)} = ±{t.plus_minus:g}: as large as {t.name} itself "
                                 f"({q.value:g} {m.length_unit}); a tolerance is smaller than its length")
        elif "." not in t.name:
            what = ("the driver (its value is set, not made)" if t.name == m.driver.name else
                    "an unknown (it follows from the lengths)" if t.name in {u.name for u in m.unknowns}
                    else "not a parameter")
            joint = (", and in a joints file a fixed joint's coordinate such as O4.x"
                     if m.extra.get("drawing") is not None else "")
            raise InputError(f"{label.format(t.name)}: {what}; the lengths of {m.source} are "
                             f"{', '.join(lengths)}{joint}")
    varies = [Vary(t.name, _value_of(m, doc, t.name) - t.plus_minus,
                   _value_of(m, doc, t.name) + t.plus_minus, None) for t in tolerances]
    try:
        renamed, moves = joint_moves(m, doc, varies, fixed)
    except InputError as exc:  # the scan's checks of a joint's coordinate, in this option's name
        text = str(exc)
        for t in tolerances:
            text = text.replace(f"--vary {t.name}", label.format(t.name)).replace(f"vary {t.name!r}",
                                                                                  label.format(t.name))
        raise InputError(text) from None
    directions = []
    for t, v in zip(tolerances, renamed):
        nominal = _value_of(m, doc, t.name)
        if moves is None or v.name in m.parameters:
            directions.append(Direction(t, v.name, nominal, ((t.name, 1.0),)))
            continue
        joint, _, axis = t.name.rpartition(".")
        g = next(g for g in moves.moves if g.joint == joint)
        dx, dy = g.drawn[0] - moves.root[0], g.drawn[1] - moves.root[1]
        r2 = dx * dx + dy * dy
        r = math.sqrt(r2)
        # the ground vector's length hypot(dx, dy) and angle atan2(dy, dx), differentiated
        rates = ((g.length, dx / r), (g.angle, -dy / r2)) if axis == "x" else \
            ((g.length, dy / r), (g.angle, dx / r2))
        directions.append(Direction(t, v.name, nominal, rates))
    return Plan(tuple(directions), moves)


def _value_of(m: Mechanism, doc: Mapping[str, Any] | None, name: str) -> float:
    """A toleranced name's nominal value in file units: a parameter's, or a drawn joint's
    coordinate (the joint's existence is checked by joint_moves)."""
    if name in m.parameters:
        q = m.parameters[name]
        return q.value / ANGLE_UNITS[q.unit] if q.kind == "angle" else q.value
    joint, _, axis = name.rpartition(".")
    if doc is not None and isinstance(doc.get("joints"), Mapping) and joint in doc["joints"] \
            and axis in ("x", "y"):
        return float(doc["joints"][joint][0 if axis == "x" else 1])
    return 0.0  # joint_moves names what is wrong with it


# --- outputs -----------------------------------------------------------------------------------

def tolerance_chunk(job: ScanJob, start: int, designs: np.ndarray) -> dict[str, np.ndarray]:
    """One scan task: designs ``start, start + 1, ...`` (rows of the toleranced columns)
    over every driver value: ``assembled`` (designs, positions) and ``outputs`` (designs,
    positions, outputs). A design with a length at or below zero (a normal draw's far tail)
    assembles nowhere. Module-level, so it pickles to dask's workers."""
    m = job.mechanism or job_mechanism(job.text, job.source, job.overrides)
    params = (job.moves.parameters(job.names, designs) if job.moves is not None else
              {name: designs[:, j] for j, name in enumerate(job.names)})
    sol = solve_designs(m, params, np.array(job.values), branch=job.branch, tol=job.tol,
                        paths=bool(m.points))
    assembled = sol.status == CONVERGED
    for name, col in params.items():
        q = m.parameters[name]
        if q.kind == "length" and not q.signed:
            assembled[np.asarray(col) <= 0.0] = False
    outputs = design_outputs(m, sol)
    outputs[~assembled] = np.nan
    return {"design": np.arange(start, start + len(designs)), "assembled": assembled, "outputs": outputs}


@frozen
class Samples:
    """The Monte Carlo's designs, drawn once (design i the same whatever the chunking or
    the scheduler): what :func:`linkage.scan.engine.run_chunks` reads as its plan."""

    designs: np.ndarray

    @property
    def total(self) -> int:
        return len(self.designs)

    def chunk(self, start: int, stop: int) -> np.ndarray:
        return self.designs[start:stop]


def draw(plan: Plan, samples: int, seed: int, distribution: str) -> Samples:
    """``samples`` designs: each toleranced column its nominal plus a draw within ±D
    (uniform) or of sigma D/3 (normal), independently."""
    rng = np.random.default_rng(seed)
    d = np.array([x.tolerance.plus_minus for x in plan.directions])
    if distribution == "uniform":
        u = rng.uniform(-1.0, 1.0, (samples, len(d)))
    else:
        u = rng.standard_normal((samples, len(d))) / 3.0
    return Samples(plan.nominal + u * d)


# --- the study ---------------------------------------------------------------------------------

@frozen
class ToleranceStudy:
    """A tolerance study over the driver values ``values`` (display units). Arrays are
    indexed [output, position] (``sensitivity`` [output, tolerance, position]), in
    display units (deg; the length unit), per unit of each tolerance's parameter;
    NaN where there is no value. ``status`` per position: ok, near_limit, undefined
    (J singular) or not_assembled (the nominal design)."""

    mechanism: str
    source: str
    driver: str
    driver_unit: str
    length_unit: str
    values: tuple[float, ...]
    tolerances: tuple[Tolerance, ...]
    outputs: tuple[Output, ...]
    nominal: np.ndarray
    sensitivity: np.ndarray
    status: tuple[str, ...]
    nonlinearity: np.ndarray
    """Per position: the largest miss of the linear prediction at ±D over the worst-case band."""
    distribution: str
    branch: str | None
    samples: int | None = None
    seed: int = 0
    mc_low: np.ndarray | None = None
    mc_median: np.ndarray | None = None
    mc_high: np.ndarray | None = None
    mc_sigma: np.ndarray | None = None
    not_assembled: np.ndarray | None = None
    """Per position: the share of samples that do not assemble there."""
    not_assembled_anywhere: float | None = None
    """The share of samples that fail to assemble at one position or more."""

    @property
    def contributions(self) -> np.ndarray:
        """(output, tolerance, position): each tolerance's share, (dq/dp_i) D_i."""
        d = np.array([t.plus_minus for t in self.tolerances])
        return self.sensitivity * d[None, :, None]

    @property
    def worst_case(self) -> np.ndarray:
        return np.abs(self.contributions).sum(axis=1)

    @property
    def rss(self) -> np.ndarray:
        return np.sqrt((self.contributions ** 2).sum(axis=1))

    @property
    def linear_sigma(self) -> np.ndarray:
        """The output's standard deviation in the linear model, under ``distribution``."""
        return self.rss / (3.0 if self.distribution == "normal" else math.sqrt(3.0))

    def output(self, name: str) -> int:
        names = [o.name for o in self.outputs]
        if name not in names:
            raise InputError(f"no output {name!r}; the outputs are {', '.join(names)}")
        return names.index(name)


def sensitivities(m: Mechanism, plan: Plan, values: np.ndarray, q: np.ndarray, solved: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(sensitivity (outputs, tolerances, positions), J invertible per position) at the
    nominal solutions ``q`` (positions, unknowns; internal units)."""
    from ..kinematics.placing import place_motion_np
    from ..kinematics.rates import solve_rates_np

    outs = outputs_of(m)
    k = len(values)
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    drv = np.where(solved, values * scale, 0.0)
    qs = [np.where(solved, q[:, j], 0.0) for j in range(q.shape[1])]
    by_parameter: dict[str, np.ndarray] = {}
    invertible = solved.copy()
    for name in {p for d in plan.directions for p, _ in d.rates}:
        model = LoopModel.compile(parameter_as_driver(m, name), {m.driver.name: drv})
        p = np.full(k, m.parameters[name].value)
        qd, _, ok = solve_rates_np(model, qs, p, 1.0, 0.0)
        invertible &= ok
        moved = place_motion_np(model, qs, p, qd, 1.0, [np.zeros(k)] * len(qs), 0.0)
        rows = []
        for o in outs:
            if o.point:
                v = moved[o.point][1]
                rows.append(v.real if o.axis == "x" else v.imag)
            else:
                rows.append(degrees(qd[o.index]) if o.kind == "angle" else qd[o.index])
        by_parameter[name] = np.array(rows).reshape(len(outs), k)
    s = np.stack([sum(rate * by_parameter[p] for p, rate in d.rates) for d in plan.directions], axis=1) \
        if plan.directions else np.empty((len(outs), 0, k))
    s[:, :, ~invertible] = np.nan
    return s, invertible


def parameter_as_driver(m: Mechanism, name: str) -> Mechanism:
    """``m`` with the parameter ``name`` as its driver and its driver a parameter: the
    velocity equation of this mechanism at unit rate is dq/dp = -J^-1 dPhi/dp. A drawing's
    fixed joints are placed by their vectors (a joint at the end of a toleranced ground
    vector moves with it)."""
    params = {k: q for k, q in m.parameters.items() if k != name}
    params[m.driver.name] = m.driver
    extra = {k: v for k, v in m.extra.items() if k not in ("drawing", "drawn_parameters")}
    return replace(m, parameters=params, driver=m.parameters[name], extra=extra, driver_range=None)


def study(m: Mechanism, plan: Plan, values: Sequence[float], *, branch: str | None, tol: float,
          samples: int | None, seed: int, distribution: str, job: ScanJob,
          scheduler: str | None = None, workers: int | None = None,
          progress: Any = None) -> ToleranceStudy:
    """The linear study, checked against the exact solutions at ±D, and with ``samples``
    the Monte Carlo beside it (``job``: the scan job its chunks run as)."""
    vals = np.asarray(values, dtype=float)
    outs = outputs_of(m)
    # the nominal design and every tolerance at +D and -D, solved exactly
    d = np.array([x.tolerance.plus_minus for x in plan.directions])
    rows = [plan.nominal]
    for j in range(len(d)):
        for sign in (1.0, -1.0):
            r = plan.nominal.copy()
            r[j] += sign * d[j]
            rows.append(r)
    exact = tolerance_chunk(job, 0, np.array(rows))
    solved = exact["assembled"][0]
    nominal = exact["outputs"][0]  # (positions, outputs)
    q = np.stack([radians(nominal[:, o.index]) if o.kind == "angle" else nominal[:, o.index]
                  for o in outs if not o.point], axis=1) if m.unknowns else np.empty((len(vals), 0))
    s, invertible = sensitivities(m, plan, vals, q, solved)
    status, nonlinearity = judge(exact, nominal, s, d, outs, solved, invertible)
    base = ToleranceStudy(m.name, m.source, m.driver.name, m.driver.unit, m.length_unit,
                          tuple(float(v) for v in vals), tuple(x.tolerance for x in plan.directions),
                          outs, nominal.T.copy(), s, status, nonlinearity, distribution, branch)
    if samples is None:
        return base
    return monte_carlo(base, m, plan, samples, seed, job, scheduler, workers, progress)


def judge(exact: Mapping[str, np.ndarray], nominal: np.ndarray, s: np.ndarray, d: np.ndarray,
          outs: Sequence[Output], solved: np.ndarray, invertible: np.ndarray
          ) -> tuple[tuple[str, ...], np.ndarray]:
    """Each position's status and its linearity: the largest |exact - nominal - linear| at
    any tolerance's +D or -D, over the output's worst-case band."""
    band = np.abs(s * d[None, :, None]).sum(axis=1).T  # (positions, outputs)
    scale = np.nanmax(np.abs(nominal)) if np.isfinite(nominal).any() else 1.0
    floor = 1e-9 * max(scale, 1.0)
    worst = np.zeros(len(solved))
    reached = np.ones(len(solved), dtype=bool)
    for j in range(len(d)):
        for k, sign in enumerate((1.0, -1.0)):
            row = 1 + 2 * j + k
            reached &= exact["assembled"][row]
            moved = wrap_near(exact["outputs"][row], nominal, outs)
            miss = np.abs(moved - nominal - sign * d[j] * s[:, j, :].T)
            with np.errstate(invalid="ignore"):
                worst = np.fmax(worst, np.nanmax(miss / (band + floor), axis=1, initial=0.0))
    status = []
    for k in range(len(solved)):
        if not solved[k]:
            status.append("not_assembled")
        elif not invertible[k]:
            status.append("undefined")
        elif not reached[k] or not worst[k] <= NONLINEAR_LIMIT:
            status.append("near_limit")
        else:
            status.append("ok")
    return tuple(status), np.where(solved & reached, worst, np.nan)


def monte_carlo(base: ToleranceStudy, m: Mechanism, plan: Plan, samples: int, seed: int, job: ScanJob,
                scheduler: str | None, workers: int | None, progress: Any = None) -> ToleranceStudy:
    """Draw the samples and run them as a scan's chunks (the scan engine's runner)."""
    from .engine import run_chunks
    from .task import pick_chunk

    n_out, k = len(base.outputs), len(base.values)
    held = samples * k * (n_out + 1)
    if held > MAX_HELD:
        raise InputError(f"--samples {samples:,} x {k:,} positions x {n_out + 1} numbers is {held:,}, more "
                         f"than the {MAX_HELD:,} a tolerance study holds; use fewer samples or larger --step")
    drawn = draw(plan, samples, seed, base.distribution)
    size = pick_chunk(m, k, job.branch, None, samples)
    assembled = np.zeros((samples, k), dtype=bool)
    outputs = np.full((samples, k, n_out), np.nan)
    done = 0
    for part in run_chunks(job, drawn, size, scheduler=scheduler, workers=workers, task=tolerance_chunk):
        rows = part["design"]
        assembled[rows] = part["assembled"]
        outputs[rows] = part["outputs"]
        done += len(rows)
        if progress is not None:
            progress(done)
    outputs = wrap_near(outputs, base.nominal.T[None, :, :], base.outputs, copy=False)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        # numpy's warnings of a position no sample assembles at (all NaN): not_assembled says so
        warnings.simplefilter("ignore", RuntimeWarning)
        low, median, high = np.nanpercentile(outputs, PERCENTILES, axis=0)  # (positions, outputs) each
        counts = np.isfinite(outputs).sum(axis=0)
        sigma = np.where(counts > 1, np.nanstd(outputs, axis=0, ddof=1) if samples > 1 else np.nan, np.nan)
    return replace(base, samples=samples, seed=seed, mc_low=low.T, mc_median=median.T, mc_high=high.T,
                   mc_sigma=sigma.T, not_assembled=1.0 - assembled.mean(axis=0),
                   not_assembled_anywhere=float(1.0 - assembled.all(axis=1).mean()) if k else 0.0)


# --- the checked front doors ---------------------------------------------------------------------

def prepare(m: Mechanism, tolerances: Sequence[Tolerance], values: Sequence[float], *,
            branch: str | None, tol: float, doc: Mapping[str, Any] | None, text: str = "",
            overrides: Sequence[tuple[str, float]] = (), samples: int | None = None,
            distribution: str = "normal", label: str = OPTION) -> tuple[Plan, ScanJob]:
    """Everything checked before anything is solved: the plan and the scan job its designs
    run as (``text``: the file's text for workers; empty: the mechanism travels pickled)."""
    from ..kinematics.sweep import check_driver_values
    from .request import default_branch

    if distribution not in DISTRIBUTIONS:
        raise InputError(f"--distribution must be {' or '.join(DISTRIBUTIONS)}, got {distribution!r}")
    if samples is not None and not 1 <= samples <= MAX_SAMPLES:
        raise InputError(f"--samples must be between 1 and {MAX_SAMPLES:,}, got {samples}")
    plan = plan_tolerances(m, tolerances, doc, [k for k, _ in overrides], label)
    if len(values) > MAX_SCAN_POSITIONS:
        raise InputError(f"{len(values):,} driver positions is more than {MAX_SCAN_POSITIONS:,}; use a "
                         "larger --step")
    listed = check_driver_values(m, values)
    if not listed:
        raise InputError("give at least one driver value")
    chosen = default_branch(m, branch, tol)
    job = ScanJob(text, m.source, tuple(overrides), plan.columns, tuple(listed), chosen, tol,
                  None if text else m, plan.moves)
    return plan, job


def tolerance(mechanism: Mechanism | str, tolerances: Mapping[str, float],
              values: Sequence[float] | None = None, *, samples: int | None = DEFAULT_SAMPLES,
              seed: int = 0, distribution: str = "normal", branch: str | None = None,
              tol: float = 1e-12, scheduler: str | None = None,
              workers: int | None = None) -> ToleranceStudy:
    """The public ``linkage.tolerance``: how the tolerances ``{name: D}`` (±D in the file's
    units, D > 0; a length parameter, or of a joints file given by path a fixed joint's
    coordinate such as ``"O4.x"``) spread every unknown and named point of ``mechanism``
    (a Mechanism or a path) over the driver ``values`` (display units; default the
    file's range or 0..359 deg): the linear worst-case and RSS bands with each
    tolerance's contribution, and with ``samples`` (None: none) a Monte Carlo of that
    many designs drawn ``distribution`` ("normal": sigma D/3, or "uniform" within ±D)
    from ``seed``, run on dask like :func:`linkage.scan_designs` (``scheduler``,
    ``workers``). Every argument is checked first: a misuse raises InputError naming it.
    See docs/tolerance.md."""
    from ..arguments import check_reals, check_scan_options, check_text, check_whole, describe
    from ..kinematics.loading import mechanism_of
    from ..solve import check_criteria

    m = mechanism_of("mechanism", mechanism)
    if not isinstance(tolerances, Mapping) or not tolerances:
        raise InputError(f"tolerances must be a non-empty dict of name -> D (±D, D > 0), got "
                         f"{describe(tolerances)}")
    tols = []
    for name, d in tolerances.items():
        if not isinstance(name, str) or not name:
            raise InputError(f"tolerances' keys must be parameter names (strings), got {describe(name)}")
        tols.append(check_tolerance(name, d))
    if samples is not None:
        check_whole("samples", samples, 1, MAX_SAMPLES)
    check_scan_options(seed=seed, workers=workers, scheduler=scheduler, max_designs=MAX_SAMPLES)
    check_text("distribution", distribution, optional=False)
    if distribution not in DISTRIBUTIONS:
        raise InputError(f"distribution must be {' or '.join(DISTRIBUTIONS)}, got {distribution!r}")
    check_text("branch", branch)
    check_criteria(tol, 0.0, None, 50)
    if values is None:
        from ..arguments import driver_span
        from ..kinematics.sweep import driver_values

        if m.driver.kind != "angle" and m.driver_range is None:
            raise InputError(f"values: {m.driver.name} is a length with no [driver] range in the file: "
                             "give the driver values")
        a, b = driver_span(m, None, None, turn_end=359.0)
        values = driver_values(a, b, 1.0, None)
    values = check_reals("values", values, most=MAX_SCAN_POSITIONS)
    if not values:
        raise InputError("values must hold at least one driver value")
    doc = None
    if not isinstance(mechanism, Mechanism) and any("." in t.name for t in tols):
        from pathlib import Path

        from ..files import parse_toml, read_input

        doc = parse_toml(read_input(Path(mechanism)), str(mechanism))  # a joint's coordinates
    try:
        plan, job = prepare(m, tols, list(values), branch=branch, tol=tol, doc=doc, samples=samples,
                            distribution=distribution, label=API)
    except ParseError as exc:
        raise InputError(str(exc)) from None
    return study(m, plan, list(values), branch=job.branch, tol=tol, samples=samples, seed=seed,
                 distribution=distribution, job=job, scheduler=scheduler, workers=workers)
